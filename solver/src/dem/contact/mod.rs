//! Narrow phase: the exact contact geometry of two overlapping shapes, or of a shape and a wall.

pub mod ellipsoid;
pub mod polyhedron;
pub mod sphere;

use nalgebra::Vector3;

/// Geometry of one contact, the same for both bodies of the pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Contact point (world frame): midway between the two bodies' deepest points, or for two
    /// polyhedra the centre of their overlap (the centre of pressure).
    pub point: Vector3<f64>,
    /// Unit contact normal pointing from body A into body B.
    pub normal: Vector3<f64>,
    /// Penetration depth δ > 0: the minimum translational distance separating the bodies.
    pub depth: f64,
}

use nalgebra::Matrix3;

use self::ellipsoid::EllipsoidPose;
use self::polyhedron::PolyhedronPose;
use super::domain::Domain;

/// One convex piece of a body in the world, as the narrow phase meets it: the body itself for a
/// sphere, an ellipsoid or a polyhedron, one component sphere of a bonded grain.
#[derive(Clone, Copy)]
pub enum Piece<'a> {
    Sphere {
        center: Vector3<f64>,
        radius: f64,
    },
    /// The body's ellipsoid at the current orientation, centred at `center` (the right image).
    Ellipsoid {
        pose: &'a EllipsoidPose,
        center: Vector3<f64>,
    },
    Polyhedron(PolyhedronPose<'a>),
}

impl Piece<'_> {
    /// A sphere or an ellipsoid as an ellipsoid; a sphere is the ellipsoid with equal axes.
    fn ellipsoid(&self) -> EllipsoidPose {
        match *self {
            Piece::Ellipsoid { pose, center } => pose.with_center(center),
            Piece::Sphere { center, radius } => {
                EllipsoidPose::new(center, &Matrix3::identity(), Vector3::repeat(radius))
            }
            Piece::Polyhedron(_) => unreachable!("a polyhedron is met as a polyhedron"),
        }
    }

    /// Smallest half-thickness, the scale against which overlaps are judged.
    pub fn smallest_half_extent(&self) -> f64 {
        match *self {
            Piece::Sphere { radius, .. } => radius,
            Piece::Ellipsoid { pose, .. } => pose.smallest_semi_axis(),
            Piece::Polyhedron(pose) => pose.shape().inner_radius(),
        }
    }
}

/// Contact of piece A with piece B. `warm` carries a direction from one step to the next: on
/// entry the pair's last contact normal or separating direction (zero if none), on exit the
/// one found now (zero if none), so that both touching and merely close pairs start warm.
#[inline(always)]
pub fn between(a: &Piece, b: &Piece, warm: &mut Vector3<f64>) -> Option<ContactGeometry> {
    match (a, b) {
        (Piece::Sphere { center: ca, radius: ra }, Piece::Sphere { center: cb, radius: rb }) => {
            sphere::sphere_sphere(ca, *ra, cb, *rb)
        }
        _ => curved(a, b, warm),
    }
}

/// The non-spherical pairs, kept out of line so that the sphere path stays small.
#[inline(never)]
fn curved(a: &Piece, b: &Piece, warm: &mut Vector3<f64>) -> Option<ContactGeometry> {
    let start = (*warm != Vector3::zeros()).then_some(*warm);
    let flip = |c: ContactGeometry| ContactGeometry { normal: -c.normal, ..c };
    // Polyhedron queries find no separating direction to keep; the ellipsoid query does.
    let (contact, separating) = match (a, b) {
        (Piece::Polyhedron(pa), Piece::Polyhedron(pb)) => {
            (polyhedron::polyhedron_polyhedron(pa, pb, start.as_ref()), None)
        }
        (Piece::Polyhedron(p), Piece::Sphere { center, radius }) => {
            (polyhedron::polyhedron_sphere(p, center, *radius), None)
        }
        (Piece::Sphere { center, radius }, Piece::Polyhedron(p)) => {
            (polyhedron::polyhedron_sphere(p, center, *radius).map(flip), None)
        }
        (Piece::Polyhedron(p), other) => {
            (polyhedron::polyhedron_ellipsoid(p, &other.ellipsoid(), start.as_ref()), None)
        }
        (other, Piece::Polyhedron(p)) => {
            (polyhedron::polyhedron_ellipsoid(p, &other.ellipsoid(), start.map(|n| -n).as_ref()).map(flip), None)
        }
        _ => {
            let (contact, stats) =
                ellipsoid::ellipsoid_ellipsoid_with_stats(&a.ellipsoid(), &b.ellipsoid(), start.as_ref());
            (contact, stats.separating)
        }
    };
    *warm = match (&contact, separating) {
        (Some(c), _) => c.normal,
        (None, Some(n)) => n,
        (None, None) => Vector3::zeros(),
    };
    contact
}

/// Contact of a piece with the floor z = 0.
#[inline]
pub fn with_floor(p: &Piece) -> Option<ContactGeometry> {
    match p {
        Piece::Sphere { center, radius } => sphere::sphere_floor(center, *radius),
        Piece::Ellipsoid { .. } => ellipsoid::ellipsoid_plane(&p.ellipsoid(), &Vector3::zeros(), &Vector3::z()),
        Piece::Polyhedron(pose) => polyhedron::polyhedron_plane(pose, &Vector3::zeros(), &Vector3::z()),
    }
}

/// Contact of a piece with the cylinder wall, if the domain has one.
#[inline]
pub fn with_wall(p: &Piece, domain: &Domain) -> Option<ContactGeometry> {
    let Domain::Cylinder { diameter } = *domain else { return None };
    let c = diameter / 2.0;
    match p {
        Piece::Sphere { center, radius } => sphere::sphere_cylinder_wall(center, *radius, c, c, c),
        Piece::Ellipsoid { .. } => ellipsoid::ellipsoid_cylinder_wall(&p.ellipsoid(), c, c, c),
        Piece::Polyhedron(pose) => polyhedron::polyhedron_cylinder_wall(pose, c, c, c),
    }
}
