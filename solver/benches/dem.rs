//! Particle-steps per second of the DEM engine on the standard settled beds of `solver::bed`
//! (the same beds as `sedpack bench`), with 1 and 2 threads, at rest and shaken (Eq. 14): the
//! LAMMPS comparison bed of 2,450 spheres, and 2,000 ellipsoids, Rhine-scan polyhedra and
//! bonded-sphere grains. Beds are built once and cached in target/sedpack-bench/.

use std::path::PathBuf;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use solver::bed::{BedSpec, build};
use solver::dem::{Shaking, Simulation};
use solver::packing::ShapeKind;

fn cache(spec: &BedSpec) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!(
        "../target/sedpack-bench/{}-v{}.json",
        spec.name(),
        solver::VERSION
    ))
}

fn bed(spec: &BedSpec) -> Simulation {
    let path = cache(spec);
    if let Some(sim) = std::fs::read_to_string(&path).ok().and_then(|s| serde_json::from_str(&s).ok()) {
        return sim;
    }
    eprintln!("building {} for the benchmark, cached in {}", spec.name(), path.display());
    let sim = build(spec, &mut |_| {}).expect("the standard beds build");
    std::fs::create_dir_all(path.parent().expect("a folder")).expect("the cache folder");
    std::fs::write(&path, serde_json::to_string(&sim).expect("serialisable")).expect("the cache file");
    sim
}

fn particle_steps(c: &mut Criterion) {
    let mut group = c.benchmark_group("settled_bed");
    group.sample_size(10);
    for shape in [ShapeKind::Sphere, ShapeKind::Ellipsoid, ShapeKind::Mesh, ShapeKind::BondedSpheres] {
        let spec = BedSpec::standard(shape);
        let base = bed(&spec);
        group.throughput(Throughput::Elements(base.bodies.len() as u64));
        for threads in [1, 2] {
            for shaken in [false, true] {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
                let mut sim = base.clone();
                sim.shaking = shaken.then_some(Shaking { amplitude: 3e-4, period: 0.025 });
                let state = if shaken { "shaken" } else { "settled" };
                group.bench_function(BenchmarkId::new(spec.name(), format!("{threads} threads, {state}")), |b| {
                    pool.install(|| b.iter(|| sim.step().unwrap()))
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, particle_steps);
criterion_main!(benches);
