//! How fast one grain settles in still water: the engine's answer (one grain dropped with fluid
//! forces on) and the literature's correlations for a grain of the same volume and form, the
//! numbers of `sedpack settle` and of the second paper's §4.1 (Fig. 9).

use nalgebra::{UnitQuaternion, Vector3};

use super::Fluid;
use super::drag::{DallaValle, FluidProperties};
use crate::SolverError;
use crate::dem::{
    Calibration, ContactPoint, Domain, MIN_STEPS_PER_COLLISION, Material, NewBody, Settings, Shape, Simulation,
};

/// The dimensionless diameter and velocity of the second paper's Eqs. 9–10 (Haider &
/// Levenspiel's d* and u*, Dietrich's D* = d*³ and W* = u*³).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scales {
    /// Length scale (μ²/(g ρ_f (ρ_s − ρ_f)))^(1/3): d* = D_n / length.
    pub length: f64,
    /// Velocity scale (g μ (ρ_s − ρ_f)/ρ_f²)^(1/3): u* = u_t / velocity.
    pub velocity: f64,
}

impl Scales {
    pub fn new(fluid: &FluidProperties, grain_density: f64, gravity: f64) -> Self {
        let buoyant = gravity * (grain_density - fluid.density);
        Self {
            length: (fluid.viscosity * fluid.viscosity / (fluid.density * buoyant)).cbrt(),
            velocity: (buoyant * fluid.viscosity / (fluid.density * fluid.density)).cbrt(),
        }
    }

    /// C_D of a grain of nominal diameter `d` settling at `velocity`: weight minus buoyancy
    /// equals drag, C_D = 4 (ρ_s − ρ_f) g d/(3 ρ_f u²) = (4/3) d*/u*².
    pub fn drag_coefficient(&self, d: f64, velocity: f64) -> f64 {
        4.0 / 3.0 * (d / self.length) / (velocity / self.velocity).powi(2)
    }
}

/// Haider & Levenspiel's (1989) explicit terminal velocity, their Eq. 20, the curves of the
/// second paper's Fig. 9: u* = [18/d*² + (2.3348 − 1.7439 φ)/d*^½]⁻¹, fitted for
/// 0.5 ≤ φ ≤ 1.
pub fn haider_levenspiel_velocity(scales: &Scales, nominal_diameter: f64, sphericity: f64) -> f64 {
    let d = nominal_diameter / scales.length;
    scales.velocity / (18.0 / (d * d) + (2.3348 - 1.7439 * sphericity) / d.sqrt())
}

/// Dietrich (1982), "Settling velocity of natural particles", Water Resources Research 18,
/// 1615–1626, Eqs. 8–9: W* = R₃ 10^(R₁ + R₂) with D* = (ρ_s − ρ_f) g D_n³/(ρ_f ν²) and
/// W* = ρ_f w³/((ρ_s − ρ_f) g ν); R₁ the size effect, R₂ that of the Corey shape factor
/// CSF = S/√(L I), R₃ that of Powers' roundness P (6 for perfectly round grains, 2–3 for
/// angular crushed grains, 3.5 for natural sediment). Below D* = 0.05 Stokes' law, W* = D*²/5832.
pub fn dietrich_velocity(scales: &Scales, nominal_diameter: f64, corey: f64, powers: f64) -> f64 {
    let dstar = (nominal_diameter / scales.length).powi(3);
    let wstar = if dstar < 0.05 {
        dstar * dstar / 5832.0
    } else {
        let x = dstar.log10();
        let r1 = -3.76715 + 1.92944 * x - 0.09815 * x.powi(2) - 0.00575 * x.powi(3) + 0.00056 * x.powi(4);
        let r2 = (1.0 - (1.0 - corey) / 0.85).log10() - (1.0 - corey).powf(2.3) * (x - 4.6).tanh()
            + 0.3 * (0.5 - corey) * (1.0 - corey).powi(2) * (x - 4.6);
        let r3 = (0.65 - corey / 2.83 * (x - 4.6).tanh()).powf(1.0 + (3.5 - powers) / 2.5);
        r3 * 10f64.powf(r1 + r2)
    };
    // u* = W*^(1/3).
    scales.velocity * wstar.cbrt()
}

