//! What fluid forces cost a step: the settled bed of 2,000 bonded-sphere grains of
//! `solver::bed` (the same bed, and cache file, as the `dem` benchmark), stepped with fluid
//! forces off, in still water, and under a logarithmic current (u* = 0.05 m/s, z₀ = 0.23 mm,
//! measured from the bed surface), at rest and shaken (Eq. 14), on 1 and 2 threads, the fluid
//! forces updated every 1e-4 s (the default) and, under the current, every step. Each variant
//! also prints the fluid stage's share of the step (`Simulation::stage_times`).

mod beds;

use beds::bed;
use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use solver::bed::BedSpec;
use solver::dem::Shaking;
use solver::fluid::flow::Flow;
use solver::packing::{FLUID_COUPLING, FluidSpec, ShapeKind};

fn fluid_cost(c: &mut Criterion) {
    let spec = BedSpec::standard(ShapeKind::BondedSpheres);
    let base = bed(&spec);
    // The bed's grains are of the 5.6–8 mm class: cells of three largest grains (Derived::fluid_cell).
    let forces = |flow: Flow, coupling: u32| solver::fluid::Fluid {
        viscosity: FluidSpec::STILL_WATER.viscosity,
        flow,
        lift: true,
        cell: 3.0 * 8e-3,
        slice: 1e-3,
        cutoff: 0.5,
        coupling,
    };
    // Updated every 1e-4 s as packings are, and every step: what one update costs.
    let every = (FLUID_COUPLING / base.settings.time_step).round() as u32;
    let current = Flow::Logarithmic { shear_velocity: 0.05, roughness: 2.3e-4 };
    let variants = [
        ("off", None),
        ("still water", Some(forces(Flow::Quiescent, every))),
        ("current", Some(forces(current, every))),
        ("current, updated every step", Some(forces(current, 1))),
    ];
    let mut group = c.benchmark_group("fluid");
    group.sample_size(10);
    group.throughput(Throughput::Elements(base.bodies.len() as u64));
    for threads in [1, 2] {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
        for shaken in [false, true] {
            for (name, fluid) in variants {
                let mut sim = base.clone();
                sim.fluid = fluid;
                sim.shaking = shaken.then_some(Shaking { amplitude: 3e-4, period: 0.025 });
                let state = if shaken { "shaken" } else { "settled" };
                group.bench_function(
                    BenchmarkId::new(spec.name(), format!("{threads} threads, {state}, {name}")),
                    |b| pool.install(|| b.iter(|| sim.step().unwrap())),
                );
                let t = sim.stage_times();
                let total = t.neighbours + t.fluid + t.contacts + t.bodies;
                eprintln!("  fluid stage: {:.1} % of the step", 100.0 * t.fluid.as_secs_f64() / total.as_secs_f64());
            }
        }
    }
    group.finish();
}

criterion_group!(benches, fluid_cost);
criterion_main!(benches);
