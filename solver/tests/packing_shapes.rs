//! Packings of real shapes run to convergence: convex polyhedra from the two Rhine scans, each
//! keeping its own form (§5.1), and bonded-sphere grains (Sun & Xiao §2.4).

mod common;

use common::small_bed_of as spec;
use solver::dem::Shape;
use solver::grain::{MeshLibrary, RHINE_FORMS, UnitMesh, rhine_meshes};
use solver::packing::{FormSpec, Packing, Phase, ShapeKind};

fn converge(packing: &mut Packing) -> f64 {
    while packing.advance(20_000).unwrap() != Phase::Converged {}
    packing.result().unwrap().porosity.bulk
}

#[test]
fn rhine_polyhedra_keep_their_own_forms_and_settle() {
    let meshes: Vec<UnitMesh> = rhine_meshes().iter().map(|(_, m)| UnitMesh::new(m).unwrap()).collect();
    let own: Vec<(f64, f64)> = meshes
        .iter()
        .map(|m| (m.original_form().s / m.original_form().i, m.original_form().i / m.original_form().l))
        .collect();
    let library = MeshLibrary { source: "builtin:rhine".into(), faces: 300, digest: "test".into(), meshes };
    let mut packing = Packing::new(spec(ShapeKind::Mesh, FormSpec::Own, Some(library), 0.05)).unwrap();
    let n = converge(&mut packing);
    let bodies = &packing.simulation.bodies;
    assert!(bodies.len() > 30);
    for (shape, record) in bodies.shape.iter().zip(&packing.grains) {
        assert!(matches!(shape, Shape::Polyhedron(_)));
        // Each grain is one of the two scans rescaled to its size: flatness and elongation are
        // the scan's own (Fig. 5 with the original form), the mass-equivalent ellipsoid of the
        // rescaled polyhedron has the drawn size D.
        let f = shape.form();
        let (fl, el) = (f.s / f.i, f.i / f.l);
        let off = own.iter().map(|&(a, b)| (a - fl).abs().max((b - el).abs())).fold(f64::INFINITY, f64::min);
        assert!(off < 1e-9, "FL {fl}, EL {el}: {off:e} from the nearest scan's own");
        assert!((f.size() - record.size).abs() < 1e-12 * record.size);
        assert!((5.6e-3..=8e-3).contains(&record.size));
    }
    // A thin bed of a few layers: only a loose plausibility range.
    assert!((0.25..0.6).contains(&n), "porosity {n}");
}

#[test]
fn bonded_sphere_grains_settle() {
    let mut packing =
        Packing::new(spec(ShapeKind::BondedSpheres, FormSpec::Distribution(RHINE_FORMS), None, 0.06)).unwrap();
    let n = converge(&mut packing);
    let b = &packing.simulation.bodies;
    assert!(b.len() > 80 && b.shape.iter().all(|s| matches!(s, Shape::Bonded(_))));
    assert!((0.25..0.65).contains(&n), "porosity {n}");
}
