//! Physics of polyhedron and bonded-sphere grains in the engine: a cube on a slope sticks or
//! slides by μ (and creeps under the paper's software's single contact point), a cube dropped on
//! its corner comes to rest on a face, bonded grains rebound with e_n and conserve momentum, and
//! a bonded rod comes to rest lying down.

mod common;

use common::{box_shape, momenta, settings, slide_x};
use nalgebra::{UnitQuaternion, Vector3};
use solver::dem::{ContactPoint, Domain, NewBody, Settings, Shape, Simulation};
use solver::grain::{FormParameters, bonded_grain};

const G: f64 = 9.81;

fn body(shape: Shape, position: Vector3<f64>, orientation: UnitQuaternion<f64>, velocity: Vector3<f64>) -> NewBody {
    NewBody { shape, position, orientation, velocity, angular_velocity: Vector3::zeros() }
}

/// A grain resting on the floor in `orientation` with its centre at `height`, under gravity
/// tilted by θ (a plane inclined by θ): after 0.1 s of settling, its displacement along the
/// slope, its acceleration and the angle it turned by over the next `time` s.
fn on_slope(
    shape: Shape,
    orientation: UnitQuaternion<f64>,
    height: f64,
    theta_degrees: f64,
    time: f64,
) -> (f64, f64, f64) {
    on_slope_with(ContactPoint::CentreOfPressure, shape, orientation, height, theta_degrees, time)
}

/// [`on_slope`] with the given contact point rule.
fn on_slope_with(
    rule: ContactPoint,
    shape: Shape,
    orientation: UnitQuaternion<f64>,
    height: f64,
    theta_degrees: f64,
    time: f64,
) -> (f64, f64, f64) {
    let theta = theta_degrees.to_radians();
    let g = Vector3::new(G * theta.sin(), 0.0, -G * theta.cos());
    let settings = Settings { contact_point: rule, ..settings(0.1, 0.5, g) };
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings).unwrap();
    sim.add_body(body(shape, Vector3::new(0.05, 0.05, height), orientation, Vector3::zeros()));
    for _ in 0..20_000 {
        sim.step().unwrap();
    }
    let q0 = sim.bodies.orientation[0];
    let (dx, a) = slide_x(&mut sim, time);
    (dx, a, sim.bodies.orientation[0].angle_to(&q0))
}

#[test]
fn a_cube_on_a_slope_sticks_or_slides_by_friction() {
    let g_eff = G * 1650.0 / 2650.0;
    let cube_on_slope =
        |theta, time| on_slope(box_shape(0.01, 0.01, 0.01), UnitQuaternion::identity(), 0.005, theta, time);
    // Below the friction angle (tan⁻¹ μ = 26.57°) the cube is held by its contact's tangential
    // springs and, once settled, does not move: at 20° and at 26.5°, where its centre of
    // pressure sits near the downhill edge, it moves by less than 1 nm in 0.2 s (rounding). With
    // a single contact point it would rock about that point and ratchet down at ~0.2 mm/s.
    for theta in [20.0, 26.5] {
        let (dx, a, turn) = cube_on_slope(theta, 0.2);
        assert!(dx.abs() < 1e-9 && turn < 1e-9, "{theta}°: moved {dx} m, turned {turn} rad, acceleration {a} m/s²");
    }
    // Above it the cube slides flat at a = g'(sin θ − μ cos θ): 0.053 m/s² at 27°, 1.00 m/s² at
    // 35°, within 1 %.
    for theta in [27.0f64, 35.0] {
        let (_, a, _) = cube_on_slope(theta, 0.2);
        let r = theta.to_radians();
        let expected = g_eff * (r.sin() - 0.5 * r.cos());
        assert!((a - expected).abs() < 0.01 * expected, "{theta}°: slides at {a} vs {expected} m/s²");
    }
}

