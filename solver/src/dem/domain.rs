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

    /// Maps a position into [0, L)² horizontally (periodic domain only); returns the whole
    /// periods taken off in x and y.
    pub fn wrap(&self, p: &mut Vector3<f64>) -> [i32; 2] {
        let Domain::Periodic { width } = *self else { return [0, 0] };
        let mut periods = [0; 2];
        for (k, period) in periods.iter_mut().enumerate() {
            let mut n = (p[k] / width).floor();
            p[k] -= n * width;
            // Round-off can leave the result just outside [0, L).
            if p[k] < 0.0 {
                p[k] += width;
                n -= 1.0;
            } else if p[k] >= width {
                p[k] -= width;
                n += 1.0;
            }
            *period = n as i32;
        }
        periods
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

    /// Squared distance from i to the nearest periodic image of j, both inside the box: each
    /// component of their separation is then within ±L, so at most one period is added or taken.
    #[inline]
    pub fn nearest_distance2(&self, xi: &Vector3<f64>, xj: &Vector3<f64>) -> f64 {
        let d = xj - xi;
        let nearest = |d: f64| match *self {
            Domain::Periodic { width } if d > 0.5 * width => d - width,
            Domain::Periodic { width } if d < -0.5 * width => d + width,
            _ => d,
        };
        nearest(d.x).powi(2) + nearest(d.y).powi(2) + d.z * d.z
    }

    /// Every periodic image of j within `reach` of i along both periodic axes: the nearest one,
    /// and its neighbour too when `reach` exceeds half the period (long grains in a narrow box).
    pub fn images_within(&self, xi: &Vector3<f64>, xj: &Vector3<f64>, reach: f64) -> impl Iterator<Item = [i16; 2]> {
        let nearest = self.nearest_image(xi, xj);
        let l = self.width();
        let axis = move |k: usize, d: f64| {
            (-1..=1).map(move |s| nearest[k] + s).filter(move |&m| (d + m as f64 * l).abs() < reach)
        };
        let (dx, dy) = (xj.x - xi.x, xj.y - xi.y);
        let periodic = self.is_periodic();
        axis(0, dx).flat_map(move |mx| axis(1, dy).map(move |my| [mx, my])).filter(move |m| periodic || *m == [0, 0])
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
