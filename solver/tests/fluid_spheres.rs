//! One sphere in still water under the second paper's drag law (Sun & Xiao Eqs. 3–7, Dalla
//! Valle's curve at ε_f = 1): its terminal velocity against the law's closed form and against
//! the standard drag curve, and its approach to it in the Stokes regime.

use std::sync::OnceLock;

use nalgebra::{UnitQuaternion, Vector3};
use solver::dem::{Calibration, ContactPoint, Domain, Material, NewBody, Settings, Shape, Simulation};
use solver::fluid::drag::FluidProperties;
use solver::fluid::flow::Flow;
use solver::fluid::settling::{Drop, Settling, drop, sphere_terminal_velocity};
use solver::fluid::{Fluid, WATER};

/// Quartz in the papers' water (§4.2).
fn material() -> Material {
    Material::default()
}

/// Diameters (m) whose terminal Reynolds numbers span 0.1 (50 µm) to 1.2 × 10⁴ (13 mm).
const DIAMETERS: [f64; 8] = [5e-5, 1e-4, 2e-4, 5e-4, 1e-3, 2e-3, 5e-3, 1.3e-2];

/// Each diameter dropped once, shared by the tests of this file.
fn drops() -> &'static [(f64, Settling)] {
    static DROPS: OnceLock<Vec<(f64, Settling)>> = OnceLock::new();
    DROPS.get_or_init(|| {
        DIAMETERS
            .iter()
            .map(|&d| {
                let run = Drop {
                    shape: Shape::Sphere { radius: d / 2.0 },
                    material: material(),
                    viscosity: WATER.viscosity,
                    orientation: UnitQuaternion::identity(),
                };
                (d, drop(&run).expect("a lone sphere settles"))
            })
            .collect()
    })
}

#[test]
fn a_sphere_settles_at_the_closed_form_terminal_velocity_of_its_drag_law() {
    // Weight minus buoyancy equals the drag of Eqs. 3–7 at ε_f = 1: 0.63 Re + 4.8 √Re =
    // √(4 Ar/3) solved for Re. The simulation's fixed point is that balance, so only the
    // stopping rule (speed steady to 1e-5 over 5 relaxation times) separates them; 1 % is the
    // issue's bound.
    for (d, s) in drops() {
        let exact = sphere_terminal_velocity(&WATER, 2650.0, 9.81, *d);
        let error = s.terminal_velocity / exact - 1.0;
        assert!(error.abs() < 0.01, "d = {d} m: {} m/s against {exact} m/s", s.terminal_velocity);
        assert!(s.drift < 1e-12 * exact, "a sphere falls straight: {}", s.drift);
    }
    let (reynolds_low, reynolds_high) = (drops()[0].1.reynolds, drops()[DIAMETERS.len() - 1].1.reynolds);
    assert!(reynolds_low < 0.15 && reynolds_high > 1e4, "{reynolds_low} … {reynolds_high}");
}

/// Brown & Lawler (2003), "Sphere drag and settling velocity revisited", J. Environ. Eng. 129,
/// 222–231, Eq. 19: the standard drag curve fitted to 480 measurements corrected for walls,
/// C_D = 24/Re (1 + 0.150 Re^0.681) + 0.407/(1 + 8710/Re), Re < 2 × 10⁵.
fn standard_curve(re: f64) -> f64 {
    24.0 / re * (1.0 + 0.150 * re.powf(0.681)) + 0.407 / (1.0 + 8710.0 / re)
}

/// Terminal velocity of a sphere under the standard curve: C_D Re² = 4 Ar/3 by bisection in
/// log Re (C_D Re² rises with Re).
fn standard_velocity(fluid: &FluidProperties, d: f64) -> f64 {
    let ar = (2650.0 - fluid.density) * fluid.density * 9.81 * d.powi(3) / fluid.viscosity.powi(2);
    let (mut lo, mut hi) = (-8.0f64, 8.0f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        let re = 10f64.powf(mid);
        if standard_curve(re) * re * re < 4.0 * ar / 3.0 { lo = mid } else { hi = mid }
    }
    10f64.powf(lo) * fluid.viscosity / (fluid.density * d)
}

#[test]
fn against_the_standard_drag_curve_a_sphere_under_the_papers_law_settles_up_to_14_percent_slow() {
    // Dalla Valle's curve, the paper's (Eq. 4), lies above the standard curve: by 1 % at
    // Re = 0.1, 7 % at 1, 12 % at 10, 32 % near 10³ (C_D of the two formulas). Measured spheres
    // scatter about the standard curve by a few per cent, so the paper's law agrees with them
    // within that scatter only for Re_p ≲ 0.2; above, a sphere under it settles slower than
    // measured spheres, by up to 14 % near Re_p = 10³ (simulated: 0.989 of the standard curve's
    // velocity at Re_p = 0.11, 0.947 at 0.75, 0.92 at 4.6–36, 0.91 at 142, 0.87 at 490, 0.86 at
    // 2240, 0.95 at 1.0 × 10⁴). The check pins that envelope: within 2 % for Re_p ≤ 0.2, between
    // 0.85 and 1 up to 1.2 × 10⁴.
    for (d, s) in drops() {
        let standard = standard_velocity(&WATER, *d);
        let ratio = s.terminal_velocity / standard;
        let lowest = if s.reynolds <= 0.2 { 0.98 } else { 0.85 };
        assert!(ratio <= 1.0 && ratio > lowest, "d = {d} m, Re_p {}: {ratio}", s.reynolds);
    }
}