#[test]
fn under_the_paper_softwares_contact_point_a_cube_below_the_friction_angle_creeps() {
    // The paper's software puts a polyhedron's wall contact at its deepest vertex (waLBerla's
    // MESA-PD): a cube resting on a face has its whole support at one corner, rocks about it
    // and, where the centre of pressure holds it still to 1 nm (above), walks down a 20° slope
    // (35 µm in 0.2 s measured, ~0.2 mm/s).
    let (dx, a, turn) =
        on_slope_with(ContactPoint::Witness, box_shape(0.01, 0.01, 0.01), UnitQuaternion::identity(), 0.005, 20.0, 0.2);
    eprintln!("witness point, 20°: moved {dx:e} m, turned {turn:e} rad in 0.2 s, acceleration {a} m/s²");
    assert!(dx > 1e-5, "moved {dx} m, turned {turn} rad");
}

#[test]
fn a_grain_resting_on_any_of_its_faces_neither_tips_nor_creeps() {
    // A 10 × 6 × 3 mm block on a 10° slope, on each of its six faces: it tips only where
    // tan θ exceeds its half-width over its half-height along the slope (3/10 at worst), and it
    // slides only above tan⁻¹ μ, so on every face it must stay put.
    let faces = [
        (UnitQuaternion::identity(), 0.0015),
        (UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::PI), 0.0015),
        (UnitQuaternion::from_axis_angle(&Vector3::x_axis(), std::f64::consts::FRAC_PI_2), 0.003),
        (UnitQuaternion::from_axis_angle(&Vector3::x_axis(), -std::f64::consts::FRAC_PI_2), 0.003),
        (UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2), 0.005),
        (UnitQuaternion::from_axis_angle(&Vector3::y_axis(), -std::f64::consts::FRAC_PI_2), 0.005),
    ];
    for (k, (q, h)) in faces.into_iter().enumerate() {
        let (dx, _, turn) = on_slope(box_shape(0.01, 0.006, 0.003), q, h, 10.0, 0.2);
        assert!(dx.abs() < 1e-9 && turn < 1e-9, "face {k}: moved {dx} m, turned {turn} rad");
    }
}

#[test]
fn a_cube_dropped_on_its_corner_comes_to_rest_on_a_face() {
    // Body diagonal nearly vertical, tipped 3° so that it falls over to one side.
    let diagonal = Vector3::new(1.0, 1.0, 1.0).normalize();
    let onto_corner = UnitQuaternion::rotation_between(&diagonal, &Vector3::z()).unwrap();
    let tip = UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 3f64.to_radians());
    let mut sim =
        Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::new(0.0, 0.0, -G))).unwrap();
    sim.add_body(body(
        box_shape(0.01, 0.01, 0.01),
        Vector3::new(0.05, 0.05, 0.0095),
        tip * onto_corner,
        Vector3::zeros(),
    ));
    for _ in 0..60_000 {
        sim.step().unwrap();
    }
    sim.damping = Some(1e-6);
    for _ in 0..60_000 {
        sim.step().unwrap();
    }
    // Resting on a face: one body axis vertical, the centre half a side above the floor.
    let q = sim.bodies.orientation[0];
    let vertical = [Vector3::x(), Vector3::y(), Vector3::z()].iter().map(|a| (q * a).z.abs()).fold(0.0, f64::max);
    assert!(vertical > 0.9999, "a face down: largest vertical component of a body axis {vertical}");
    let z = sim.bodies.position[0].z;
    assert!((z - 0.005).abs() < 1e-5, "resting height {z}");
}

fn rod(length: f64) -> Shape {
    // L = 3 d, I = S = d: a row of three touching spheres of diameter d (Sun & Xiao §2.4).
    let d = length / 3.0;
    Shape::from(&bonded_grain(&FormParameters::new(length, d, d).unwrap()).unwrap())
}

