//! Imbrication from the drag of a current. Gravel deposited by a current is imbricated: a grain
//! leans on its downstream neighbour with its long axis dipping upstream, shingled like roof
//! tiles, the fabric `solver::fabric` measures. The mechanism is the drag's direction: a grain
//! propped on its downstream neighbour is pressed onto its prop by the current, and one propped
//! on its upstream neighbour (dipping downstream) is pushed off it and falls flat.
//!
//! The test puts a bonded-sphere rod, leaning 20° with its foot on the floor, with its upper end
//! on the edge of a flat slab lying downstream or upstream of it, in a logarithmic current over
//! the floor, with the second paper's fluid forces (Sun & Xiao Eqs. 3–7: Syamlal's drag on each
//! component sphere at the fluid velocity of its height, summed into force and torque; Saffman's
//! lift, Eq. 8), and checks that only the rod dipping upstream keeps its lean; without the current
//! both do. A drag of the wrong sign would keep the other rod instead, and no drag both. The
//! rods' fate hangs on the drag's net force: the torque the profile adds (a few % of the weight's)
//! would not change it, so the last test checks that torque on its own.

mod common;

use common::{box_shape, settings};
use nalgebra::{UnitQuaternion, Vector3};
use solver::dem::{Domain, NewBody, Shape, Simulation};
use solver::fabric::{Imbrication, imbrication};
use solver::fluid::flow::Flow;
use solver::fluid::{Fluid, FluidResponse, Scratch, WATER};
use solver::grain::{FormParameters, bonded_grain};

/// Diameter of the rod's three spheres (m): a 12 × 4 × 4 mm rod of nominal diameter 5.8 mm.
const D: f64 = 4e-3;
/// The rod's lean (°) and the angle (°) from the vertical of its contact normal at the prop's
/// edge, which leans the rod away from the prop: with a frictionless edge the foot then needs a
/// friction coefficient of 0.25 (statics of the leaning rod), half the material's 0.5.
const DIP: f64 = 20.0;
const EDGE: f64 = 20.0;
/// The slab the rod leans on: 20 × 20 mm, 11 times the rod's weight.
const SLAB: f64 = 0.02;
/// Roughness length z₀ = k_s/30 (Nikuradse) of a gravel bed with k_s ≈ 2 D_n of the rod, 12 mm.
const ROUGHNESS: f64 = 4e-4;
/// Bed shear velocity (m/s), from the drag on the rod against its weight and friction: the rod
/// dipping downstream is held by the friction at its foot, which statics with a frictionless prop
/// leaves 0.15 of its weight to spare (the edge's friction adds more), so the current must push
/// with a good part of the weight; at u* = 0.055 m/s the drag is 0.43–0.47 of it (Shields number
/// u*²/((ρ_s/ρ_f − 1) g D_n) = 0.032, below the ~0.045 that moves a bed of such grains) and the
/// slab's drag (Haider & Levenspiel's at its centre height) 0.36 of its weight, within its
/// friction with the rod's push added. Measured, the rod dipping downstream stays up to 0.0475
/// m/s and the slab starts sliding between 0.06 and 0.065 m/s: the window is that narrow.
const SHEAR_VELOCITY: f64 = 0.055;
/// Steps to settle on the contacts, then to run with or without the current (0.2 s: the rod
/// pushed off falls and comes to rest in ~0.1 s).
const SETTLE: usize = 10_000;
const RUN: usize = 40_000;

/// Which way the rod's long axis dips, against the flow +x.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Lean {
    /// Foot upstream, upper end on a slab downstream: imbricated.
    Upstream,
    /// Foot downstream, upper end on a slab upstream.
    Downstream,
}

fn body(shape: Shape, position: Vector3<f64>, orientation: UnitQuaternion<f64>) -> NewBody {
    NewBody { shape, position, orientation, velocity: Vector3::zeros(), angular_velocity: Vector3::zeros() }
}