#[test]
fn a_sphere_starting_at_rest_approaches_its_terminal_velocity_as_stokes_drag_says() {
    // d = 20 µm: Re_t = 7.6e-3. Under linear drag the speed is u_t (1 − e^(−t/τ)) with
    // τ = u_t/g' and g' = (1 − ρ_f/ρ_p) g. Dalla Valle's curve is linear to within its
    // 6.048 √Re/23.04 term, 2.3 % at Re_t, which bounds the departure of u/u_t from the
    // exponential (it is largest, ~0.8 %, while the grain accelerates); 1 % is the check, with
    // the fluid forces updated every step and every 40 steps (τ/10): between updates the drag
    // coefficient is held and the drag follows the velocity, which under linear drag is exact.
    let d = 2e-5;
    let m = material();
    let exact = sphere_terminal_velocity(&WATER, m.density, 9.81, d);
    let tau = exact / (9.81 * (1.0 - m.fluid_density / m.density));
    let time_step = tau / 400.0;
    for coupling in [1, 40] {
        let settings = Settings {
            material: m,
            time_step,
            skin: 1e-6,
            calibration: Calibration::Discrete,
            contact_point: ContactPoint::CentreOfPressure,
        };
        let mut sim = Simulation::new(Domain::Periodic { width: 1e-3 }, settings).unwrap();
        sim.add_body(NewBody {
            shape: Shape::Sphere { radius: d / 2.0 },
            position: Vector3::new(5e-4, 5e-4, 5e-4),
            orientation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
        });
        sim.fluid = Some(Fluid::still(WATER.viscosity, 1e-3, coupling));
        let mut worst: f64 = 0.0;
        for _ in 0..(8 * 400) {
            sim.step().unwrap();
            let analytic = 1.0 - (-sim.time / tau).exp();
            worst = worst.max((-sim.bodies.velocity[0].z / exact - analytic).abs());
        }
        assert!(worst < 0.01, "coupling {coupling}: largest departure {worst}");
        assert!((-sim.bodies.velocity[0].z / exact - 1.0).abs() < 1e-3, "coupling {coupling}");
    }
}

#[test]
fn a_sphere_at_rest_over_the_bed_of_a_sheared_flow_is_lifted_by_eq_8() {
    // A 2 mm sphere held at rest with its centre 1.5 mm above the floor (the bed: one sphere
    // makes no surface of §4.4) in laminar open-channel flow, u* = 0.01 m/s, depth 0.05 m:
    // U = (u*²/ν)(z − z²/2h), G = dU/dz = (u*²/ν)(1 − z/h). One step from rest: the vertical
    // change of velocity is (lift − (ρ_p − ρ_f) V g) Δt/m, the horizontal one drag Δt/m.
    let m = material();
    let (d, z) = (2e-3, 1.5e-3);
    let flow = Flow::Laminar { shear_velocity: 0.01, depth: 0.05 };
    let settings = Settings {
        material: m,
        time_step: 5e-6,
        skin: 1e-4,
        calibration: Calibration::Discrete,
        contact_point: ContactPoint::CentreOfPressure,
    };
    let mut sim = Simulation::new(Domain::Periodic { width: 0.04 }, settings).unwrap();
    sim.add_body(NewBody {
        shape: Shape::Sphere { radius: d / 2.0 },
        position: Vector3::new(0.02, 0.02, z),
        orientation: UnitQuaternion::identity(),
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
    });
    sim.fluid =
        Some(Fluid { viscosity: WATER.viscosity, flow, lift: true, cell: 0.01, slice: 1e-3, cutoff: 0.5, coupling: 1 });
    sim.step().unwrap();
    let nu = WATER.viscosity / WATER.density;
    let rate = 0.01f64.powi(2) / nu;
    let (u, g) = (rate * (z - z * z / 0.1), rate * (1.0 - z / 0.05));
    let volume = std::f64::consts::PI * d.powi(3) / 6.0;
    let mass = m.density * volume;
    let lift = sim.bodies.velocity[0].z * mass / 5e-6 + (m.density - m.fluid_density) * volume * 9.81;
    let saffman = 1.6 * WATER.density * nu.sqrt() * d * d * u * g.sqrt();
    assert!((lift / saffman - 1.0).abs() < 1e-6, "lift {lift} N against {saffman} N");
    assert!(saffman > 0.0, "a grain lagging the flow is lifted");
    // Drag along the flow: Eqs. 3–7 for a sphere alone at slip U.
    let re = WATER.density * d * u / WATER.viscosity;
    let drag = (0.63 + 4.8 / re.sqrt()).powi(2) * 0.5 * WATER.density * u * u * std::f64::consts::PI * d * d / 4.0;
    assert!((sim.bodies.velocity[0].x * mass / 5e-6 / drag - 1.0).abs() < 1e-9);
}
