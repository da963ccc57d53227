//! The narrow phase's shortcuts against the full query, on recorded packings: every listed pair
//! of every other step of a small packing of Rhine-scan polyhedra and of one of ellipsoids,
//! through generation, shaking (Eq. 14) and damping (§4.3). The shortcuts are the pairs skipped
//! because their distance bound exceeds how far they may have moved, the polyhedron contacts
//! confirmed from the last step's features, and the closed-form and clipped-cell centres of
//! pressure; the full query is the cold GJK + EPA with the overlap clipped facet by facet. And
//! the distance bound of a pair found apart, on two cubes falling side by side: only their
//! relative motion uses it up.

mod common;

use common::{box_shape, settings, small_bed_of as spec};
use nalgebra::{UnitQuaternion, Vector3};
use solver::dem::{Audit, Domain, NewBody, Simulation};
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

/// Two 1 cm cubes 1.0025 mm apart along x, falling at 3 m/s under gravity, the second also
/// closing in on the first at `closing` m/s: the audit of each step until `steps` or their first
/// contact, and the step of that contact.
fn falling_cubes(closing: f64, steps: u64) -> (Audit, Option<u64>) {
    let mut sim =
        Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.5, 0.5, Vector3::new(0.0, 0.0, -9.81))).unwrap();
    for (x, vx) in [(0.04, 0.0), (0.0510025, -closing)] {
        sim.add_body(NewBody {
            shape: box_shape(0.01, 0.01, 0.01),
            position: Vector3::new(x, 0.05, 1.0),
            orientation: UnitQuaternion::identity(),
            velocity: Vector3::new(vx, 0.0, -3.0),
            angular_velocity: Vector3::zeros(),
        });
    }
    let mut audit = Audit::default();
    for step in 0..steps {
        let a = sim.audit_next_step().unwrap();
        audit.merge(&a);
        if a.contacts > 0 {
            return (audit, Some(step));
        }
        sim.step().unwrap();
    }
    (audit, None)
}

#[test]
fn grains_falling_together_keep_their_distance_bound() {
    // 0.05 s of falling: each cube moves 16 cm, 160 times the gap, but not relative to the other,
    // so after the first query the pair is skipped at every step. (A bound on each body's own
    // travel would be used up every 33 steps: 2 × 3 m/s × 5 µs per step against 1 mm.)
    let (a, contact) = falling_cubes(0.0, 10_000);
    assert_eq!(contact, None);
    assert_eq!((a.pairs, a.skipped, a.wrongly_skipped), (10_000, 9_999, 0), "{a:?}");
}

#[test]
fn grains_closing_in_are_queried_in_time_to_meet() {
    // Closing at 1 m/s, 5 µm per step, the 1.0025 mm gap is gone after 200.5 steps: the first
    // contact is found after the 201st step, and no step before skips a touching pair.
    let (a, contact) = falling_cubes(1.0, 1_000);
    assert_eq!(a.wrongly_skipped, 0, "{a:?}");
    assert_eq!(contact, Some(201), "{a:?}");
    // The bound still skips most steps: each query finds the gap left, and the pair is skipped
    // until its relative motion could have closed it.
    assert!(a.skipped > 150, "{a:?}");
}
