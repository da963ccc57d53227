//! The prescribed fluid velocity field. The fluid is not solved for: its velocity is given, as
//! still water or as a steady current over the bed, and the grains feel it through drag and
//! lift. Channel profiles run along +x (the axis of the shaking of Eq. 14) and are measured from
//! the bed surface, which rises as grains deposit.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// von Kármán's constant of the law of the wall.
pub const KARMAN: f64 = 0.41;

/// A steady fluid velocity field.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Flow {
    /// Still water.
    Quiescent,
    /// The same velocity everywhere (m/s).
    Uniform { velocity: Vector3<f64> },
    /// Laminar flow in an open channel of `depth` h above the bed with bed shear velocity u*
    /// (τ_b = ρ u*²): u(z) = (u*²/ν)(z − z²/(2h)) for 0 ≤ z ≤ h (the half Poiseuille profile of
    /// a film driven by gravity), u(h) above the free surface; still water in the bed.
    Laminar { shear_velocity: f64, depth: f64 },
    /// The rough-wall law of the wall, u(z) = (u*/κ) ln(z/z₀) above the roughness length z₀
    /// (Nikuradse; z₀ ≈ k_s/30 for a bed of roughness k_s), still water below z₀.
    Logarithmic { shear_velocity: f64, roughness: f64 },
}

impl Flow {
    /// Whether the field depends on the height above the bed, which then has to be found.
    pub fn needs_bed(&self) -> bool {
        matches!(self, Flow::Laminar { .. } | Flow::Logarithmic { .. })
    }

    /// Fluid velocity at `position` over a bed surface at height `bed`, and the vorticity
    /// ∇ × U there (for the lift of Eq. 8).
    #[inline]
    pub fn at(&self, position: &Vector3<f64>, bed: f64, kinematic_viscosity: f64) -> (Vector3<f64>, Vector3<f64>) {
        let z = position.z - bed;
        // U = (u(z), 0, 0) has the vorticity (0, du/dz, 0).
        let along = |u: f64, shear: f64| (Vector3::new(u, 0.0, 0.0), Vector3::new(0.0, shear, 0.0));
        match *self {
            Flow::Quiescent => (Vector3::zeros(), Vector3::zeros()),
            Flow::Uniform { velocity } => (velocity, Vector3::zeros()),
            Flow::Laminar { shear_velocity, depth } => {
                if z <= 0.0 {
                    return (Vector3::zeros(), Vector3::zeros());
                }
                let rate = shear_velocity * shear_velocity / kinematic_viscosity;
                let z = z.min(depth);
                along(rate * (z - z * z / (2.0 * depth)), rate * (1.0 - z / depth))
            }
            Flow::Logarithmic { shear_velocity, roughness } => {
                if z <= roughness {
                    (Vector3::zeros(), Vector3::zeros())
                } else {
                    along(shear_velocity / KARMAN * (z / roughness).ln(), shear_velocity / (KARMAN * z))
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const NU: f64 = 1e-6;

    /// du/dz by central differences, to check each profile's vorticity against its velocity.
    fn slope(flow: &Flow, z: f64, bed: f64) -> f64 {
        let h = 1e-7;
        let u = |z: f64| flow.at(&Vector3::new(0.3, 0.2, z), bed, NU).0.x;
        (u(z + h) - u(z - h)) / (2.0 * h)
    }

    #[test]
    fn the_logarithmic_profile_is_the_law_of_the_wall_above_the_moving_bed() {
        let flow = Flow::Logarithmic { shear_velocity: 0.05, roughness: 2e-4 };
        let bed = 0.03;
        // 1 cm above the bed: (0.05/0.41) ln(0.01/2e-4) = 0.47707... m/s.
        let (u, w) = flow.at(&Vector3::new(0.0, 0.0, bed + 0.01), bed, NU);
        assert!((u.x - 0.05 / 0.41 * 50f64.ln()).abs() < 1e-12 && u.y == 0.0 && u.z == 0.0);
        assert!((w.y - slope(&flow, bed + 0.01, bed)).abs() < 1e-6 * w.y);
        assert_eq!(flow.at(&Vector3::new(0.0, 0.0, bed + 1e-4), bed, NU).0, Vector3::zeros());
    }

    #[test]
    fn the_laminar_profile_has_the_bed_shear_stress_and_a_still_surface() {
        let flow = Flow::Laminar { shear_velocity: 0.01, depth: 0.05 };
        // Wall shear rate u*²/ν = 100 1/s; surface velocity u*² h/(2ν) = 2.5 m/s.
        let at_bed = flow.at(&Vector3::new(0.0, 0.0, 1e-9), 0.0, NU).1.y;
        assert!((at_bed - 100.0).abs() < 1e-5, "{at_bed}");
        let surface = flow.at(&Vector3::new(0.0, 0.0, 0.05), 0.0, NU).0.x;
        assert!((surface - 2.5).abs() < 1e-12);
        let above = flow.at(&Vector3::new(0.0, 0.0, 0.2), 0.0, NU);
        assert_eq!((above.0.x, above.1.y), (surface, 0.0));
        for z in [0.01, 0.025, 0.04] {
            assert!((flow.at(&Vector3::new(0.0, 0.0, z), 0.0, NU).1.y - slope(&flow, z, 0.0)).abs() < 1e-5);
        }
    }
}
