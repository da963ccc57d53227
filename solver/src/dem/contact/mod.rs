//! Narrow phase: the exact contact geometry of two overlapping shapes, or of a shape and a wall.

pub mod ellipsoid;
pub mod polyhedron;
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

use nalgebra::Matrix3;

use self::ellipsoid::EllipsoidPose;
use super::domain::Domain;
use super::shape::Shape;

/// A body as the narrow phase sees it: its shape at a position (the right periodic image), and
/// for an ellipsoid its pose from the current orientation.
#[derive(Clone, Copy)]
pub struct Placed<'a> {
    pub shape: &'a Shape,
    pub position: Vector3<f64>,
    pub pose: Option<&'a EllipsoidPose>,
}

impl Placed<'_> {
    /// The body as an ellipsoid at its position; a sphere is the ellipsoid with equal axes.
    fn ellipsoid(&self) -> EllipsoidPose {
        match (self.pose, self.shape) {
            (Some(pose), _) => pose.with_center(self.position),
            (None, shape) => {
                EllipsoidPose::new(self.position, &Matrix3::identity(), Vector3::repeat(shape.bounding_radius()))
            }
        }
    }
}

/// Contact of body A with body B; `warm` is the pair's normal at the previous step, if any.
#[inline]
pub fn between(a: &Placed, b: &Placed, warm: Option<&Vector3<f64>>) -> Option<ContactGeometry> {
    match (a.shape, b.shape) {
        (Shape::Sphere { radius: ra }, Shape::Sphere { radius: rb }) => {
            sphere::sphere_sphere(&a.position, *ra, &b.position, *rb)
        }
        _ => ellipsoid::ellipsoid_ellipsoid(&a.ellipsoid(), &b.ellipsoid(), warm),
    }
}

/// Contact of a body with the floor z = 0.
#[inline]
pub fn with_floor(a: &Placed) -> Option<ContactGeometry> {
    match a.shape {
        Shape::Sphere { radius } => sphere::sphere_floor(&a.position, *radius),
        Shape::Ellipsoid { .. } => ellipsoid::ellipsoid_plane(&a.ellipsoid(), &Vector3::zeros(), &Vector3::z()),
    }
}

/// Contact of a body with the cylinder wall, if the domain has one.
#[inline]
pub fn with_wall(a: &Placed, domain: &Domain) -> Option<ContactGeometry> {
    let Domain::Cylinder { diameter } = *domain else { return None };
    let c = diameter / 2.0;
    match a.shape {
        Shape::Sphere { radius } => sphere::sphere_cylinder_wall(&a.position, *radius, c, c, c),
        Shape::Ellipsoid { .. } => ellipsoid::ellipsoid_cylinder_wall(&a.ellipsoid(), c, c, c),
    }
}
