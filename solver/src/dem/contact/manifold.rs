//! A face resting on a plane: the paper's one contact law spread over the contact area.
//!
//! One contact point at the centre of pressure carries the whole force of Eqs. 6–7. For a face
//! lying on the floor that leaves the grain's rocking about that point undamped (the normal
//! dashpot acts where rocking does not move the grain) and lets it ratchet down a slope. So a
//! polyhedron whose face lies on a plane (three or more vertices beyond it) gets a contact
//! manifold: the corners of the footprint (the hull of those vertices, projected onto the contact
//! plane, at most [`MAX_POINTS`]), each carrying the law of Eqs. 6–7 with the pair's effective mass
//! scaled by a weight w_k (Σ w_k = 1), the same depth δ, and its own tangential history. The
//! weights put their centroid at the centre of pressure (Σ w_k x_k = x_c): the elastic force is
//! the paper's k_n δ at the centre of pressure, translation meets the same dashpot and friction
//! as one point, and rocking and twisting meet the dashpot and friction spread over the face.
//! The weights are the maximum-entropy coordinates of x_c (w_k ∝ exp(λ · (x_k − x_c)), positive and
//! smooth in x_c): no corner carries more than its share, and none jumps when the grain tilts.

use nalgebra::{Matrix2, Vector2, Vector3};

use super::ContactGeometry;
use super::ellipsoid::tangent_basis;

type V3 = Vector3<f64>;
type V2 = Vector2<f64>;

/// Most points of a manifold.
pub const MAX_POINTS: usize = 6;
/// Newton iterations for the weights, and the relative residual that ends them.
const WEIGHT_ITERATIONS: usize = 30;
const WEIGHT_TOLERANCE: f64 = 1e-12;

/// The key of a single-point contact.
pub const SINGLE: u64 = u64::MAX;

/// The key of the point where edge (v, w) of a grain crosses the contact plane.
pub fn edge_key(v: u32, w: u32) -> u64 {
    1 << 63 | u64::from(v.min(w)) << 32 | u64::from(v.max(w))
}

/// The points of one contact with a wall: each with its weight and the grain's vertex or edge
/// it is on (its key from one step to the next).
#[derive(Debug, Clone, Copy)]
pub struct Manifold {
    pub geometry: ContactGeometry,
    pub len: usize,
    pub points: [V3; MAX_POINTS],
    pub weights: [f64; MAX_POINTS],
    pub features: [u64; MAX_POINTS],
}

impl Manifold {
    /// One point, the contact point itself, with the whole law.
    pub fn single(geometry: ContactGeometry) -> Self {
        let mut m = Self {
            geometry,
            len: 1,
            points: [V3::zeros(); MAX_POINTS],
            weights: [0.0; MAX_POINTS],
            features: [SINGLE; MAX_POINTS],
        };
        m.points[0] = geometry.point;
        m.weights[0] = 1.0;
        m
    }

    /// The contact of each point: the shared normal and depth at that point.
    pub fn point(&self, k: usize) -> ContactGeometry {
        ContactGeometry { point: self.points[k], ..self.geometry }
    }

    /// The manifold on the footprint `corners` (positions, and their keys) of a
    /// contact whose centre of pressure is `geometry.point`: the corners' hull projected onto the
    /// plane through it, reduced to [`MAX_POINTS`], with maximum-entropy weights. A single point
    /// when fewer than three corners span an area around the centre of pressure.
    pub fn spread(geometry: ContactGeometry, corners: &[(V3, u64)]) -> Self {
        let single = Self::single(geometry);
        if corners.len() < 3 {
            return single;
        }
        let (t1, t2) = tangent_basis(&geometry.normal);
        let c = geometry.point;
        let flat = |x: &V3| V2::new(t1.dot(&(x - c)), t2.dot(&(x - c)));
        let mut hull = [(V2::zeros(), 0u64); 64];
        let n = corners.len().min(hull.len());
        for (slot, (x, v)) in hull.iter_mut().zip(corners) {
            *slot = (flat(x), *v);
        }
        let mut len = convex_hull(&mut hull[..n]);
        while len > MAX_POINTS {
            drop_least_area(&mut hull, &mut len);
        }
        if len < 3 {
            return single;
        }
        let Some(weights) = max_entropy_weights(&hull[..len]) else { return single };
        let mut m = single;
        m.len = len;
        for k in 0..len {
            let (p, v) = hull[k];
            m.points[k] = c + t1 * p.x + t2 * p.y;
            m.weights[k] = weights[k];
            m.features[k] = v;
        }
        m
    }
}

/// Moves the convex hull of `points` (counter-clockwise, Andrew's monotone chain) to the front
/// and returns its length. Corners within rounding of a straight side are left out, so that the
/// hull of points on a line (where a face's edges cross the plane) does not flicker.
fn convex_hull(points: &mut [(V2, u64)]) -> usize {
    points.sort_unstable_by(|p, q| p.0.x.total_cmp(&q.0.x).then(p.0.y.total_cmp(&q.0.y)));
    let size = points.iter().map(|p| p.0.norm()).fold(0.0, f64::max);
    let straight = 1e-9 * size * size;
    let turn = |o: &V2, a: &V2, b: &V2| (a - o).perp(&(b - o)) - straight;
    let mut hull = [(V2::zeros(), 0u64); 129];
    let mut len = 0;
    for p in points.iter() {
        while len >= 2 && turn(&hull[len - 2].0, &hull[len - 1].0, &p.0) <= 0.0 {
            len -= 1;
        }
        hull[len] = *p;
        len += 1;
    }
    let lower = len + 1;
    for p in points.iter().rev().skip(1) {
        while len >= lower && turn(&hull[len - 2].0, &hull[len - 1].0, &p.0) <= 0.0 {
            len -= 1;
        }
        hull[len] = *p;
        len += 1;
    }
    let len = (len - 1).min(points.len());
    points[..len].copy_from_slice(&hull[..len]);
    len
}

