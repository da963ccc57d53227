//! The grains' material and the fluid they settle in (§4.2).

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Material constants of §4.2; the default is the paper's: quartz grains in water.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Material {
    /// Grain density ρ_p (kg/m³).
    pub density: f64,
    /// Fluid density ρ_f (kg/m³); buoyancy reduces the weight to (ρ_p − ρ_f) V g (Eq. 10).
    pub fluid_density: f64,
    /// Gravitational acceleration (m/s²), (0, 0, −9.81) in the paper's setups.
    pub gravity: Vector3<f64>,
    /// Normal restitution coefficient e_n (Eq. 11).
    pub restitution: f64,
    /// Collision time T_c (s, Eq. 11).
    pub collision_time: f64,
    /// Poisson's ratio ν (Eq. 13).
    pub poisson_ratio: f64,
    /// Coulomb friction coefficient μ_p (Eq. 7).
    pub friction: f64,
}

impl Default for Material {
    fn default() -> Self {
        Self {
            density: 2650.0,
            fluid_density: 1000.0,
            gravity: Vector3::new(0.0, 0.0, -9.81),
            restitution: 0.1,
            collision_time: 2e-4,
            poisson_ratio: 0.22,
            friction: 0.5,
        }
    }
}

impl Material {
    /// Gravity minus buoyancy per unit grain volume, (ρ_p − ρ_f) g (Eq. 10).
    pub fn weight_per_volume(&self) -> Vector3<f64> {
        (self.density - self.fluid_density) * self.gravity
    }
}
