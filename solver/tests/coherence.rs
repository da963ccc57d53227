//! The narrow phase's shortcuts against the full query, on recorded packings: every listed pair
//! of every other step of a small packing of Rhine-scan polyhedra and of one of ellipsoids,
//! through generation, shaking (Eq. 14) and damping (§4.3). The shortcuts are the pairs skipped
//! because their distance bound exceeds how far they may have moved, the polyhedron contacts
//! confirmed from the last step's features, and the closed-form and clipped-cell centres of
//! pressure; the full query is the cold GJK + EPA with the overlap clipped facet by facet.

mod common;

use common::small_bed_of as spec;
use solver::dem::Audit;
use solver::grain::{MeshLibrary, RHINE_FORMS, UnitMesh, rhine_meshes};
use solver::packing::{FormSpec, Packing, PackingSpec, Phase, ShapeKind};

/// Audits every other step until the packing converges; the audit of each phase.
fn audited(spec: PackingSpec) -> Vec<(Phase, Audit)> {
    let mut packing = Packing::new(spec).unwrap();
    let mut audits: Vec<(Phase, Audit)> = Vec::new();
    let mut phase = Phase::Generation;
    while phase != Phase::Converged {
        let audit = packing.simulation.audit_next_step().unwrap();
        match audits.last_mut() {
            Some((p, a)) if *p == phase => a.merge(&audit),
            _ => audits.push((phase, audit)),
        }
        phase = packing.advance(2).unwrap();
    }
    audits
}

#[test]
fn polyhedron_shortcuts_agree_with_the_full_query_through_a_packing() {
    let meshes: Vec<UnitMesh> = rhine_meshes().iter().map(|(_, m)| UnitMesh::new(m).unwrap()).collect();
    let library = MeshLibrary { source: "builtin:rhine".into(), faces: 300, digest: "test".into(), meshes };
    let audits = audited(spec(ShapeKind::Mesh, FormSpec::Own, Some(library), 0.03));
    let phases: Vec<Phase> = audits.iter().map(|(p, _)| *p).collect();
    assert_eq!(phases, [Phase::Generation, Phase::Shaking, Phase::Damping]);
    let contacts: usize = audits.iter().map(|(_, a)| a.contacts).sum();
    assert!(contacts > 100_000, "{contacts} contacts");
    for (phase, a) in &audits {
        let name = phase.name();
        // Shortcuts were taken: most pairs were skipped, and contacts were confirmed (the
        // falling grains of the generation phase meet a few times).
        assert!(a.skipped > a.pairs / 2 && a.contacts > 10, "{name}: {a:?}");
        assert_eq!((a.wrongly_skipped, a.mismatched), (0, 0), "{name}: {a:?}");
        // Depth and normal come from the same face of K: equal to rounding.
        assert!(a.depth < 1e-13 && a.normal < 1e-12, "{name}: {a:?}");
        // The point: both are the overlap's centroid, which a nearly flat overlap (faces
        // parallel to within ~1e-9 rad) fixes only to the rounding of its corners divided by
        // that angle; such contacts are rare, and checked in exact arithmetic
        // (tests/contact_polyhedron.rs).
        assert!(a.points_beyond * 1000 < a.contacts && a.point < 1e-6, "{name}: {a:?}");
    }
}

#[test]
fn ellipsoid_pairs_skipped_as_apart_never_touch() {
    let audits = audited(spec(ShapeKind::Ellipsoid, FormSpec::Distribution(RHINE_FORMS), None, 0.04));
    let contacts: usize = audits.iter().map(|(_, a)| a.contacts).sum();
    assert!(contacts > 100_000, "{contacts} contacts");
    for (phase, a) in &audits {
        let name = phase.name();
        assert!(a.skipped > a.pairs / 2 && a.contacts > 10, "{name}: {a:?}");
        assert_eq!((a.wrongly_skipped, a.mismatched), (0, 0), "{name}: {a:?}");
        // Ellipsoid contacts take no shortcut: warm or cold Newton ends at the same minimum.
        assert!(a.depth < 1e-12 && a.normal < 1e-8, "{name}: {a:?}");
    }
}
