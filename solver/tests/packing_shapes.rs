//! Packings of real shapes run to convergence: convex polyhedra from the two Rhine scans, each
//! keeping its own form (§5.1), and bonded-sphere grains (Sun & Xiao §2.4).

use solver::dem::{Calibration, Domain, Shaking, Shape};
use solver::grain::{FormDistribution, MeshLibrary, SieveCurve, UnitMesh, rhine_meshes};
use solver::packing::{FormSpec, GrainSpec, Material, Packing, PackingSpec, Phase, Process, ShapeKind};

fn spec(shape: ShapeKind, form: FormSpec, meshes: Option<MeshLibrary>, mass: f64) -> PackingSpec {
    PackingSpec {
        domain: Domain::Periodic { width: 0.04 },
        height: 0.15,
        grains: GrainSpec { shape, size: SieveCurve::new(vec![5.6e-3, 8e-3], vec![1.0]).unwrap(), mass, form, meshes },
        material: Material::default(),
        time_step: 5e-6,
        calibration: Calibration::Discrete { time_step: 5e-6 },
        process: Process {
            spacing: 0.012,
            velocity: 1.0,
            shaking: Shaking { amplitude: 3e-4, period: 0.025 },
            shaking_duration: 0.05,
            damping: 1e-3,
            height_change: 1e-5,
            interval: 0.01,
            max_time: 5.0,
        },
        slice: 1e-3,
        cutoff: 0.5,
        trim: Some(4e-3),
        seed: 3,
    }
}

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
    let rhine = FormDistribution { mu_fl: 0.647, sigma_fl: 0.175, mu_el: 0.682, sigma_el: 0.139 };
    let mut packing = Packing::new(spec(ShapeKind::BondedSpheres, FormSpec::Distribution(rhine), None, 0.06)).unwrap();
    let n = converge(&mut packing);
    let b = &packing.simulation.bodies;
    assert!(b.len() > 80 && b.shape.iter().all(|s| matches!(s, Shape::Bonded(_))));
    assert!((0.25..0.65).contains(&n), "porosity {n}");
}
