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

    /// The periodic image of j nearest to i, as whole periods to add to x_j in x and y.
    #[inline]
    pub fn nearest_image(&self, xi: &Vector3<f64>, xj: &Vector3<f64>) -> [i16; 2] {
        match *self {
            Domain::Periodic { width } => {
                [(-((xj.x - xi.x) / width).round()) as i16, (-((xj.y - xi.y) / width).round()) as i16]
            }
            Domain::Cylinder { .. } => [0, 0],
        }
    }

    /// The offset of a periodic image.
    #[inline]
    pub fn shift(&self, image: [i16; 2]) -> Vector3<f64> {
        let l = self.width();
        Vector3::new(image[0] as f64 * l, image[1] as f64 * l, 0.0)
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
