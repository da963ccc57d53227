//! The contact law of §3.1 and §4.2: a linear spring-dashpot in the normal direction (Eq. 6)
//! and a tangential spring with history and dashpot capped by Coulomb friction (Eq. 7), with
//! coefficients from the restitution coefficient and collision time through the pair's
//! effective mass (Eqs. 11–13).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

use super::contact::ContactGeometry;
use super::material::Material;

/// κ = 2(1 − ν)/(2 − ν), Eq. 13.
pub fn tangential_stiffness_ratio(poisson_ratio: f64) -> f64 {
    2.0 * (1.0 - poisson_ratio) / (2.0 - poisson_ratio)
}

/// How k_n and d_n follow from e_n and T_c.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Calibration {
    /// Eq. 11 as printed: exact for the continuous equation of motion. Integrated with the
    /// semi-implicit Euler scheme at T_c/Δt = 40 collisions rebound with e ≈ 0.084–0.095, not 0.1.
    Continuous,
    /// Eq. 11 solved for the semi-implicit Euler map of the simulation's step Δt instead of the
    /// continuous motion, so that a simulated binary collision rebounds with exactly e_n after
    /// exactly T_c.
    Discrete,
}

/// Parameters of the linear spring-dashpot law, per unit effective mass so that each pair
/// scales them by its own m_eff (Eq. 11).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LinearSpringDashpot {
    /// k_n / m_eff = (π² + ln² e_n)/T_c², Eq. 11.
    stiffness_per_mass: f64,
    /// d_n / m_eff = −2 ln e_n / T_c, Eq. 11.
    damping_per_mass: f64,
    /// κ of Eq. 13: k_t = κ k_n, d_t = sqrt(κ) d_n (Eq. 12).
    kappa: f64,
    sqrt_kappa: f64,
    /// Coulomb friction coefficient μ_p of Eq. 7.
    friction: f64,
}

/// What a contact keeps from one time step to the next.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct ContactHistory {
    /// Tangential spring displacement δ_t of Eq. 7 (zero when the contact is open).
    pub tangential_displacement: Vector3<f64>,
}

impl LinearSpringDashpot {
    /// The law of a material integrated with time step Δt = `time_step`.
    pub fn new(material: &Material, calibration: Calibration, time_step: f64) -> Self {
        let Material { restitution, collision_time, poisson_ratio, friction, .. } = *material;
        let (stiffness_per_mass, damping_per_mass) = match calibration {
            Calibration::Continuous => {
                let ln_e = restitution.ln();
                ((std::f64::consts::PI.powi(2) + ln_e * ln_e) / collision_time.powi(2), -2.0 * ln_e / collision_time)
            }
            Calibration::Discrete => {
                // Per step, the map x'' = −ω² x − 2γ x' has eigenvalues r e^{±iθ} with
                // r² = 1 − 2γΔt and 2r cos θ = 2 − 2γΔt − ω²Δt². Contact lasts N = T_c/Δt steps
                // when θ = π/N, and the rebound velocity is r^N times the impact velocity.
                let steps = collision_time / time_step;
                let r = restitution.powf(1.0 / steps);
                let cos = (std::f64::consts::PI / steps).cos();
                ((1.0 + r * r - 2.0 * r * cos) / time_step.powi(2), (1.0 - r * r) / time_step)
            }
        };
        let kappa = tangential_stiffness_ratio(poisson_ratio);
        Self { stiffness_per_mass, damping_per_mass, kappa, sqrt_kappa: kappa.sqrt(), friction }
    }

    /// Normal stiffness k_n for a pair of effective mass m_eff = m_i m_j/(m_i + m_j), Eq. 11.
    pub fn normal_stiffness(&self, effective_mass: f64) -> f64 {
        effective_mass * self.stiffness_per_mass
    }

    /// Normal damping d_n, Eq. 11.
    pub fn normal_damping(&self, effective_mass: f64) -> f64 {
        effective_mass * self.damping_per_mass
    }

    /// The force exerted on body B by body A at a contact, to be applied at the contact point
    /// (−force on A). `relative_velocity` is the velocity of B's material point at the contact
    /// minus A's; the contact normal points from A into B.
    ///
    /// Normal (Eq. 6): F_n = (k_n δ − d_n u_n) n, with δ > 0 the overlap (Eq. 6's signed
    /// distance is −δ). Tangential (Eq. 7): the spring displacement δ_t is turned into the new
    /// tangent plane keeping its length, advanced by u_t Δt, and the trial force
    /// −k_t δ_t − d_t u_t is capped at μ|F_n|; when it slips, δ_t is reset to the value whose
    /// spring and dashpot give exactly the capped force.
    #[inline(always)]
    pub fn force(
        &self,
        effective_mass: f64,
        geometry: &ContactGeometry,
        relative_velocity: &Vector3<f64>,
        history: &mut ContactHistory,
        dt: f64,
    ) -> Vector3<f64> {
        let n = geometry.normal;
        let kn = effective_mass * self.stiffness_per_mass;
        let dn = effective_mass * self.damping_per_mass;
        let un = relative_velocity.dot(&n);
        let normal_magnitude = kn * geometry.depth - dn * un;
        let ut = relative_velocity - un * n;

        let old = history.tangential_displacement;
        let in_plane = old - old.dot(&n) * n;
        let in_plane_norm2 = in_plane.norm_squared();
        let mut displacement =
            if in_plane_norm2 > 0.0 { in_plane * (old.norm_squared() / in_plane_norm2).sqrt() } else { in_plane };
        displacement += ut * dt;

        let kt = self.kappa * kn;
        let dt_damping = self.sqrt_kappa * dn;
        let mut tangential = -kt * displacement - dt_damping * ut;
        let limit = self.friction * normal_magnitude.abs();
        let trial2 = tangential.norm_squared();
        if trial2 > limit * limit {
            tangential *= limit / trial2.sqrt();
            displacement = -(tangential + dt_damping * ut) / kt;
        }
        history.tangential_displacement = displacement;
        normal_magnitude * n + tangential
    }
}
