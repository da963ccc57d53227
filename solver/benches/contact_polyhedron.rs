//! Cost of the convex-polyhedron narrow phase (contact queries per second for polyhedra
//! of ~50, 100 and 300 faces, warm and cold), next to parry3d's GJK/EPA on the same pairs.
//!
//! The grains are generated pebbles (1000 faces) simplified to at most 50, 100 and 300 faces
//! (§5.2.1), 16 of each, centred on their centre of mass. Each benchmark runs over a fixed set of
//! 1024 random pairs in shallow contact, as in a settled packing: B approaches A along a random
//! direction until they touch and then 0.1 % of the grain size further. "warm" is the same pair
//! one time step later (both turned by 1e-4 rad, B moved by 1e-6) with the previous normal
//! passed in; "cold" has no previous normal; "engine, kept features" is the simulation's query
//! with what it kept of the previous step's contact. Criterion's time is per 1024 queries, its
//! throughput in queries per second. Mean GJK and EPA iterations go to stderr.

mod common;
use common::random_unit;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use parry3d_f64::math::{Pose, Rotation as PRotation, Vector as PVector};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use solver::dem::contact::ContactPoint;
use solver::dem::contact::coherence::Features;
use solver::dem::contact::polyhedron::{
    Mode, PolyhedronPose, polyhedron_plane, polyhedron_polyhedron, polyhedron_polyhedron_coherent,
    polyhedron_polyhedron_with_stats,
};
use solver::dem::shape::ConvexPolyhedron;
use solver::dem::uniform_rotation;
use solver::grain::pebble::pebble;
use solver::grain::simplify;

type V3 = Vector3<f64>;

const PAIRS: usize = 1024;
const SHAPES: usize = 16;

struct Grains {
    shapes: Vec<ConvexPolyhedron>,
    parry: Vec<parry3d_f64::shape::ConvexPolyhedron>,
    faces: f64,
}

fn grains(max_faces: usize) -> Grains {
    let shapes: Vec<ConvexPolyhedron> = (0..SHAPES as u64)
        .map(|seed| {
            let mesh = simplify(&pebble(seed, 1000).unwrap(), max_faces).unwrap().mesh;
            let com = mesh.mass_properties().center_of_mass;
            ConvexPolyhedron::new(&mesh.map_vertices(|v| v - com)).unwrap()
        })
        .collect();
    let parry = shapes
        .iter()
        .map(|s| {
            let points: Vec<PVector> = s.vertices().iter().map(|v| PVector::new(v.x, v.y, v.z)).collect();
            parry3d_f64::shape::ConvexPolyhedron::from_convex_hull(&points).unwrap()
        })
        .collect();
    let faces = shapes.iter().map(|s| s.triangles().len() as f64).sum::<f64>() / SHAPES as f64;
    Grains { shapes, parry, faces }
}

struct Pair {
    a: usize,
    b: usize,
    qa: UnitQuaternion<f64>,
    qb: UnitQuaternion<f64>,
    xb: V3,
    previous_normal: V3,
    /// The features the engine kept from the previous step's contact.
    features: Features,
    /// The rotation matrices of qa and qb.
    ra: Matrix3<f64>,
    rb: Matrix3<f64>,
}

impl Pair {
    fn poses<'g>(&'g self, g: &'g Grains) -> (PolyhedronPose<'g>, PolyhedronPose<'g>) {
        (
            PolyhedronPose::new(&g.shapes[self.a], V3::zeros(), &self.ra),
            PolyhedronPose::new(&g.shapes[self.b], self.xb, &self.rb),
        )
    }

    fn set_rotations(&mut self, qa: UnitQuaternion<f64>, qb: UnitQuaternion<f64>) {
        (self.qa, self.qb) = (qa, qb);
        (self.ra, self.rb) = (qa.to_rotation_matrix().into_inner(), qb.to_rotation_matrix().into_inner());
    }

    fn parry_poses(&self) -> (Pose, Pose) {
        let pose = |q: &UnitQuaternion<f64>, x: &V3| {
            Pose::from_parts(PVector::new(x.x, x.y, x.z), PRotation::from_xyzw(q.i, q.j, q.k, q.w))
        };
        (pose(&self.qa, &V3::zeros()), pose(&self.qb, &self.xb))
    }
}

/// Shallow persisting contacts: B approaches A along m until they touch (bisection on the
/// overlap test, which holds on an interval of centre distances), then 0.1 % of the grain size
/// further; one step later both have turned and B moved a little.
fn pairs(g: &Grains) -> Vec<Pair> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut out = Vec::with_capacity(PAIRS);
    while out.len() < PAIRS {
        let (a, b) = (rng.random_range(0..SHAPES), rng.random_range(0..SHAPES));
        let (qa, qb) = (uniform_rotation(&mut rng), uniform_rotation(&mut rng));
        let m = random_unit(&mut rng);
        let size = g.shapes[a].bounding_radius() + g.shapes[b].bounding_radius();
        let mut pair = Pair {
            a,
            b,
            qa,
            qb,
            xb: V3::zeros(),
            previous_normal: V3::zeros(),
            features: Features::default(),
            ra: Matrix3::zeros(),
            rb: Matrix3::zeros(),
        };
        pair.set_rotations(qa, qb);
        let (mut inside, mut outside) = (0.0, size);
        for _ in 0..60 {
            let t = 0.5 * (inside + outside);
            pair.xb = m * t;
            let (pa, pb) = pair.poses(g);
            if polyhedron_polyhedron(&pa, &pb, None).is_some() {
                inside = t;
            } else {
                outside = t;
            }
        }
        pair.xb = m * (outside - 1e-3 * 0.5 * size);
        let (pa, pb) = pair.poses(g);
        let mut features = Features::default();
        let Some(contact) = polyhedron_polyhedron_coherent(
            &pa,
            &pb,
            None,
            0.0,
            &mut features,
            Mode::Coherent,
            ContactPoint::CentreOfPressure,
        )
        .0
        else {
            continue;
        };
        pair.previous_normal = contact.normal;
        pair.features = features;
        let qa = UnitQuaternion::from_scaled_axis(random_unit(&mut rng) * 1e-4) * pair.qa;
        let qb = UnitQuaternion::from_scaled_axis(random_unit(&mut rng) * 1e-4) * pair.qb;
        pair.set_rotations(qa, qb);
        pair.xb += random_unit(&mut rng) * 1e-6;
        out.push(pair);
    }
    out
}

