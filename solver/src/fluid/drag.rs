//! Drag laws. The second paper's law (Sun & Xiao §2.3, Eqs. 3–7) is Syamlal et al.'s: the drag
//! coefficient of one sphere (Dalla Valle's curve) evaluated at the Reynolds number divided by
//! V_r and divided by V_r², where V_r is the ratio of the settling velocity of a group of
//! grains at fluid fraction ε_f to that of one grain alone. A non-spherical body that is not
//! made of spheres takes Haider & Levenspiel's (1989) curve for its sphericity in place of
//! Dalla Valle's, under the same hindrance.

use nalgebra::Vector3;

/// A drag coefficient C_D(Re) of one particle alone in an unbounded fluid, Re formed with the
/// diameter of the sphere of equal volume.
pub trait DragCurve {
    fn drag_coefficient(&self, reynolds: f64) -> f64;
}

/// Dalla Valle's (1948) curve, the one-sphere law inside Syamlal et al.'s (Sun & Xiao Eq. 4):
/// C_D = (0.63 + 4.8/√Re)².
///
/// Eq. 4 as printed reads C_d = (0.63 + 0.48 √(V_r/Re_p)), without the square and with 0.48:
/// that gives C_d ≈ 2 at Re = 0.1 where a sphere has 240. Syamlal et al. (1993) and the
/// paper's own solver (SediFoam, `SyamlalOBrien.C`: `sqr(0.63 + 4.8*sqrt(Vr/Re))`) have the
/// square and 4.8, which gives 23.04/Re at small Re, within 4 % of Stokes' 24/Re.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct DallaValle;

impl DragCurve for DallaValle {
    #[inline]
    fn drag_coefficient(&self, reynolds: f64) -> f64 {
        let root = 0.63 + 4.8 / reynolds.sqrt();
        root * root
    }
}

impl DallaValle {
    /// Terminal Reynolds number of a sphere alone, in closed form: with X = √C_D the balance of
    /// weight and drag is C_D Re² = 4 Ar/3 (Ar = (ρ_p − ρ_f) ρ_f g d³/μ², Archimedes), i.e.
    /// 0.63 Re + 4.8 √Re = √(4 Ar/3), a quadratic in √Re.
    pub fn terminal_reynolds(archimedes: f64) -> f64 {
        let a = (4.0 * archimedes / 3.0).sqrt();
        let root = (-4.8 + (4.8f64 * 4.8 + 4.0 * 0.63 * a).sqrt()) / (2.0 * 0.63);
        root * root
    }
}

/// Haider & Levenspiel (1989), "Drag coefficient and terminal velocity of spherical and
/// nonspherical particles", Powder Technology 58, 63–70, their Eq. 10 with Eq. 11's
/// coefficients: C_D = 24/Re (1 + A Re^B) + C/(1 + D/Re), with A, B, C, D functions of the
/// sphericity φ (surface of the sphere of equal volume over the particle's surface). The
/// curve depends on φ alone, not on the orientation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HaiderLevenspiel {
    pub sphericity: f64,
    a: f64,
    b: f64,
    c: f64,
    d: f64,
}

impl HaiderLevenspiel {
    pub fn new(sphericity: f64) -> Self {
        let (p, p2, p3) = (sphericity, sphericity * sphericity, sphericity.powi(3));
        Self {
            sphericity,
            a: (2.3288 - 6.4581 * p + 2.4486 * p2).exp(),
            b: 0.0964 + 0.5565 * p,
            c: (4.905 - 13.8944 * p + 18.4222 * p2 - 10.2599 * p3).exp(),
            d: (1.4681 + 12.2584 * p - 20.7322 * p2 + 15.8855 * p3).exp(),
        }
    }
}

impl DragCurve for HaiderLevenspiel {
    #[inline]
    fn drag_coefficient(&self, reynolds: f64) -> f64 {
        24.0 / reynolds * (1.0 + self.a * reynolds.powf(self.b)) + self.c / (1.0 + self.d / reynolds)
    }
}

/// The fluid: density ρ_f (kg/m³) and dynamic viscosity μ (Pa·s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FluidProperties {
    pub density: f64,
    pub viscosity: f64,
}

impl FluidProperties {
    /// Kinematic viscosity ν = μ/ρ_f (m²/s).
    pub fn kinematic_viscosity(&self) -> f64 {
        self.viscosity / self.density
    }

    /// Particle Reynolds number Re_p = ρ_f d |u|/μ (Eq. 5).
    #[inline]
    pub fn reynolds(&self, diameter: f64, speed: f64) -> f64 {
        self.density * diameter * speed / self.viscosity
    }
}

