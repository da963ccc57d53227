//! Physics of the DEM engine with ellipsoids: restitution and duration of collisions, friction on
//! a slope, conservation laws in free collisions and free rotation, and a grain settling on its
//! flattest side.

use nalgebra::{UnitQuaternion, Vector3};
mod common;

use common::{collide, momenta, settings, slide_x};
use solver::dem::{Domain, NewBody, Shape, Simulation};

const G: f64 = 9.81;

fn ellipsoid(
    axes: [f64; 3],
    position: Vector3<f64>,
    orientation: UnitQuaternion<f64>,
    velocity: Vector3<f64>,
) -> NewBody {
    NewBody {
        shape: Shape::Ellipsoid { semi_axes: Vector3::from(axes) },
        position,
        orientation,
        velocity,
        angular_velocity: Vector3::zeros(),
    }
}

#[test]
fn head_on_ellipsoids_rebound_with_the_restitution_coefficient_after_the_collision_time() {
    // Long axes along the line of centres: the contact normal passes through both centres, so
    // the collision is central and the pair behaves like two spheres of the same masses.
    let a = [4e-3, 2e-3, 1.5e-3];
    let b = [3e-3, 2.5e-3, 1e-3];
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::zeros())).unwrap();
    sim.add_body(ellipsoid(a, Vector3::new(0.03, 0.05, 0.05), UnitQuaternion::identity(), Vector3::new(0.5, 0.0, 0.0)));
    sim.add_body(ellipsoid(
        b,
        Vector3::new(0.03 + 7e-3 + 1.03e-4, 0.05, 0.05),
        UnitQuaternion::identity(),
        Vector3::new(-0.5, 0.0, 0.0),
    ));
    let steps = collide(&mut sim);
    let v = &sim.bodies.velocity;
    let e = v[1].x - v[0].x;
    // Accepted: 2 % off e_n, 5 % off T_c.
    assert!((e - 0.1).abs() < 0.002, "restitution {e}");
    assert!((steps as f64 * 5e-6 - 2e-4).abs() < 0.05 * 2e-4, "contact lasted {steps} steps");
    assert!(sim.bodies.angular_velocity.iter().all(|w| w.norm() < 1e-9), "a central collision spins nothing");
}

#[test]
fn an_oblique_collision_of_tilted_ellipsoids_conserves_momentum() {
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::zeros())).unwrap();
    let tilt = |x: f64, y: f64, z: f64| UnitQuaternion::from_euler_angles(x, y, z);
    sim.add_body(ellipsoid(
        [4e-3, 2e-3, 1e-3],
        Vector3::new(0.03, 0.05, 0.05),
        tilt(0.3, 0.5, 0.9),
        Vector3::new(0.6, 0.05, 0.0),
    ));
    sim.add_body(ellipsoid(
        [3e-3, 3e-3, 1.5e-3],
        Vector3::new(0.0375, 0.0515, 0.0505),
        tilt(-0.7, 0.2, 0.1),
        Vector3::new(-0.4, 0.0, 0.02),
    ));
    let (p0, l0) = momenta(&sim);
    collide(&mut sim);
    let (p1, l1) = momenta(&sim);
    assert!(sim.bodies.angular_velocity.iter().all(|w| w.norm() > 1.0), "an eccentric impact spins both");
    // Equal and opposite forces at one point: linear momentum to round-off. Angular momentum
    // also carries the first-order integrator's drift in the tumbling of the spun bodies, of
    // order 1e-4 per 0.1 s (see the free-rotation test); this collision lasts a few ms.
    assert!((p1 - p0).norm() < 1e-12 * p0.norm(), "linear momentum {p0} → {p1}");
    assert!((l1 - l0).norm() < 1e-4 * l0.norm(), "angular momentum {l0} → {l1}");
}

/// Relative drift of angular momentum and kinetic energy of a body tumbling freely for 0.1 s.
fn tumble(time_step: f64) -> (f64, f64, f64) {
    let mut s = settings(0.1, 0.5, Vector3::zeros());
    s.time_step = time_step;
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, s).unwrap();
    let mut body =
        ellipsoid([4e-3, 2e-3, 1e-3], Vector3::new(0.05, 0.05, 0.05), UnitQuaternion::identity(), Vector3::zeros());
    body.angular_velocity = Vector3::new(20.0, 30.0, 40.0);
    sim.add_body(body);
    let (_, l0) = momenta(&sim);
    let e0 = sim.bodies.kinetic_energy();
    for _ in 0..(0.1 / time_step).round() as usize {
        sim.step().unwrap();
    }
    let (_, l1) = momenta(&sim);
    let turned = (sim.bodies.angular_velocity[0].normalize() - Vector3::new(20.0, 30.0, 40.0).normalize()).norm();
    ((l1 - l0).norm() / l0.norm(), ((sim.bodies.kinetic_energy() - e0) / e0).abs(), turned)
}