/// The rod on the floor at body 0, leaning on the slab's edge at body 1, at rest.
fn leaning(lean: Lean) -> Simulation {
    let r = D / 2.0;
    let rod = Shape::from(&bonded_grain(&FormParameters::new(3.0 * D, D, D).unwrap()).unwrap());
    // +1 when the upper end points downstream; the end spheres' centres are 2 D apart.
    let s = if lean == Lean::Upstream { 1.0 } else { -1.0 };
    let (dip, edge) = (DIP.to_radians(), EDGE.to_radians());
    let foot = Vector3::new(0.04, 0.05, r);
    let top = foot + 2.0 * D * Vector3::new(s * dip.cos(), 0.0, dip.sin());
    // The edge under the top sphere, r sin(EDGE) beyond its centre, sets the slab's height.
    let (height, edge_x) = (top.z - r * edge.cos(), top.x + s * r * edge.sin());
    let slab = box_shape(SLAB, SLAB, height);
    let gravity = Vector3::new(0.0, 0.0, -9.81);
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, gravity)).unwrap();
    // The rod's long axis is its body x: turned about y by −s·dip its +x end rises to +s x.
    sim.add_body(body(rod, (foot + top) / 2.0, UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -s * dip)));
    let slab_centre = Vector3::new(edge_x + s * SLAB / 2.0, 0.05, height / 2.0);
    sim.add_body(body(slab, slab_centre, UnitQuaternion::identity()));
    sim
}

/// The logarithmic current over the floor, every 20 steps (1e-4 s); cells half the domain wide,
/// since two grains are no suspension: ε_f ≥ 0.99 leaves the hindrance of Eqs. 6–7 at 1.
fn current(flow: Flow) -> Fluid {
    Fluid { viscosity: WATER.viscosity, flow, lift: true, cell: 0.05, slice: 5e-3, cutoff: 0.5, coupling: 20 }
}

fn log_profile() -> Flow {
    Flow::Logarithmic { shear_velocity: SHEAR_VELOCITY, roughness: ROUGHNESS }
}

/// The rod's fabric (it is the only grain with a long axis).
fn fabric(sim: &Simulation) -> Imbrication {
    imbrication(&sim.bodies.shape[..1], &sim.bodies.orientation[..1]).unwrap()
}

struct Outcome {
    before: Imbrication,
    after: Imbrication,
    /// Displacements of the rod's centre and of the slab while the current ran (or not).
    rod: Vector3<f64>,
    slab: f64,
}

/// The rod leaning `lean` settled on its contacts, then run for `RUN` steps in `fluid`.
fn run(lean: Lean, fluid: Option<Fluid>) -> Outcome {
    let mut sim = leaning(lean);
    for _ in 0..SETTLE {
        sim.step().unwrap();
    }
    let (before, start) = (fabric(&sim), sim.bodies.position.clone());
    sim.fluid = fluid;
    for _ in 0..RUN {
        sim.step().unwrap();
    }
    let p = &sim.bodies.position;
    Outcome { before, after: fabric(&sim), rod: p[0] - start[0], slab: (p[1] - start[1]).norm() }
}

/// Checks the settled rod leans as placed: 20° (its contacts' springs sag by ~10 nm, 1e-4° over
/// the rod), all upstream or all downstream.
fn assert_leans(f: &Imbrication, lean: Lean) {
    assert!((f.mean_dip - DIP).abs() < 0.01, "{lean:?}: dip {}°", f.mean_dip);
    // Nothing breaks the symmetry across the flow, so the direction is 180° or 0° to rounding.
    let (share, direction) = if lean == Lean::Upstream { (1.0, 180.0) } else { (0.0, 0.0) };
    assert_eq!(f.upstream, share, "{lean:?}");
    assert!((f.resultant_direction.abs() - direction).abs() < 1e-6, "{lean:?}: {}°", f.resultant_direction);
}

