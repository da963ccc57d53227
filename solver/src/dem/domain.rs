//! The two domains of §4.1: a bottom plane z = 0 plus either horizontal periodicity over a
//! square of side L, or a vertical cylinder wall of diameter L. Both occupy [0, L]² in x and y.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum Domain {
    /// Periodic in x and y with period `width`.
    Periodic { width: f64 },
    /// Cylinder wall of the given diameter, axis at (L/2, L/2).
    Cylinder { diameter: f64 },
}

impl Domain {
    /// L: the side of the periodic square or the diameter of the cylinder.
    pub fn width(&self) -> f64 {
        match *self {
            Domain::Periodic { width } => width,
            Domain::Cylinder { diameter } => diameter,
        }
    }

    pub fn is_periodic(&self) -> bool {
        matches!(self, Domain::Periodic { .. })
    }

    /// Horizontal area of the domain: L² (periodic) or π L²/4 (cylinder).
    pub fn cross_section(&self) -> f64 {
        match *self {
            Domain::Periodic { width } => width * width,
            Domain::Cylinder { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
        }
    }

    /// Maps a position into [0, L)² horizontally (periodic domain only).
    pub fn wrap(&self, p: &mut Vector3<f64>) {
        if let Domain::Periodic { width } = *self {
            p.x = p.x.rem_euclid(width);
            p.y = p.y.rem_euclid(width);
            // rem_euclid can round up to exactly `width` for tiny negative inputs.
            if p.x >= width {
                p.x = 0.0;
            }
            if p.y >= width {
                p.y = 0.0;
            }
        }
    }

    /// The periodic image offset s that makes x_j + s the image of j nearest to x_i.
    #[inline]
    pub fn image_shift(&self, xi: &Vector3<f64>, xj: &Vector3<f64>) -> Vector3<f64> {
        match *self {
            Domain::Periodic { width } => {
                Vector3::new(-width * ((xj.x - xi.x) / width).round(), -width * ((xj.y - xi.y) / width).round(), 0.0)
            }
            Domain::Cylinder { .. } => Vector3::zeros(),
        }
    }

    /// Whether a grain of bounding radius r centred at horizontal (x, y) lies inside the domain.
    pub fn holds(&self, x: f64, y: f64, r: f64) -> bool {
        match *self {
            Domain::Periodic { .. } => true,
            Domain::Cylinder { diameter } => {
                let c = diameter / 2.0;
                (x - c).hypot(y - c) + r <= c
            }
        }
    }
}
