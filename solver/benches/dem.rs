//! Particle-steps per second of the DEM engine on the standard settled beds of `solver::bed`
//! (the same beds as `sedpack bench`), with 1 and 2 threads, at rest and shaken (Eq. 14): the
//! LAMMPS comparison bed of 2,450 spheres, and 2,000 ellipsoids, Rhine-scan polyhedra and
//! bonded-sphere grains. Beds are built once and cached in target/sedpack-bench/.

mod beds;

use beds::bed;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use solver::bed::BedSpec;
use solver::dem::Shaking;
use solver::packing::ShapeKind;

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
