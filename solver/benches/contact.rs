//! Cost of the ellipsoid narrow phase per persisting contact.
//!
//! Each benchmark runs over a fixed set of 1024 random pairs (semi-axes in [1, 10], so aspect
//! ratios up to 10:1, random orientations): criterion's time is per 1024 queries, its
//! throughput in queries per second. The Newton iteration counts of each set go to stderr.

mod common;
use common::random_unit;

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{Matrix3, UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use solver::dem::contact::ellipsoid::{
    EllipsoidPose, ellipsoid_cylinder_wall, ellipsoid_ellipsoid, ellipsoid_ellipsoid_with_stats, ellipsoid_plane,
};
use solver::dem::uniform_rotation;

type V3 = Vector3<f64>;

const PAIRS: usize = 1024;

#[derive(Clone, Copy)]
struct Grain {
    q: UnitQuaternion<f64>,
    axes: V3,
}

impl Grain {
    fn random(rng: &mut ChaCha8Rng) -> Self {
        Self { q: uniform_rotation(rng), axes: V3::from_fn(|_, _| 10f64.powf(rng.random_range(0.0..1.0))) }
    }

    fn rotation(&self) -> Matrix3<f64> {
        self.q.to_rotation_matrix().into_inner()
    }

    fn reach(&self, n: &V3) -> V3 {
        EllipsoidPose::new(V3::zeros(), &self.rotation(), self.axes).support(n)
    }

    fn rolling_radius(&self) -> f64 {
        self.axes.min().powi(2) / self.axes.max()
    }
}

/// Poses of a pair whose support points along `n` overlap by `depth`.
fn placed(a: &Grain, b: &Grain, n: &V3, depth: f64) -> (EllipsoidPose, EllipsoidPose) {
    let xb = a.reach(n) - n * depth + b.reach(n);
    (EllipsoidPose::new(V3::zeros(), &a.rotation(), a.axes), EllipsoidPose::new(xb, &b.rotation(), b.axes))
}

struct Persisting {
    now: (EllipsoidPose, EllipsoidPose),
    previous_normal: V3,
}

/// Shallow contacts (0.1–30 % of ρ_A + ρ_B, i.e. up to 3 % of the smallest semi-axis for a 10:1
/// grain) one time step after the previous one: both grains turned by `turn` rad about random
/// axes, the normal swung by `turn` rad and the depth changed by 1 %.
fn persisting(turn: f64) -> Vec<Persisting> {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    (0..PAIRS)
        .map(|_| {
            let (mut a, mut b) = (Grain::random(&mut rng), Grain::random(&mut rng));
            let n = random_unit(&mut rng);
            let depth = rng.random_range(1e-3..0.3) * (a.rolling_radius() + b.rolling_radius());
            let (pa, pb) = placed(&a, &b, &n, depth);
            let previous_normal = ellipsoid_ellipsoid(&pa, &pb, None).expect("overlapping by construction").normal;
            a.q = UnitQuaternion::from_scaled_axis(random_unit(&mut rng) * turn) * a.q;
            b.q = UnitQuaternion::from_scaled_axis(random_unit(&mut rng) * turn) * b.q;
            let n = UnitQuaternion::from_scaled_axis(n.cross(&random_unit(&mut rng)).normalize() * turn) * n;
            Persisting { now: placed(&a, &b, &n, depth * 1.01), previous_normal }
        })
        .collect()
}

/// Pairs at a uniformly drawn fraction of their reach along a random direction.
fn random_pairs(rng: &mut ChaCha8Rng, fraction: std::ops::Range<f64>) -> Vec<(EllipsoidPose, EllipsoidPose)> {
    (0..PAIRS)
        .map(|_| {
            let (a, b) = (Grain::random(rng), Grain::random(rng));
            let m = random_unit(rng);
            let ha = (a.reach(&m)).dot(&m);
            let hb = (b.reach(&m)).dot(&m);
            let xb = m * (rng.random_range(fraction.clone()) * (ha + hb));
            (EllipsoidPose::new(V3::zeros(), &a.rotation(), a.axes), EllipsoidPose::new(xb, &b.rotation(), b.axes))
        })
        .collect()
}

fn report_iterations(label: &str, runs: impl Iterator<Item = (u32, bool)>) {
    let mut counts: Vec<(u32, bool)> = runs.collect();
    counts.sort_unstable();
    let mean = counts.iter().map(|c| c.0 as f64).sum::<f64>() / counts.len() as f64;
    let searched = counts.iter().filter(|c| c.1).count();
    eprintln!(
        "{label}: Newton iterations mean {mean:.2}, median {}, max {}; {searched} of {} needed the global search",
        counts[counts.len() / 2].0,
        counts.last().unwrap().0,
        counts.len()
    );
}

fn ellipsoid_pairs(c: &mut Criterion) {
    let mut group = c.benchmark_group("ellipsoid_ellipsoid");
    group.throughput(Throughput::Elements(PAIRS as u64));
    for (label, turn) in [("warm, 1e-3 rad per step", 1e-3), ("warm, 1e-4 rad per step", 1e-4)] {
        let pairs = persisting(turn);
        report_iterations(
            label,
            pairs.iter().map(|p| {
                let stats = ellipsoid_ellipsoid_with_stats(&p.now.0, &p.now.1, Some(&p.previous_normal)).1;
                (stats.newton_iterations, stats.global_search)
            }),
        );
        group.bench_function(label, |bench| {
            bench.iter(|| {
                for p in &pairs {
                    black_box(ellipsoid_ellipsoid(black_box(&p.now.0), black_box(&p.now.1), Some(&p.previous_normal)));
                }
            })
        });
    }
    let pairs = persisting(1e-3);
    report_iterations(
        "cold, shallow",
        pairs.iter().map(|p| {
            let stats = ellipsoid_ellipsoid_with_stats(&p.now.0, &p.now.1, None).1;
            (stats.newton_iterations, stats.global_search)
        }),
    );
    group.bench_function("cold, shallow", |bench| {
        bench.iter(|| {
            for p in &pairs {
                black_box(ellipsoid_ellipsoid(black_box(&p.now.0), black_box(&p.now.1), None));
            }
        })
    });
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for (label, fraction) in
        [("cold, deep (centres at 0-50 % of reach)", 0.0..0.5), ("cold, mixed (0-110 % of reach)", 0.0..1.1)]
    {
        let pairs = random_pairs(&mut rng, fraction);
        report_iterations(
            label,
            pairs.iter().map(|(a, b)| {
                let stats = ellipsoid_ellipsoid_with_stats(a, b, None).1;
                (stats.newton_iterations, stats.global_search)
            }),
        );
        group.bench_function(label, |bench| {
            bench.iter(|| {
                for (a, b) in &pairs {
                    black_box(ellipsoid_ellipsoid(black_box(a), black_box(b), None));
                }
            })
        });
    }
    group.finish();
}

fn walls_and_poses(c: &mut Criterion) {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let grains: Vec<(V3, Grain)> = (0..PAIRS)
        .map(|_| {
            let grain = Grain::random(&mut rng);
            let out = random_unit(&mut rng).xy().normalize();
            // Centres within a largest semi-axis of the floor and of a wall of radius 200.
            let rho = 200.0 - rng.random_range(0.0..10.0);
            (V3::new(rho * out.x, rho * out.y, rng.random_range(0.0..10.0)), grain)
        })
        .collect();
    let poses: Vec<EllipsoidPose> = grains.iter().map(|(x, g)| EllipsoidPose::new(*x, &g.rotation(), g.axes)).collect();
    let mut group = c.benchmark_group("ellipsoid_walls");
    group.throughput(Throughput::Elements(PAIRS as u64));
    group.bench_function("EllipsoidPose::new", |bench| {
        let rotations: Vec<(V3, Matrix3<f64>, V3)> = grains.iter().map(|(x, g)| (*x, g.rotation(), g.axes)).collect();
        bench.iter(|| {
            for (x, r, axes) in &rotations {
                black_box(EllipsoidPose::new(black_box(*x), black_box(r), black_box(*axes)));
            }
        })
    });
    group.bench_function("plane", |bench| {
        bench.iter(|| {
            for e in &poses {
                black_box(ellipsoid_plane(black_box(e), &V3::zeros(), &V3::z()));
            }
        })
    });
    group.bench_function("cylinder wall", |bench| {
        bench.iter(|| {
            for e in &poses {
                black_box(ellipsoid_cylinder_wall(black_box(e), 0.0, 0.0, 200.0));
            }
        })
    });
    group.finish();
}

criterion_group!(benches, ellipsoid_pairs, walls_and_poses);
criterion_main!(benches);