fn report(label: &str, g: &Grains, pairs: &[Pair], warm: bool) {
    let (mut gjk, mut epa, mut contacts, mut points) = (0u64, 0u64, 0u64, 0u64);
    for p in pairs {
        let (a, b) = p.poses(g);
        let (contact, stats) = polyhedron_polyhedron_with_stats(&a, &b, warm.then_some(&p.previous_normal));
        gjk += stats.gjk_iterations as u64;
        epa += stats.epa_iterations as u64;
        contacts += contact.is_some() as u64;
        points += stats.centre_of_pressure() as u64;
    }
    let n = pairs.len() as f64;
    eprintln!(
        "{label}: {:.0} faces on average; GJK iterations {:.2}, EPA iterations {:.2} per query; {contacts} contacts, {points} with the centre of pressure",
        g.faces,
        gjk as f64 / n,
        epa as f64 / n
    );
}

fn polyhedron_pairs(c: &mut Criterion) {
    for max_faces in [50, 100, 300] {
        let g = grains(max_faces);
        let pairs = pairs(&g);
        let mut group = c.benchmark_group(format!("polyhedron_polyhedron, ≤{max_faces} faces"));
        group.throughput(Throughput::Elements(PAIRS as u64));
        for (label, warm) in [("warm", true), ("cold", false)] {
            report(&format!("≤{max_faces} faces, {label}"), &g, &pairs, warm);
            let poses: Vec<(PolyhedronPose, PolyhedronPose, V3)> = pairs
                .iter()
                .map(|p| {
                    let (a, b) = p.poses(&g);
                    (a, b, p.previous_normal)
                })
                .collect();
            group.bench_function(label, |bench| {
                bench.iter(|| {
                    for (a, b, n) in &poses {
                        black_box(polyhedron_polyhedron(black_box(a), black_box(b), warm.then_some(n)));
                    }
                })
            });
        }
        // The engine's query one step later: EPA confirmed from the kept features, the centre of
        // pressure in closed form where it applies.
        let kept: Vec<(PolyhedronPose, PolyhedronPose, V3, Features)> = pairs
            .iter()
            .map(|p| {
                let (a, b) = p.poses(&g);
                (a, b, p.previous_normal, p.features)
            })
            .collect();
        for (name, rule) in [
            ("engine, kept features", ContactPoint::CentreOfPressure),
            ("engine, kept features, witness point", ContactPoint::Witness),
        ] {
            group.bench_function(name, |bench| {
                bench.iter(|| {
                    for (a, b, n, f) in &kept {
                        let mut features = *f;
                        black_box(polyhedron_polyhedron_coherent(
                            black_box(a),
                            black_box(b),
                            Some(n),
                            0.0,
                            &mut features,
                            Mode::Coherent,
                            rule,
                        ));
                    }
                })
            });
        }
        let parry_pairs: Vec<(Pose, Pose, usize, usize)> = pairs
            .iter()
            .map(|p| {
                let (a, b) = p.parry_poses();
                (a, b, p.a, p.b)
            })
            .collect();
        group.bench_function("parry3d query::contact", |bench| {
            bench.iter(|| {
                for (pa, pb, a, b) in &parry_pairs {
                    black_box(parry3d_f64::query::contact(pa, &g.parry[*a], pb, &g.parry[*b], 0.0).unwrap());
                }
            })
        });
        group.finish();
    }
}

fn floor_and_poses(c: &mut Criterion) {
    let g = grains(300);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let grains: Vec<(usize, Matrix3<f64>, V3)> = (0..PAIRS)
        .map(|_| {
            let k = rng.random_range(0..SHAPES);
            let r = uniform_rotation(&mut rng).to_rotation_matrix().into_inner();
            let lowest = g.shapes[k].vertices().iter().map(|v| (r * v).z).fold(f64::INFINITY, f64::min);
            (k, r, V3::new(0.0, 0.0, -lowest - 1e-3 * g.shapes[k].bounding_radius()))
        })
        .collect();
    let poses: Vec<PolyhedronPose> = grains.iter().map(|(k, r, x)| PolyhedronPose::new(&g.shapes[*k], *x, r)).collect();
    let mut group = c.benchmark_group("polyhedron_walls, ≤300 faces");
    group.throughput(Throughput::Elements(PAIRS as u64));
    group.bench_function("PolyhedronPose::new", |bench| {
        bench.iter(|| {
            for (k, r, x) in &grains {
                black_box(PolyhedronPose::new(&g.shapes[*k], black_box(*x), black_box(r)));
            }
        })
    });
    group.bench_function("floor", |bench| {
        bench.iter(|| {
            for p in &poses {
                black_box(polyhedron_plane(black_box(p), &V3::zeros(), &V3::z()));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, polyhedron_pairs, floor_and_poses);
criterion_main!(benches);
