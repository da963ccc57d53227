//! Rigid bodies stored as arrays (one entry per grain), so that the per-step loops stream
//! through memory.

use nalgebra::{Matrix3, Quaternion, UnitQuaternion, Vector3};
use rand::{Rng, RngExt};
use serde::{Deserialize, Serialize};

use super::contact::Stance;
use super::shape::Shape;

/// Position, orientation, velocities and mass properties of all grains.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Bodies {
    pub position: Vec<Vector3<f64>>,
    /// Rotation from the body frame (principal axes) to the world frame.
    pub orientation: Vec<UnitQuaternion<f64>>,
    pub velocity: Vec<Vector3<f64>>,
    /// Angular velocity in the world frame.
    pub angular_velocity: Vec<Vector3<f64>>,
    pub mass: Vec<f64>,
    /// Principal moments of inertia (body frame).
    pub inertia: Vec<Vector3<f64>>,
    pub volume: Vec<f64>,
    #[serde(with = "super::shape::table")]
    pub shape: Vec<Shape>,
    pub bounding_radius: Vec<f64>,
    /// A bound on how far any point of the body has moved about its centre since it was
    /// created: the sum over steps of |ω| r Δt. With the offset of two centres it bounds how far
    /// a pair found apart can have closed in ([`super::contact::coherence`]).
    pub turn: Vec<f64>,
}

/// The initial state of a new body.
#[derive(Debug, Clone)]
pub struct NewBody {
    pub shape: Shape,
    pub position: Vector3<f64>,
    pub orientation: UnitQuaternion<f64>,
    pub velocity: Vector3<f64>,
    pub angular_velocity: Vector3<f64>,
}

impl Bodies {
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    pub fn push(&mut self, body: NewBody, density: f64) -> usize {
        let volume = body.shape.volume();
        self.position.push(body.position);
        self.orientation.push(body.orientation);
        self.velocity.push(body.velocity);
        self.angular_velocity.push(body.angular_velocity);
        self.mass.push(density * volume);
        self.inertia.push(body.shape.principal_inertia(density));
        self.volume.push(volume);
        self.bounding_radius.push(body.shape.bounding_radius());
        self.turn.push(0.0);
        self.shape.push(body.shape);
        self.len() - 1
    }

    /// Where the pair (i, j) stands for its distance bound, j's centre (with its periodic image)
    /// lying at `offset` from i's.
    #[inline(always)]
    pub fn stance(&self, i: usize, j: usize, offset: Vector3<f64>) -> Stance {
        Stance { offset, turn: self.turn[i] + self.turn[j] }
    }

    /// Velocity of the material point of body `b` at world point `p` (with `arm` = p − x_b).
    #[inline]
    pub fn point_velocity(&self, b: usize, arm: &Vector3<f64>) -> Vector3<f64> {
        self.velocity[b] + self.angular_velocity[b].cross(arm)
    }

    /// Inertia tensor of body `b` in the world frame, R diag(I) Rᵀ.
    pub fn world_inertia(&self, b: usize) -> Matrix3<f64> {
        let r = self.orientation[b].to_rotation_matrix();
        r.matrix() * Matrix3::from_diagonal(&self.inertia[b]) * r.matrix().transpose()
    }

    pub fn kinetic_energy(&self) -> f64 {
        (0..self.len())
            .map(|b| {
                let w = self.angular_velocity[b];
                0.5 * self.mass[b] * self.velocity[b].norm_squared() + 0.5 * w.dot(&(self.world_inertia(b) * w))
            })
            .sum()
    }
}

/// A rotation drawn uniformly from SO(3) (Shoemake's method).
pub fn uniform_rotation<R: Rng + ?Sized>(rng: &mut R) -> UnitQuaternion<f64> {
    let (u1, u2, u3): (f64, f64, f64) = (rng.random(), rng.random(), rng.random());
    let tau = 2.0 * std::f64::consts::PI;
    let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
    UnitQuaternion::from_quaternion(Quaternion::new(
        b * (tau * u3).cos(),
        a * (tau * u2).sin(),
        a * (tau * u2).cos(),
        b * (tau * u3).sin(),
    ))
}