#[test]
fn free_rotation_of_an_asymmetric_body_conserves_angular_momentum_to_first_order() {
    // No contact, no gravity: Euler's equations with the world-frame inertia from the current
    // orientation. Spun about an axis between its principal axes the body tumbles; L and the
    // kinetic energy are constants of the motion, which the first-order scheme keeps up to a
    // drift proportional to Δt: halving Δt halves it.
    let (l_coarse, e_coarse, turned) = tumble(5e-6);
    let (l_fine, e_fine, _) = tumble(2.5e-6);
    assert!(turned > 0.01, "it tumbles");
    assert!(l_coarse < 1e-3 && e_coarse < 1e-3, "drift {l_coarse}, {e_coarse} at the paper's Δt");
    for (coarse, fine) in [(l_coarse, l_fine), (e_coarse, e_fine)] {
        let order = coarse / fine;
        assert!((1.7..2.3).contains(&order), "first order: drift {coarse} → {fine} for Δt/2");
    }
}

/// A flat ellipsoid (5 × 5 × 1.5 mm semi-axes) resting on a plane inclined by θ (gravity
/// tilted); returns its displacement along the slope and its acceleration fitted over `time` s.
/// Laid flat it is not quite at rest: it rocks about its slightly tilted equilibrium without
/// loss (the contact law has no rolling resistance), so a strongly damped start (Eq. 15) settles
/// it first when it sticks.
fn slide(theta_degrees: f64, friction: f64, time: f64, settle: bool) -> (f64, f64) {
    let theta = theta_degrees.to_radians();
    let g = Vector3::new(G * theta.sin(), 0.0, -G * theta.cos());
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, friction, g)).unwrap();
    let c = 1.5e-3;
    sim.add_body(ellipsoid([5e-3, 5e-3, c], Vector3::new(0.03, 0.05, c), UnitQuaternion::identity(), Vector3::zeros()));
    if settle {
        sim.damping = Some(1e-12);
        for _ in 0..60_000 {
            sim.step().unwrap();
        }
        sim.damping = None;
    }
    slide_x(&mut sim, time)
}

#[test]
fn an_ellipsoid_on_a_slope_sticks_or_slides_by_friction() {
    let g_eff = G * 1650.0 / 2650.0;
    // tan 20° = 0.36 < μ = 0.5: the tangential spring holds it. What remains of the rocking moves
    // its centre by about 1 µm; sliding freely it would cover g' sin θ t²/2 ≈ 10 mm in 0.1 s.
    let (dx, _) = slide(20.0, 0.5, 0.1, true);
    assert!(dx.abs() < 1e-5, "sticks: moved {dx} m");
    // tan 35° = 0.70 > μ = 0.5: it slides with a = g'(sin θ − μ cos θ) = 1.00 m/s².
    let theta = 35f64.to_radians();
    let (_, a) = slide(35.0, 0.5, 0.2, false);
    let expected = g_eff * (theta.sin() - 0.5 * theta.cos());
    // 1 %: the rocking adds ±0.05 mm to a 20 mm slide.
    assert!((a - expected).abs() < 0.01 * expected, "slides: {a} vs {expected}");
}

#[test]
fn a_dropped_ellipsoid_comes_to_rest_on_its_flattest_side() {
    // Dropped standing on its long axis (tilted a little), it topples and rests with its short
    // axis vertical: the only stable equilibrium, the lowest centre of mass.
    let mut sim =
        Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::new(0.0, 0.0, -G))).unwrap();
    let q = UnitQuaternion::from_euler_angles(0.0, std::f64::consts::FRAC_PI_2 - 0.2, 0.3);
    sim.add_body(ellipsoid([4e-3, 2.5e-3, 1e-3], Vector3::new(0.05, 0.05, 4.5e-3), q, Vector3::zeros()));
    for _ in 0..40_000 {
        sim.step().unwrap();
    }
    // Rolling without slipping loses nothing in this contact law, so the rocking is damped out
    // as in the packing protocol (Eq. 15), more strongly.
    sim.damping = Some(1e-6);
    for _ in 0..100_000 {
        sim.step().unwrap();
    }
    let short_axis = sim.bodies.orientation[0] * Vector3::z();
    assert!(short_axis.z.abs() > 0.999, "short axis {short_axis} should be vertical");
    // Resting on its side: the centre at height c = 1 mm minus the small static overlap.
    let z = sim.bodies.position[0].z;
    assert!((z - 1e-3).abs() < 1e-5, "height {z}");
}
