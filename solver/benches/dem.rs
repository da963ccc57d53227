//! Particle-steps per second of the DEM engine on settled beds, with 1 and 2 threads.
//!
//! The sphere bed of 2,450 grains is the LAMMPS comparison bed of `../shared/peers/lammps`:
//! d = 6.7 mm, ρ = 2650 kg/m³ in water, a 0.05 m periodic square, a 7 × 7 × 50 lattice with
//! random velocities in ±0.2 m/s, poured for 0.5 s and settled. The bed of 8,000 ellipsoids is
//! the settled bed of 2,000 tiled 2 × 2 (the same structure, four times the grains: the growth
//! of cost with grain count alone). Settled beds are cached in target/sedpack-bench/ so that
//! only the first run pays for the settling.

use std::path::PathBuf;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use nalgebra::{UnitQuaternion, Vector3};
use rand::{RngExt, SeedableRng};
use rand_chacha::ChaCha8Rng;
use solver::dem::{Calibration, Domain, NewBody, Settings, Shaking, Shape, Simulation};
use solver::grain::{FormDistribution, MeshLibrary, SieveCurve, UnitMesh, rhine_meshes};
use solver::packing::{FormSpec, GrainSpec, Material, Packing, PackingSpec, Phase, Process, ShapeKind};

struct Bed {
    name: &'static str,
    width: f64,
    per_row: usize,
    layers: usize,
    shape: fn(&mut ChaCha8Rng) -> Shape,
}

fn sphere(_: &mut ChaCha8Rng) -> Shape {
    Shape::Sphere { radius: 3.35e-3 }
}

fn settings() -> Settings {
    Settings {
        density: 2650.0,
        fluid_density: 1000.0,
        gravity: Vector3::new(0.0, 0.0, -9.81),
        restitution: 0.1,
        collision_time: 2e-4,
        poisson_ratio: 0.22,
        friction: 0.5,
        time_step: 5e-6,
        skin: 1e-3,
        calibration: Calibration::Discrete { time_step: 5e-6 },
    }
}

fn cache(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("../target/sedpack-bench/{name}.json"))
}

fn cached(name: &str) -> Option<Simulation> {
    serde_json::from_str(&std::fs::read_to_string(cache(name)).ok()?).ok()
}

fn store(name: &str, sim: &Simulation) {
    let path = cache(name);
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(&path, serde_json::to_string(sim).unwrap()).unwrap();
}

/// A bed made by the packing protocol itself (§4.3) with a short shaking, in a periodic square
/// of `width`: grains of the 5.6–8 mm class, ellipsoids and bonded spheres of the Rhine form
/// distribution (Table 2), polyhedra of the two Rhine scans with their own forms.
fn protocol_bed(name: &str, shape: ShapeKind, width: f64, mass: f64) -> Simulation {
    if let Some(sim) = cached(name) {
        return sim;
    }
    let rhine = FormDistribution { mu_fl: 0.647, sigma_fl: 0.175, mu_el: 0.682, sigma_el: 0.139 };
    let (form, meshes) = match shape {
        ShapeKind::Mesh => {
            let meshes = rhine_meshes().iter().map(|(_, m)| UnitMesh::new(m).unwrap()).collect();
            (
                FormSpec::Own,
                Some(MeshLibrary { source: "builtin:rhine".into(), faces: 300, digest: String::new(), meshes }),
            )
        }
        _ => (FormSpec::Distribution(rhine), None),
    };
    let spec = PackingSpec {
        domain: Domain::Periodic { width },
        height: 0.4,
        grains: GrainSpec { shape, size: SieveCurve::new(vec![5.6e-3, 8e-3], vec![1.0]).unwrap(), mass, form, meshes },
        material: Material::default(),
        time_step: 5e-6,
        calibration: Calibration::Discrete { time_step: 5e-6 },
        process: Process {
            spacing: 0.012,
            velocity: 1.0,
            shaking: Shaking { amplitude: 3e-4, period: 0.025 },
            shaking_duration: 0.2,
            damping: 1e-3,
            height_change: 1e-5,
            interval: 0.01,
            max_time: 30.0,
        },
        slice: 1e-3,
        cutoff: 0.5,
        trim: None,
        seed: 1,
    };
    eprintln!("packing {name} for the benchmark, cached in {}", cache(name).display());
    let mut packing = Packing::new(spec).unwrap();
    while packing.advance(10_000).unwrap() != Phase::Converged {}
    let mut sim = packing.simulation;
    sim.damping = None;
    sim.shaking = None;
    store(name, &sim);
    sim
}

