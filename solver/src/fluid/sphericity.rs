//! Wadell's sphericity φ = (surface of the sphere of equal volume)/(surface of the particle),
//! the shape factor of Haider & Levenspiel's drag curve, for the shapes sedpack's grains take.

use std::f64::consts::PI;

use nalgebra::Vector3;

use crate::dem::Shape;
use crate::dem::shape::Polyhedron;

/// Carlson's symmetric elliptic integral R_F(x, y, z) by the duplication theorem (Carlson 1995,
/// Numer. Algorithms 10, 13–26, Algorithm 1), to round-off.
fn carlson_rf(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    loop {
        let mean = (x + y + z) / 3.0;
        let spread = [(mean - x).abs(), (mean - y).abs(), (mean - z).abs()].into_iter().fold(0.0, f64::max);
        if spread < 1e-4 * mean {
            // Fifth-order series about the mean (Carlson's Eq. 2.2), error O(spread⁶).
            let (dx, dy) = ((mean - x) / mean, (mean - y) / mean);
            let dz = -(dx + dy);
            let (e2, e3) = (dx * dy - dz * dz, dx * dy * dz);
            return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / mean.sqrt();
        }
        let lambda = (x * y).sqrt() + (y * z).sqrt() + (z * x).sqrt();
        (x, y, z) = ((x + lambda) / 4.0, (y + lambda) / 4.0, (z + lambda) / 4.0);
    }
}

/// Carlson's R_D(x, y, z) = R_J(x, y, z, z) by the duplication theorem (Carlson 1995, Algorithm 4).
fn carlson_rd(mut x: f64, mut y: f64, mut z: f64) -> f64 {
    let (mut sum, mut scale) = (0.0, 1.0);
    loop {
        let mean = (x + y + 3.0 * z) / 5.0;
        let spread = [(mean - x).abs(), (mean - y).abs(), (mean - z).abs()].into_iter().fold(0.0, f64::max);
        if spread < 1e-4 * mean {
            let (dx, dy) = ((mean - x) / mean, (mean - y) / mean);
            let dz = -(dx + dy) / 3.0;
            let (xy, zz) = (dx * dy, dz * dz);
            let (e2, e3, e4, e5) = (xy - 6.0 * zz, (3.0 * xy - 8.0 * zz) * dz, 3.0 * (xy - zz) * zz, xy * zz * dz);
            let series =
                1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0 - 9.0 * e2 * e3 / 52.0
                    + 3.0 * e5 / 26.0;
            return 3.0 * sum + scale * series / (mean * mean.sqrt());
        }
        let lambda = (x * y).sqrt() + (y * z).sqrt() + (z * x).sqrt();
        sum += scale / (z.sqrt() * (z + lambda));
        scale /= 4.0;
        (x, y, z) = ((x + lambda) / 4.0, (y + lambda) / 4.0, (z + lambda) / 4.0);
    }
}

/// Surface area of the ellipsoid with semi-axes a, b, c: 4π abc R_G(a⁻², b⁻², c⁻²), with
/// 2 R_G(x, y, z) = z R_F − (x − z)(y − z) R_D/3 + √(xy/z) (DLMF 19.16.3, 19.21.10, 19.33.3).
pub fn ellipsoid_surface(semi_axes: &Vector3<f64>) -> f64 {
    // Order so that z is the largest of the three arguments (the smallest semi-axis): the
    // products (x − z)(y − z) are then of one sign and nothing cancels.
    let mut s = [semi_axes.x, semi_axes.y, semi_axes.z];
    s.sort_by(|p, q| q.total_cmp(p));
    let (x, y, z) = (s[0].powi(-2), s[1].powi(-2), s[2].powi(-2));
    let rg = 0.5 * (z * carlson_rf(x, y, z) - (x - z) * (y - z) * carlson_rd(x, y, z) / 3.0 + (x * y / z).sqrt());
    4.0 * PI * s[0] * s[1] * s[2] * rg
}

/// Surface area of a stretched polyhedron grain: its base's triangles mapped by the stretch.
pub fn polyhedron_surface(p: &Polyhedron) -> f64 {
    let v = p.base.vertices();
    p.base
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| v[k as usize].component_mul(&p.scale));
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum()
}

/// Surface of the sphere of this volume, π^(1/3) (6V)^(2/3): the numerator of Wadell's
/// sphericity.
pub fn equal_volume_sphere_surface(volume: f64) -> f64 {
    PI.cbrt() * (6.0 * volume).powf(2.0 / 3.0)
}

/// Sphericity of a shape; a bonded grain's spheres touch at points, so its surface is the sum
/// of theirs.
pub fn sphericity(shape: &Shape) -> f64 {
    let equivalent = equal_volume_sphere_surface(shape.volume());
    let surface = match shape {
        Shape::Sphere { .. } => return 1.0,
        Shape::Ellipsoid { semi_axes } => ellipsoid_surface(semi_axes),
        Shape::Polyhedron(p) => polyhedron_surface(p),
        Shape::Bonded(b) => b.spheres.iter().map(|c| 4.0 * PI * c.radius * c.radius).sum(),
    };
    (equivalent / surface).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ellipsoid_surfaces_match_the_closed_forms_of_spheroids() {
        // Sphere.
        let r = 0.7;
        assert!((ellipsoid_surface(&Vector3::repeat(r)) / (4.0 * PI * r * r) - 1.0).abs() < 1e-12);
        // Prolate spheroid a > b = c: 2π b² (1 + a/(b e) asin e), e² = 1 − b²/a².
        let (a, b) = (3.0f64, 1.0f64);
        let e = (1.0 - b * b / (a * a)).sqrt();
        let prolate = 2.0 * PI * b * b * (1.0 + a / (b * e) * e.asin());
        assert!((ellipsoid_surface(&Vector3::new(b, a, b)) / prolate - 1.0).abs() < 1e-12);
        // Oblate spheroid a = b > c: 2π a² (1 + (1 − e²)/e atanh e), e² = 1 − c²/a².
        let (a, c) = (2.0f64, 0.5f64);
        let e = (1.0 - c * c / (a * a)).sqrt();
        let oblate = 2.0 * PI * a * a * (1.0 + (1.0 - e * e) / e * e.atanh());
        assert!((ellipsoid_surface(&Vector3::new(a, c, a)) / oblate - 1.0).abs() < 1e-12);
    }

    #[test]
    fn sphericity_is_one_for_a_sphere_and_below_for_flatter_shapes() {
        assert_eq!(sphericity(&Shape::Sphere { radius: 1.0 }), 1.0);
        let round = sphericity(&Shape::Ellipsoid { semi_axes: Vector3::repeat(2.0) });
        assert!((round - 1.0).abs() < 1e-12);
        // Semi-axes 2, 1, 0.5: surface 15.86916 by a 2000 × 2000 midpoint quadrature of the
        // parametrised surface, sphere of equal volume 4π π^(1/3) (6V)^(2/3) = 12.5664, so φ = 0.791873.
        let flat = sphericity(&Shape::Ellipsoid { semi_axes: Vector3::new(2.0, 1.0, 0.5) });
        assert!((flat - 0.791873).abs() < 1e-5, "{flat}");
    }
}
