//! Analytic contacts of spheres with spheres, the floor and the cylinder wall.

use nalgebra::Vector3;

use super::ContactGeometry;

/// Sphere A at `a` of radius `ra` against sphere B at `b` (already the right periodic image).
#[inline]
pub fn sphere_sphere(a: &Vector3<f64>, ra: f64, b: &Vector3<f64>, rb: f64) -> Option<ContactGeometry> {
    let d = b - a;
    let distance2 = d.norm_squared();
    let reach = ra + rb;
    if distance2 >= reach * reach {
        return None;
    }
    let distance = distance2.sqrt();
    // Coincident centres have no direction; any unit vector is a valid minimum translation.
    let normal = if distance > 0.0 { d * (1.0 / distance) } else { Vector3::z() };
    Some(ContactGeometry { point: a + 0.5 * (ra + distance - rb) * normal, normal, depth: reach - distance })
}

/// Sphere against the floor z = 0 (body B is the floor; the normal points down into it).
#[inline]
pub fn sphere_floor(center: &Vector3<f64>, radius: f64) -> Option<ContactGeometry> {
    let depth = radius - center.z;
    (depth > 0.0).then(|| ContactGeometry {
        point: Vector3::new(center.x, center.y, 0.5 * (center.z - radius)),
        normal: -Vector3::z(),
        depth,
    })
}

/// Sphere inside a vertical cylinder wall of the given axis and radius (body B is the wall; the
/// normal points radially outward).
#[inline]
pub fn sphere_cylinder_wall(
    center: &Vector3<f64>,
    radius: f64,
    axis_x: f64,
    axis_y: f64,
    wall_radius: f64,
) -> Option<ContactGeometry> {
    let h = Vector3::new(center.x - axis_x, center.y - axis_y, 0.0);
    let rho = h.norm();
    let depth = rho + radius - wall_radius;
    if depth <= 0.0 {
        return None;
    }
    let normal = if rho > 0.0 { h / rho } else { Vector3::x() };
    let mid = 0.5 * (rho + radius + wall_radius);
    Some(ContactGeometry { point: Vector3::new(axis_x, axis_y, center.z) + mid * normal, normal, depth })
}