/// The periodic bed `base` of side `width` repeated 2 × 2, at rest.
fn tiled(base: &Simulation, width: f64) -> Simulation {
    let mut sim = Simulation::new(Domain::Periodic { width: 2.0 * width }, base.settings).unwrap();
    let b = &base.bodies;
    for (tx, ty) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        for k in 0..b.len() {
            sim.add_body(NewBody {
                shape: b.shape[k].clone(),
                position: b.position[k] + Vector3::new(tx * width, ty * width, 0.0),
                orientation: b.orientation[k],
                velocity: Vector3::zeros(),
                angular_velocity: Vector3::zeros(),
            });
        }
    }
    sim
}

fn settled(bed: &Bed) -> Simulation {
    if let Some(sim) = cached(bed.name) {
        return sim;
    }
    let mut rng = ChaCha8Rng::seed_from_u64(12345);
    let mut sim = Simulation::new(Domain::Periodic { width: bed.width }, settings()).unwrap();
    let a = bed.width / bed.per_row as f64;
    for k in 0..bed.layers {
        for j in 0..bed.per_row {
            for i in 0..bed.per_row {
                let mut v = || rng.random_range(-0.2..0.2);
                let velocity = Vector3::new(v(), v(), v());
                let shape = (bed.shape)(&mut rng);
                sim.add_body(NewBody {
                    shape,
                    position: Vector3::new((i as f64 + 0.5) * a, (j as f64 + 0.5) * a, 0.005 + 0.01 * k as f64),
                    orientation: UnitQuaternion::identity(),
                    velocity,
                    angular_velocity: Vector3::zeros(),
                });
            }
        }
    }
    eprintln!("settling {} ({} grains), cached in {}", bed.name, sim.bodies.len(), cache(bed.name).display());
    while sim.time < 0.5 {
        sim.step().unwrap();
    }
    // Damping (Eq. 15) brings the poured bed to rest quickly.
    sim.damping = Some(1e-3);
    while sim.bodies.velocity.iter().map(|v| v.norm_squared()).sum::<f64>() / sim.bodies.len() as f64 > 1e-8 {
        sim.step().unwrap();
    }
    sim.damping = None;
    store(bed.name, &sim);
    sim
}

fn particle_steps(c: &mut Criterion) {
    let beds = [
        Bed { name: "spheres-2450", width: 0.05, per_row: 7, layers: 50, shape: sphere },
        Bed { name: "spheres-8112", width: 0.091, per_row: 13, layers: 48, shape: sphere },
    ];
    let mut group = c.benchmark_group("settled_bed");
    group.sample_size(10);
    // About 2,000 ellipsoids (mean grain mass 0.66 g), 500 bonded grains (lighter: 0.45 g) and
    // 300 polyhedra, whose bed takes longest to build.
    let protocol = [
        ("ellipsoids-2000", ShapeKind::Ellipsoid, 0.06, 1.32),
        ("bonded-500", ShapeKind::BondedSpheres, 0.036, 0.225),
        ("polyhedra-300", ShapeKind::Mesh, 0.036, 0.2),
    ];
    let spheres = beds.iter().map(|bed| (bed.name.to_string(), settled(bed)));
    let others = protocol.iter().flat_map(|&(n, shape, w, m)| {
        let bed = protocol_bed(n, shape, w, m);
        let more = (n == "ellipsoids-2000").then(|| ("ellipsoids-8000 (2 × 2 tiles)".to_string(), tiled(&bed, w)));
        std::iter::once((n.to_string(), bed)).chain(more)
    });
    let all = spheres.chain(others);
    for (name, base) in all {
        group.throughput(Throughput::Elements(base.bodies.len() as u64));
        for threads in [1, 2] {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            let mut sim = base.clone();
            group.bench_function(BenchmarkId::new(&name, format!("{threads} threads")), |b| {
                pool.install(|| b.iter(|| sim.step().unwrap()))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, particle_steps);
criterion_main!(benches);
