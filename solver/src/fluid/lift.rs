//! Saffman lift, Sun & Xiao Eq. 8 (Saffman 1965; van Rijn 1984).

use nalgebra::Vector3;

use super::drag::FluidProperties;

/// Lift on a sphere in a sheared flow (Eq. 8): f = C_l ρ_f ν^½ d² (w × ω)/|ω|^½, with the slip
/// w = U_f − u_p, the fluid's vorticity ω = ∇ × U_f and C_l = 1.6.
///
/// Eq. 8 as printed, C_l ρ_f ν^0.5 d² (u_p − U_f) × ∇U_f, is not a force (it lacks |∇U|^−½)
/// and leaves "vector × tensor" open. This is Saffman's result, 6.46 μ a² |w| (G/ν)^½ = 1.615
/// ρ ν^½ d² |w| G^½ for a shear rate G, in the form the paper's solver (SediFoam,
/// `enhancedCloud.C`) evaluates it: `(Uf − Up) ^ curl(Uf) / sqrt(mag(curl(Uf)))`. A grain
/// lagging a flow that grows with height (U_f > u_p, dU/dz > 0) is lifted: for U_f = (G z, 0, 0)
/// the vorticity is (0, G, 0) and (w, 0, 0) × (0, G, 0) = (0, 0, w G).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SaffmanLift {
    pub coefficient: f64,
}

impl SaffmanLift {
    /// The paper's C_l = 1.6.
    pub const PAPER: Self = Self { coefficient: 1.6 };

    #[inline]
    pub fn force(
        &self,
        fluid: &FluidProperties,
        diameter: f64,
        slip: &Vector3<f64>,
        vorticity: &Vector3<f64>,
    ) -> Vector3<f64> {
        slip.cross(vorticity) * self.coefficient(fluid, diameter, vorticity)
    }

    /// K of f = K (w × ω), linear in the slip w: C_l ρ_f ν^½ d²/|ω|^½, zero without vorticity.
    #[inline]
    pub fn coefficient(&self, fluid: &FluidProperties, diameter: f64, vorticity: &Vector3<f64>) -> f64 {
        let strength = vorticity.norm();
        if strength == 0.0 {
            return 0.0;
        }
        self.coefficient * fluid.density * fluid.kinematic_viscosity().sqrt() * diameter * diameter / strength.sqrt()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grain_lagging_a_shear_flow_is_lifted_by_saffmans_force() {
        let water = FluidProperties { density: 1000.0, viscosity: 1e-3 };
        let (d, g, w) = (1e-3, 50.0, 0.02);
        let f = SaffmanLift::PAPER.force(&water, d, &Vector3::new(w, 0.0, 0.0), &Vector3::new(0.0, g, 0.0));
        // 1.6 ρ ν^½ d² w G^½ = 1.6 · 1000 · 1e-3 · 1e-6 · 0.02 · √50.
        let expected = 1.6 * 1000.0 * 1e-3 * 1e-6 * 0.02 * 50f64.sqrt();
        assert!((f.z / expected - 1.0).abs() < 1e-12 && f.x == 0.0 && f.y == 0.0, "{f:?}");
        // A grain leading the flow is pushed down; no shear, no lift.
        let lead = SaffmanLift::PAPER.force(&water, d, &Vector3::new(-w, 0.0, 0.0), &Vector3::new(0.0, g, 0.0));
        assert!((lead.z + expected).abs() < 1e-18);
        assert_eq!(
            SaffmanLift::PAPER.force(&water, d, &Vector3::new(w, 0.0, 0.0), &Vector3::zeros()),
            Vector3::zeros()
        );
    }
}