/// Syamlal et al.'s (1993) hindrance of the drag by the other grains, Sun & Xiao Eqs. 3–7: the
/// drag on a particle of volume V and equivalent diameter d at slip velocity w = U_f − u_p is
///
/// f = V (3/4) C_D(Re_p/V_r)/V_r² ρ_f |w| w / d,
///
/// the drag the particle would feel alone at w/V_r. V_r (Eq. 6) is Garside & Al-Dibouni's ratio
/// of the settling velocity of grains at fluid fraction ε_f to that of one grain, with
/// A₁ = ε_f^4.14 and A₂ = 0.8 ε_f^1.28 (ε_f ≤ 0.85) or ε_f^2.65 (Eq. 7); V_r = 1 at ε_f = 1.
///
/// Eq. 3 reads f = V/(ε_f ε_s) β (u_p − U_f): Syamlal et al.'s β holds the factor ε_s ε_f
/// (their momentum exchange per unit volume), which cancels. The paper's solver (SediFoam,
/// `enhancedCloud.C`) multiplies by ε_f once more; the paper's equations do not, and with them
/// a suspension settles at V_r times the single-grain velocity, which is how V_r is defined.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SyamlalOBrien<C: DragCurve = DallaValle> {
    pub curve: C,
}

impl SyamlalOBrien {
    /// The paper's law: Dalla Valle's curve under the hindrance.
    pub const SPHERES: Self = Self { curve: DallaValle };
}

/// The hindrance at one fluid fraction ε_f: A₁ and A₂ of Eq. 7, computed once for all the
/// Reynolds numbers of a grain's spheres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hindrance {
    a1: f64,
    a2: f64,
}

impl Hindrance {
    /// A₁ = ε_f^4.14; A₂ = 0.8 ε_f^1.28 for ε_f ≤ 0.85, ε_f^2.65 above (Eq. 7).
    pub fn new(fluid_fraction: f64) -> Self {
        if fluid_fraction >= 1.0 {
            return Self::ALONE;
        }
        let ln = fluid_fraction.ln();
        let a2 = if fluid_fraction <= 0.85 { 0.8 * (1.28 * ln).exp() } else { (2.65 * ln).exp() };
        Self { a1: (4.14 * ln).exp(), a2 }
    }

    /// No other grain around: ε_f = 1.
    pub const ALONE: Self = Self { a1: 1.0, a2: 1.0 };

    /// V_r of Eq. 6 at particle Reynolds number `reynolds`.
    #[inline]
    pub fn velocity_ratio(&self, reynolds: f64) -> f64 {
        // Alone (A₁ = A₂ = 1) the ratio is 1: 0.5 (1 − r + √((1 + r)²)).
        if *self == Self::ALONE {
            return 1.0;
        }
        let (a1, a2) = (self.a1, self.a2);
        let r = 0.06 * reynolds;
        0.5 * (a1 - r + (r * r + 2.0 * r * (2.0 * a2 - a1) + a1 * a1).sqrt())
    }
}

impl<C: DragCurve> SyamlalOBrien<C> {
    /// Drag force on a particle of `volume` and equivalent `diameter` under `hindrance`, with
    /// `slip` = fluid velocity minus particle velocity at its centre.
    #[inline]
    pub fn force(
        &self,
        fluid: &FluidProperties,
        diameter: f64,
        volume: f64,
        hindrance: &Hindrance,
        slip: &Vector3<f64>,
    ) -> Vector3<f64> {
        slip * self.coefficient(fluid, diameter, volume, hindrance, slip.norm())
    }

    /// The drag force over the slip, β = |f|/|w| (kg/s), at slip speed `speed`: the force is
    /// β w. At zero speed, the creeping-flow limit (C_D Re → its constant), so that a grain at
    /// rest still feels drag as soon as it moves.
    #[inline]
    pub fn coefficient(
        &self,
        fluid: &FluidProperties,
        diameter: f64,
        volume: f64,
        hindrance: &Hindrance,
        speed: f64,
    ) -> f64 {
        // ρ_f |w| = μ Re/d, so β = V (3/4) C_D(Re/V_r) Re μ/(V_r² d²), finite as Re → 0.
        let reynolds = fluid.reynolds(diameter, speed).max(CREEPING_REYNOLDS);
        let vr = hindrance.velocity_ratio(reynolds);
        let cd = self.curve.drag_coefficient(reynolds / vr);
        volume * 0.75 * cd * reynolds * fluid.viscosity / (vr * vr * diameter * diameter)
    }
}