/// Checks a rod held by static friction: it and the slab move only by the contact springs'
/// elastic give (k_n = m_eff (π² + ln² e_n)/T_c² ≈ 1e5 N/m for the rod, 1e6 for the slab, against
/// 1 mN and 7 mN of drag: ~10 nm, 1e-4° of dip), so 1 µm and 1° are far above that and far below
/// sliding off the prop (mm, 20°).
fn assert_held(o: &Outcome, lean: Lean) {
    assert_leans(&o.before, lean);
    assert_leans(&o.after, lean);
    let turned = (o.after.mean_dip - o.before.mean_dip).abs();
    assert!(turned < 1.0 && o.rod.norm() < 1e-6, "{lean:?}: turned {turned}°, moved {} m", o.rod.norm());
    assert!(o.slab < 1e-6, "{lean:?}: the slab moved {} m", o.slab);
}

#[test]
fn without_a_current_a_rod_leaning_either_way_on_a_slab_stays_at_rest() {
    // The control: the rod dipping downstream needs 0.25 of friction at its foot, held by 0.5.
    for lean in [Lean::Upstream, Lean::Downstream] {
        assert_held(&run(lean, None), lean);
    }
}

#[test]
fn a_current_presses_a_rod_dipping_upstream_onto_its_prop_and_pushes_one_dipping_downstream_off() {
    // Measured: the imbricated rod turns by 2e-5° and moves 12 nm; the other one ends with a
    // dip of 2e-5° (three spheres on the floor), its centre 1.9 mm downstream; the slab moves 8 nm.
    let imbricated = run(Lean::Upstream, Some(current(log_profile())));
    assert_held(&imbricated, Lean::Upstream);
    let pushed = run(Lean::Downstream, Some(current(log_profile())));
    assert_leans(&pushed.before, Lean::Downstream);
    // Lying on its three spheres it has no dip; on anything else it would keep degrees of it.
    assert!(pushed.after.mean_dip < 1.0, "dip {}° after the current", pushed.after.mean_dip);
    // Pushed off downstream: falling flat about a foot that stays would move its centre upstream.
    assert!(pushed.rod.x > 0.0, "moved {} m along the flow", pushed.rod.x);
    assert!(pushed.slab < 1e-6, "the slab moved {} m", pushed.slab);
}

/// The fluid torque about y on the rod (body 0) leaning `lean`, at rest in `flow`.
fn torque(lean: Lean, flow: Flow) -> f64 {
    let sim = leaning(lean);
    let (mut scratch, mut responses) = (Scratch::default(), Vec::<FluidResponse>::new());
    let density = sim.settings.material.fluid_density;
    current(flow).update(&sim.bodies, &sim.domain, density, &mut scratch, &mut responses);
    // Two grains cover too little of the floor to make a bed: the profile starts at the floor.
    assert_eq!(scratch.bed, 0.0);
    responses[0].load(&Vector3::zeros(), &Vector3::zeros()).1.y
}

#[test]
fn the_current_turns_a_leaning_rods_upper_end_downstream_because_it_grows_with_height() {
    // A positive torque about y turns the rod's upper end downstream: onto its prop when it dips
    // upstream, up off it when it dips downstream. It comes from the profile: the rod's spheres
    // see faster water the higher they sit. In a uniform stream of the speed at the rod's centre
    // only the shelter of the spheres behind the leading one is left, which turns the rod dipping
    // upstream the other way (its lower sphere leads). Measured, in units of the weight's torque
    // about the foot: +0.028 and +0.066 in the profile, −0.020 and +0.020 in the uniform stream.
    let centre = leaning(Lean::Upstream).bodies.position[0];
    let uniform = Flow::Uniform { velocity: log_profile().at(&centre, 0.0, WATER.kinematic_viscosity()).0 };
    for lean in [Lean::Upstream, Lean::Downstream] {
        let (profile, stream) = (torque(lean, log_profile()), torque(lean, uniform));
        assert!(profile > 0.0 && profile > stream, "{lean:?}: {profile} N m in the profile, {stream} N m uniform");
    }
    assert!(torque(Lean::Upstream, uniform) < 0.0, "the shelter alone turns the imbricated rod's upper end up");
}