#[test]
fn bonded_rods_meeting_end_on_rebound_with_the_restitution_coefficient() {
    // End spheres meet on the rods' common axis: a central collision of two rigid bodies, so the
    // pair rebounds with e_n after T_c like two spheres of the rods' masses.
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::zeros())).unwrap();
    sim.add_body(body(
        rod(9e-3),
        Vector3::new(0.03, 0.05, 0.05),
        UnitQuaternion::identity(),
        Vector3::new(0.5, 0.0, 0.0),
    ));
    sim.add_body(body(
        rod(6e-3),
        Vector3::new(0.03 + 7.5e-3 + 1.03e-4, 0.05, 0.05),
        UnitQuaternion::identity(),
        Vector3::new(-0.5, 0.0, 0.0),
    ));
    let (mut steps, mut touched) = (0, false);
    while !(touched && sim.contacts == 0) {
        sim.step().unwrap();
        touched |= sim.contacts > 0;
        steps += (sim.contacts > 0) as u32;
    }
    let v = &sim.bodies.velocity;
    assert!((v[1].x - v[0].x - 0.1).abs() < 0.002, "restitution {}", v[1].x - v[0].x);
    assert!((steps as f64 * 5e-6 - 2e-4).abs() < 1e-5, "contact lasted {steps} steps");
}

#[test]
fn an_oblique_collision_of_bonded_grains_conserves_momentum() {
    let mut sim = Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::zeros())).unwrap();
    let disk = Shape::from(&bonded_grain(&FormParameters::new(9e-3, 6.6e-3, 3e-3).unwrap()).unwrap());
    let turn = UnitQuaternion::from_euler_angles(0.4, 0.9, -0.3);
    sim.add_body(body(
        rod(9e-3),
        Vector3::new(0.03, 0.05, 0.05),
        UnitQuaternion::identity(),
        Vector3::new(0.6, 0.05, 0.0),
    ));
    sim.add_body(body(disk, Vector3::new(0.0385, 0.0522, 0.0508), turn, Vector3::new(-0.4, 0.0, 0.02)));
    let (p0, l0) = momenta(&sim);
    let mut touched = false;
    while !(touched && sim.contacts == 0) {
        sim.step().unwrap();
        touched |= sim.contacts > 0;
    }
    let (p1, l1) = momenta(&sim);
    assert!(sim.bodies.angular_velocity.iter().all(|w| w.norm() > 1.0), "the eccentric impact spins both");
    // As for ellipsoids: exact linear momentum, angular momentum up to the integrator's drift.
    assert!((p1 - p0).norm() < 1e-12 * p0.norm(), "linear momentum {p0} → {p1}");
    assert!((l1 - l0).norm() < 1e-4 * l0.norm(), "angular momentum {l0} → {l1}");
}

#[test]
fn a_bonded_rod_dropped_on_end_comes_to_rest_lying_down() {
    let standing = UnitQuaternion::from_axis_angle(&Vector3::y_axis(), std::f64::consts::FRAC_PI_2 - 0.1);
    let mut sim =
        Simulation::new(Domain::Periodic { width: 0.1 }, settings(0.1, 0.5, Vector3::new(0.0, 0.0, -G))).unwrap();
    sim.add_body(body(rod(9e-3), Vector3::new(0.05, 0.05, 6e-3), standing, Vector3::zeros()));
    for _ in 0..60_000 {
        sim.step().unwrap();
    }
    sim.damping = Some(1e-6);
    for _ in 0..40_000 {
        sim.step().unwrap();
    }
    // Lying: the long (x) axis horizontal, all three spheres (d = 3 mm) on the floor, the
    // centre at the spheres' radius.
    let long_axis = sim.bodies.orientation[0] * Vector3::x();
    assert!(long_axis.z.abs() < 1e-3, "long axis {long_axis}");
    assert!((sim.bodies.position[0].z - 1.5e-3).abs() < 1e-5, "height {}", sim.bodies.position[0].z);
    assert_eq!(sim.contacts, 3, "three component spheres touch the floor");
}