/// Richardson & Zaki's (1954) exponent n of u_s/u_t = ε_f^n for the single grain's terminal
/// Reynolds number (their Eq. for an unbounded suspension, d/D → 0): 4.65 below Re_t = 0.2,
/// 4.4 Re_t^−0.03 to 1, 4.4 Re_t^−0.1 to 500, 2.39 above.
pub fn richardson_zaki_exponent(reynolds: f64) -> f64 {
    if reynolds < 0.2 {
        4.65
    } else if reynolds < 1.0 {
        4.4 * reynolds.powf(-0.03)
    } else if reynolds < 500.0 {
        4.4 * reynolds.powf(-0.1)
    } else {
        2.39
    }
}

/// The terminal velocity of a sphere of diameter d under the paper's drag law (Eqs. 3–7 at
/// ε_f = 1, Dalla Valle's curve), in closed form ([`DallaValle::terminal_reynolds`]).
pub fn sphere_terminal_velocity(fluid: &FluidProperties, grain_density: f64, gravity: f64, d: f64) -> f64 {
    let archimedes = (grain_density - fluid.density) * fluid.density * gravity * d.powi(3) / fluid.viscosity.powi(2);
    DallaValle::terminal_reynolds(archimedes) * fluid.viscosity / (fluid.density * d)
}

/// The orientation `sedpack settle` releases a grain in: turned 40° about its long axis, then
/// 25° about a horizontal axis, so that a grain that turns while settling shows it.
pub fn release_orientation() -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::y_axis(), 25f64.to_radians())
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), 40f64.to_radians())
}

/// One grain dropped in still water: the run's settings.
#[derive(Debug, Clone)]
pub struct Drop {
    pub shape: Shape,
    pub material: Material,
    pub viscosity: f64,
    /// Orientation at release (body to world); the grain starts at rest.
    pub orientation: UnitQuaternion<f64>,
}

/// Orientation of a grain while it settles, in degrees; an axis is None where the grain is
/// symmetric about another axis and it is not defined (the short axis of a row of spheres, the
/// long axis of a round disk).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Orientation {
    /// Angle between the short axis and the vertical: 0° broadside-on (largest projection
    /// across the fall), 90° edge-on.
    pub short_axis_tilt: Option<f64>,
    /// Angle between the long axis and the horizontal.
    pub long_axis_dip: Option<f64>,
}

/// What one grain dropped in still water does.
#[derive(Debug, Clone, PartialEq)]
pub struct Settling {
    /// Vertical speed reached (m/s).
    pub terminal_velocity: f64,
    /// Horizontal speed at the same time (m/s): a grain that glides sideways.
    pub drift: f64,
    /// Diameter of the sphere of the grain's volume, D_n (m).
    pub nominal_diameter: f64,
    /// 4 (ρ_s − ρ_f) g D_n/(3 ρ_f u_t²).
    pub drag_coefficient: f64,
    /// ρ_f u_t D_n/μ.
    pub reynolds: f64,
    /// First time the vertical speed reached 99 % of the terminal velocity (s).
    pub time_to_99: f64,
    /// Mean orientation over the last five relaxation times, once speed and orientation are
    /// steady; None for a sphere.
    pub orientation: Option<Orientation>,
    pub simulated_time: f64,
    pub steps: u64,
}

