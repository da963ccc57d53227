//! Narrow phase: the exact contact geometry of two overlapping shapes, or of a shape and a wall.

pub mod sphere;

use nalgebra::Vector3;

/// Geometry of one contact, the same for both bodies of the pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Contact point, midway between the two bodies' deepest points (world frame).
    pub point: Vector3<f64>,
    /// Unit contact normal pointing from body A into body B.
    pub normal: Vector3<f64>,
    /// Penetration depth δ > 0: the minimum translational distance separating the bodies.
    pub depth: f64,
}

use super::domain::Domain;
use super::shape::Shape;

/// Contact of body A (shape `a` at `xa`) with body B (shape `b` at `xb`, the right image).
#[inline]
pub fn between(a: &Shape, xa: &Vector3<f64>, b: &Shape, xb: &Vector3<f64>) -> Option<ContactGeometry> {
    match (a, b) {
        (Shape::Sphere { radius: ra }, Shape::Sphere { radius: rb }) => sphere::sphere_sphere(xa, *ra, xb, *rb),
        _ => unimplemented!("ellipsoid contacts"),
    }
}

/// Contact of a body with the floor z = 0.
#[inline]
pub fn with_floor(shape: &Shape, x: &Vector3<f64>) -> Option<ContactGeometry> {
    match shape {
        Shape::Sphere { radius } => sphere::sphere_floor(x, *radius),
        _ => unimplemented!("ellipsoid contacts"),
    }
}

/// Contact of a body with the cylinder wall, if the domain has one.
#[inline]
pub fn with_wall(shape: &Shape, x: &Vector3<f64>, domain: &Domain) -> Option<ContactGeometry> {
    let Domain::Cylinder { diameter } = *domain else { return None };
    let c = diameter / 2.0;
    match shape {
        Shape::Sphere { radius } => sphere::sphere_cylinder_wall(x, *radius, c, c, c),
        _ => unimplemented!("ellipsoid contacts"),
    }
}