/// The horizontal reach of a turned grain (how far it extends from its centre in the plane,
/// what a cylinder must leave it) and its reach along a direction (up, down, and slanted), against
/// brute-force maxima over its surface: for a box the corners, computed by hand from the
/// rotation; for an ellipsoid, and for each sphere of a bonded rod, points of the surface on a
/// 720 × 360 grid of angles, which can only fall short of the maximum, by less than 1e-4 of it.
#[test]
fn the_horizontal_reach_of_a_turned_grain_is_its_widest_point_in_the_plane() {
    let turns = [
        UnitQuaternion::identity(),
        UnitQuaternion::from_euler_angles(0.3, -1.1, 2.0),
        UnitQuaternion::from_euler_angles(1.4, 0.2, -0.7),
        UnitQuaternion::from_euler_angles(-0.5, 0.9, 0.1),
    ];
    let horizontal = |v: Vector3<f64>| v.x.hypot(v.y);
    let directions = [Vector3::z(), -Vector3::z(), Vector3::new(0.6, -0.48, 0.64)];
    for turn in turns {
        let (a, b, c) = (0.03, 0.02, 0.01);
        let corners: Vec<_> = (0..8)
            .map(|k| {
                let sign = |bit: usize| if k & bit == 0 { -1.0 } else { 1.0 };
                Vector3::new(sign(1) * a / 2.0, sign(2) * b / 2.0, sign(4) * c / 2.0)
            })
            .collect();
        let by_hand = corners.iter().map(|v| horizontal(turn * v)).fold(0.0, f64::max);
        let reach = box_shape(a, b, c).horizontal_reach(&turn);
        assert!((reach - by_hand).abs() < 1e-12, "box: {reach} vs {by_hand}");
        for d in &directions {
            let by_hand = corners.iter().map(|v| (turn * v).dot(d)).fold(f64::MIN, f64::max);
            let reach = box_shape(a, b, c).reach_along(&turn, d);
            assert!((reach - by_hand).abs() < 1e-12, "box along {d:?}: {reach} vs {by_hand}");
        }

        let semi_axes = Vector3::new(0.04, 0.015, 0.006);
        let mut sampled = 0.0_f64;
        let mut along = [f64::MIN; 3];
        for i in 0..720 {
            for j in 0..=360 {
                let (phi, theta) = (i as f64 * std::f64::consts::PI / 360.0, j as f64 * std::f64::consts::PI / 360.0);
                let unit = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                let point = turn * unit.component_mul(&semi_axes);
                sampled = sampled.max(horizontal(point));
                for (m, d) in along.iter_mut().zip(&directions) {
                    *m = m.max(point.dot(d));
                }
            }
        }
        let ellipsoid = Shape::Ellipsoid { semi_axes };
        let reach = ellipsoid.horizontal_reach(&turn);
        assert!(reach >= sampled - 1e-12 && reach - sampled < 1e-4 * reach, "ellipsoid: {reach} vs {sampled}");
        for (sampled, d) in along.iter().zip(&directions) {
            let reach = ellipsoid.reach_along(&turn, d);
            assert!(
                reach >= sampled - 1e-12 && reach - sampled < 1e-4 * reach,
                "ellipsoid along {d:?}: {reach} vs {sampled}"
            );
        }

        let rod = bonded_grain(&FormParameters::new(0.03, 0.01, 0.01).unwrap()).unwrap();
        let mut sampled = 0.0_f64;
        let mut along = [f64::MIN; 3];
        for sphere in &rod.spheres {
            for i in 0..720 {
                for j in 0..=360 {
                    let (phi, theta) =
                        (i as f64 * std::f64::consts::PI / 360.0, j as f64 * std::f64::consts::PI / 360.0);
                    let unit = Vector3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos());
                    let point = turn * (sphere.center + unit * sphere.radius);
                    sampled = sampled.max(horizontal(point));
                    for (m, d) in along.iter_mut().zip(&directions) {
                        *m = m.max(point.dot(d));
                    }
                }
            }
        }
        let rod = Shape::from(&rod);
        let reach = rod.horizontal_reach(&turn);
        assert!(reach >= sampled - 1e-12 && reach - sampled < 1e-4 * reach, "bonded rod: {reach} vs {sampled}");
        for (sampled, d) in along.iter().zip(&directions) {
            let reach = rod.reach_along(&turn, d);
            assert!(
                reach >= sampled - 1e-12 && reach - sampled < 1e-4 * reach,
                "bonded rod along {d:?}: {reach} vs {sampled}"
            );
        }
    }
    assert_eq!(Shape::Sphere { radius: 0.01 }.horizontal_reach(&turns[1]), 0.01);
    assert_eq!(Shape::Sphere { radius: 0.01 }.reach_along(&turns[1], &directions[2]), 0.01);
}