/// Drops the grain of `drop` from rest in still water and follows it until its vertical speed
/// and orientation are steady: the speed within 1e-5 of itself and the short axis within 0.05°
/// over five relaxation times τ = u_t/g' (u_t of the sphere of equal volume), or 400 τ at most.
/// The time step resolves τ in 400 steps, at most the engine's limit T_c/10 (a lone grain has
/// no collision to resolve). The grain falls through
/// unbounded water: whenever it has sunk through half its starting height it is lifted back by
/// that much, which in still water changes nothing.
pub fn drop(drop: &Drop) -> Result<Settling, SolverError> {
    let Drop { shape, material, viscosity, orientation } = drop.clone();
    let fluid = FluidProperties { density: material.fluid_density, viscosity };
    let g = -material.gravity.z;
    let d = 2.0 * shape.equivalent_radius();
    let tau = sphere_terminal_velocity(&fluid, material.density, g, d) / (g * (1.0 - fluid.density / material.density));
    let time_step = (tau / 400.0).min(material.collision_time / MIN_STEPS_PER_COLLISION);
    let reach = shape.bounding_radius();
    let (width, start) = (40.0 * reach, 20.0 * reach);
    let settings = Settings {
        material,
        time_step,
        skin: 0.1 * reach,
        calibration: Calibration::Discrete,
        contact_point: ContactPoint::CentreOfPressure,
    };
    let mut sim = Simulation::new(Domain::Periodic { width }, settings)?;
    sim.add_body(NewBody {
        shape: shape.clone(),
        position: Vector3::new(width / 2.0, width / 2.0, start),
        orientation,
        velocity: Vector3::zeros(),
        angular_velocity: Vector3::zeros(),
    });
    // One grain is cheap: its fluid forces are updated every step.
    sim.fluid = Some(Fluid::still(viscosity, width, 1));

    let (long, short) = principal_axes(&shape);
    let angles = |q: &UnitQuaternion<f64>| {
        (long.is_some() || short.is_some()).then(|| Orientation {
            short_axis_tilt: short.map(|a| (q * a).z.abs().min(1.0).acos().to_degrees()),
            long_axis_dip: long.map(|a| (q * a).z.abs().min(1.0).asin().to_degrees()),
        })
    };
    // Samples every 1/40 of τ: (time, vertical speed, horizontal speed, orientation).
    let stride = ((tau / 40.0 / time_step).round() as u64).max(1);
    let lag = 200;
    let mut samples: Vec<(f64, f64, f64, Option<Orientation>)> = Vec::new();
    loop {
        sim.step()?;
        if sim.bodies.position[0].z < start / 2.0 {
            sim.bodies.position[0].z += start / 2.0;
        }
        if !sim.steps.is_multiple_of(stride) {
            continue;
        }
        let v = sim.bodies.velocity[0];
        samples.push((sim.time, -v.z, v.xy().norm(), angles(&sim.bodies.orientation[0])));
        let n = samples.len();
        if n > lag && sim.time > 20.0 * tau {
            let (now, before) = (&samples[n - 1], &samples[n - 1 - lag]);
            let steady_speed = (now.1 - before.1).abs() <= 1e-5 * now.1.abs();
            let steady_turn = match (now.3, before.3) {
                (Some(a), Some(b)) => [(a.short_axis_tilt, b.short_axis_tilt), (a.long_axis_dip, b.long_axis_dip)]
                    .iter()
                    .all(|(x, y)| x.zip(*y).is_none_or(|(x, y)| (x - y).abs() < 0.05)),
                _ => true,
            };
            if (steady_speed && steady_turn) || sim.time > 400.0 * tau {
                break;
            }
        }
    }
    let &(_, terminal, drift, _) = samples.last().expect("sampled at least once");
    let reached = samples.iter().position(|s| s.1 >= 0.99 * terminal).unwrap_or(samples.len() - 1);
    let last = &samples[samples.len().saturating_sub(lag)..];
    let orientation = last[0].3.map(|first| {
        let mean = |f: fn(&Orientation) -> Option<f64>| {
            f(&first).map(|_| last.iter().filter_map(|s| s.3.as_ref().and_then(f)).sum::<f64>() / last.len() as f64)
        };
        Orientation { short_axis_tilt: mean(|o| o.short_axis_tilt), long_axis_dip: mean(|o| o.long_axis_dip) }
    });
    let scales = Scales::new(&fluid, material.density, g);
    Ok(Settling {
        terminal_velocity: terminal,
        drift,
        nominal_diameter: d,
        drag_coefficient: scales.drag_coefficient(d, terminal),
        reynolds: fluid.reynolds(d, terminal),
        time_to_99: samples[reached].0,
        orientation,
        simulated_time: sim.time,
        steps: sim.steps,
    })
}

/// The body-frame long and short axes: those of the smallest and of the largest principal
/// moment, each None when the moment equals the middle one to within 1e-6 (the axis is then
/// any in a plane: a row of spheres has no short axis, a round disk no long axis).
pub fn principal_axes(shape: &Shape) -> (Option<Vector3<f64>>, Option<Vector3<f64>>) {
    let inertia = shape.principal_inertia(1.0);
    let (small, large) = (inertia.imin(), inertia.imax());
    let middle = 3 - small - large;
    let distinct = |k: usize| (inertia[k] - inertia[middle]).abs() > 1e-6 * inertia.max();
    let axis = |k: usize| (small != large && distinct(k)).then(|| Vector3::ith(k, 1.0));
    (axis(small), axis(large))
}