/// A Reynolds number deep in creeping flow, for the drag of a slip that is exactly zero (Dalla
/// Valle's C_D Re is then 23.04 to within 3e-7).
const CREEPING_REYNOLDS: f64 = 1e-12;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dalla_valle_has_the_stokes_limit_and_the_newton_plateau() {
        // (0.63 + 4.8/√Re)² = 23.04/Re + 6.048/√Re + 0.3969.
        let re = 1e-6;
        let cd = DallaValle.drag_coefficient(re);
        assert!((cd * re / 23.04 - 1.0).abs() < 1e-3, "{cd}");
        assert!((DallaValle.drag_coefficient(1e12) - 0.3969).abs() < 1e-5);
        assert!((DallaValle.drag_coefficient(1.0) - 5.43f64.powi(2)).abs() < 1e-12);
    }

    #[test]
    fn the_closed_form_terminal_reynolds_number_balances_weight_and_drag() {
        for ar in [1e-3, 1.0, 1e3, 1e6, 1e9] {
            let re = DallaValle::terminal_reynolds(ar);
            let balance = DallaValle.drag_coefficient(re) * re * re / (4.0 * ar / 3.0);
            assert!((balance - 1.0).abs() < 1e-12, "Ar {ar}: {balance}");
        }
    }

    fn velocity_ratio(fluid_fraction: f64, reynolds: f64) -> f64 {
        Hindrance::new(fluid_fraction).velocity_ratio(reynolds)
    }

    #[test]
    fn the_velocity_ratio_is_one_alone_and_garside_al_dibounis_limits_in_a_suspension() {
        for re in [1e-3, 1.0, 1e2, 1e4] {
            assert!((velocity_ratio(1.0, re) - 1.0).abs() < 1e-12);
        }
        // Re → 0: V_r → A₁ = ε^4.14; Re → ∞: V_r → A₂.
        let eps = 0.7f64;
        assert!((velocity_ratio(eps, 1e-9) / eps.powf(4.14) - 1.0).abs() < 1e-6);
        assert!((velocity_ratio(eps, 1e9) / (0.8 * eps.powf(1.28)) - 1.0).abs() < 1e-6);
        assert!((velocity_ratio(0.9, 1e9) / 0.9f64.powf(2.65) - 1.0).abs() < 1e-6);
        // V_r solves Garside & Al-Dibouni's (V_r − A₁)/(A₂ − V_r) = 0.06 Re_t with the
        // single-grain Reynolds number Re_t = Re/V_r: V_r² − (A₁ − 0.06 Re) V_r − 0.06 Re A₂ = 0.
        for (eps, re) in [(0.6, 3.0), (0.8, 40.0), (0.95, 700.0)] {
            let vr = velocity_ratio(eps, re);
            let a1 = eps.powf(4.14);
            let a2 = if eps <= 0.85 { 0.8 * eps.powf(1.28) } else { eps.powf(2.65) };
            let residual = vr * vr - (a1 - 0.06 * re) * vr - 0.06 * re * a2;
            assert!(residual.abs() < 1e-12, "{eps} {re}: {residual}");
        }
    }

    #[test]
    fn a_single_sphere_feels_c_d_half_rho_w_squared_times_its_cross_section() {
        let water = FluidProperties { density: 1000.0, viscosity: 1e-3 };
        let d: f64 = 2e-3;
        let volume = std::f64::consts::PI * d.powi(3) / 6.0;
        let slip = Vector3::new(0.0, 0.0, 0.1);
        let f = SyamlalOBrien::SPHERES.force(&water, d, volume, &Hindrance::ALONE, &slip);
        let re = 1000.0 * d * 0.1 / 1e-3;
        let expected = DallaValle.drag_coefficient(re) * 0.5 * 1000.0 * 0.01 * std::f64::consts::PI * d * d / 4.0;
        assert!((f.z / expected - 1.0).abs() < 1e-12 && f.x == 0.0 && f.y == 0.0);
        // The hindrance: at ε_f < 1 the drag at w is the drag alone at w/V_r.
        let eps = 0.8;
        let vr = velocity_ratio(eps, re);
        let hindered = SyamlalOBrien::SPHERES.force(&water, d, volume, &Hindrance::new(eps), &slip);
        let alone_at = SyamlalOBrien::SPHERES.force(&water, d, volume, &Hindrance::ALONE, &(slip / vr));
        assert!((hindered.z / alone_at.z - 1.0).abs() < 1e-12, "{} {}", hindered.z, alone_at.z);
    }

    #[test]
    fn haider_levenspiel_at_sphericity_one_is_their_sphere_curve() {
        // Their sphere refit (Eq. 12): 24/Re (1 + 0.1806 Re^0.6459) + 0.4251/(1 + 6880.95/Re).
        // Eq. 11's coefficients at φ = 1 give A = 0.1862, B = 0.6529, C = 0.4373, D = 7189: two
        // fits of the same sphere data, 0.06 % apart at Re = 0.1 and at most 6.8 % (Re ≈ 10³).
        let hl = HaiderLevenspiel::new(1.0);
        for re in [0.1, 1.0, 10.0, 100.0, 1e3, 1e4, 1e5] {
            let sphere = 24.0 / re * (1.0 + 0.1806 * f64::powf(re, 0.6459)) + 0.4251 / (1.0 + 6880.95 / re);
            let ratio = hl.drag_coefficient(re) / sphere;
            assert!((ratio - 1.0).abs() < 0.068, "Re {re}: {ratio}");
        }
        // Less spherical grains drag more at the same Re.
        assert!(HaiderLevenspiel::new(0.6).drag_coefficient(500.0) > 2.0 * hl.drag_coefficient(500.0));
    }
}
