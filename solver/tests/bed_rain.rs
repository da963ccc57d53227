//! The raining state of `sedpack bench` (`solver::bed::rain`): a layer of new grains placed
//! above a settled bed falls freely, none touching another, until it lands on the bed.

use solver::bed::{BedSpec, RAIN_GAP, build, rain};
use solver::dem::Shaking;
use solver::packing::ShapeKind;

#[test]
fn a_rained_layer_falls_freely_and_lands_on_the_bed() {
    let spec = BedSpec { shape: ShapeKind::Mesh, grains: 100, seed: 7 };
    let mut sim = build(&spec, &mut |_| {}).expect("the bed settles");
    let old = sim.bodies.len();
    sim.shaking = Some(Shaking { amplitude: 3e-4, period: 0.025 });
    let added = rain(&spec, &mut sim);
    let b = &sim.bodies;
    assert_eq!(b.len(), old + added);
    // One layer of the box: its sites are at least 2.1 reaches of the longest grain apart.
    let width = sim.domain.width();
    let longest = (old..b.len()).map(|k| b.bounding_radius[k]).fold(0.0, f64::max);
    let sites = ((width / (2.1 * longest)).floor() as usize).pow(2);
    assert!(added >= 4 && added <= sites, "{added} grains on {sites} sites");
    for k in old..b.len() {
        assert!((b.velocity[k].z + 1.0).abs() < 1e-12, "grain {k} falls at 1 m/s");
    }

    // Until the gap closes (at 1 m/s it takes RAIN_GAP / 1 m/s, less by gravity's share), every
    // new grain falls freely: v_z = −1 m/s + a t with a = g (ρ − ρ_f) / ρ, to round-off over the
    // steps. A grain placed touching another would be pushed off this at once.
    let m = sim.settings.material;
    let a = m.weight_per_volume().z / m.density;
    let dt = sim.settings.time_step;
    let free = (0.9 * RAIN_GAP / 1.0 / dt) as u64;
    for _ in 0..free {
        sim.step().expect("a step");
    }
    let t = free as f64 * dt;
    for k in old..sim.bodies.len() {
        let vz = sim.bodies.velocity[k].z;
        assert!((vz - (-1.0 + a * t)).abs() < 1e-9, "grain {k}: v_z = {vz} m/s, free fall gives {}", -1.0 + a * t);
    }

    // By 10 ms (the default measurement of the standard bed: 4e6 particle-steps on 2,000 grains
    // are 2,000 steps of Δt = 5e-6 s) most have landed: a grain that hit the bed has lost most of its
    // speed (e = 0.1), where free fall would have reached 1.06 m/s.
    for _ in free..2000 {
        sim.step().expect("a step");
    }
    let landed = (old..sim.bodies.len()).filter(|&k| sim.bodies.velocity[k].z > -0.5).count();
    assert!(4 * landed >= 3 * added, "{landed} of {added} landed by 10 ms");
}