/// Removes the hull corner whose removal loses the least area.
fn drop_least_area(hull: &mut [(V2, u64)], len: &mut usize) {
    let n = *len;
    let loss = |k: usize| {
        let (a, b, c) = (hull[(k + n - 1) % n].0, hull[k].0, hull[(k + 1) % n].0);
        (b - a).perp(&(c - a)).abs()
    };
    let k = (0..n).min_by(|&i, &j| loss(i).total_cmp(&loss(j))).expect("a hull has corners");
    hull.copy_within(k + 1..n, k);
    *len -= 1;
}

/// Positive weights w_k with Σ w_k = 1 and Σ w_k x_k = 0 (the corners taken relative to the
/// point they must reproduce): w_k ∝ exp(λ · x_k), λ by Newton's method on Σ w_k x_k = 0, whose
/// Jacobian is the weighted covariance of the corners. `None` unless the origin lies strictly
/// inside their hull.
fn max_entropy_weights(corners: &[(V2, u64)]) -> Option<[f64; MAX_POINTS]> {
    let size = corners.iter().map(|(x, _)| x.norm()).fold(0.0, f64::max);
    if size == 0.0 || !size.is_finite() {
        return None;
    }
    let mut lambda = V2::zeros();
    let mut w = [0.0; MAX_POINTS];
    for _ in 0..WEIGHT_ITERATIONS {
        let exponents: [f64; MAX_POINTS] =
            std::array::from_fn(
                |k| if k < corners.len() { lambda.dot(&(corners[k].0 / size)) } else { f64::NEG_INFINITY },
            );
        let top = exponents.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
        let mut total = 0.0;
        for k in 0..corners.len() {
            w[k] = (exponents[k] - top).exp();
            total += w[k];
        }
        let (mut mean, mut second) = (V2::zeros(), Matrix2::zeros());
        for k in 0..corners.len() {
            w[k] /= total;
            let y = corners[k].0 / size;
            mean += y * w[k];
            second += y * y.transpose() * w[k];
        }
        if mean.norm() <= WEIGHT_TOLERANCE {
            return Some(w);
        }
        let step = (second - mean * mean.transpose()).try_inverse()? * mean;
        lambda -= step;
        if !lambda.iter().all(|l| l.is_finite()) {
            return None;
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn square() -> ContactGeometry {
        ContactGeometry { point: V3::new(0.1, 0.2, 0.0), normal: -V3::z(), depth: 1e-6 }
    }

    #[test]
    fn the_weights_put_the_points_centroid_at_the_centre_of_pressure() {
        // A square face of side 2 around (0, 0); centre of pressure off centre.
        let corners: Vec<(V3, u64)> = [(1.0, 1.0), (-1.0, 1.0), (-1.0, -1.0), (1.0, -1.0), (0.0, 0.0)]
            .iter()
            .enumerate()
            .map(|(k, (x, y))| (V3::new(*x, *y, 3e-7), k as u64))
            .collect();
        let m = Manifold::spread(square(), &corners);
        assert_eq!(m.len, 4, "the interior corner is not on the hull");
        let total: f64 = m.weights[..m.len].iter().sum();
        assert!((total - 1.0).abs() < 1e-14);
        assert!(m.weights[..m.len].iter().all(|&w| w > 0.0));
        let centroid: V3 = (0..m.len).map(|k| m.points[k] * m.weights[k]).sum();
        assert!((centroid - square().point).norm() < 1e-12, "{centroid}");
        // The points lie in the plane through the centre of pressure, with the vertices' keys.
        assert!((0..m.len).all(|k| m.points[k].z == 0.0 && m.features[k] < 4));
    }

    #[test]
    fn a_centre_of_pressure_outside_the_corners_gives_one_point() {
        let corners: Vec<(V3, u64)> = [(1.0, 1.0), (2.0, 1.0), (2.0, 2.0)]
            .iter()
            .enumerate()
            .map(|(k, (x, y))| (V3::new(*x, *y, 0.0), k as u64))
            .collect();
        assert_eq!(Manifold::spread(square(), &corners).len, 1);
    }

    #[test]
    fn many_corners_are_reduced_to_the_largest_hull_of_six() {
        let corners: Vec<(V3, u64)> = (0..12)
            .map(|k| {
                let phi = std::f64::consts::TAU * k as f64 / 12.0;
                (V3::new(0.1 + phi.cos(), 0.2 + phi.sin(), 0.0), k)
            })
            .collect();
        let m = Manifold::spread(square(), &corners);
        assert_eq!(m.len, MAX_POINTS);
        let centroid: V3 = (0..m.len).map(|k| m.points[k] * m.weights[k]).sum();
        assert!((centroid - square().point).norm() < 1e-12);
    }
}
