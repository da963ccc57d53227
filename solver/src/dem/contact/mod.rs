//! Narrow phase: the exact contact geometry of two overlapping shapes, or of a shape and a wall.
//!
//! One module per algorithm: support functions ([`support`]), GJK ([`gjk`]), EPA ([`epa`]), the
//! centre of pressure ([`centre_of_pressure`]) and frame coherence ([`coherence`]); the queries
//! per pair of shapes in [`sphere`], [`ellipsoid`] and [`polyhedron`].

pub mod centre_of_pressure;
pub mod coherence;
pub mod ellipsoid;
pub(crate) mod epa;
pub(crate) mod gjk;
pub mod manifold;
pub mod polyhedron;
pub mod sphere;
pub mod support;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

pub use self::coherence::{PairCache, Stance};
use self::ellipsoid::EllipsoidPose;
pub use self::manifold::Manifold;
use self::polyhedron::Apart;
pub use self::polyhedron::Mode;
use self::support::PolyhedronPose;
use super::domain::Domain;

/// Where the force of a contact with a polyhedron acts (spheres and ellipsoids have one point,
/// midway between their deepest points, either way).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub enum ContactPoint {
    /// The centroid of the overlap, the centre of pressure of a Winkler contact
    /// ([`centre_of_pressure`]); a face lying on a wall spreads over its corners ([`manifold`]).
    #[default]
    CentreOfPressure,
    /// What the paper's software does (waLBerla's MESA-PD, §3.1): EPA's witness midpoint between
    /// two polyhedra, and against a wall the deepest vertex moved back half the depth, one point.
    Witness,
}

/// Geometry of one contact, the same for both bodies of the pair.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Contact point (world frame): midway between the two bodies' deepest points, or for two
    /// polyhedra the centre of their overlap (the centre of pressure) unless the
    /// [`ContactPoint`] rule is EPA's witness.
    pub point: Vector3<f64>,
    /// Unit contact normal pointing from body A into body B.
    pub normal: Vector3<f64>,
    /// Penetration depth δ > 0: the minimum translational distance separating the bodies.
    pub depth: f64,
}

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
            Piece::Polyhedron(pose) => pose.inner_radius(),
        }
    }

    /// Radius of a sphere about the piece's centre that holds it.
    pub fn bounding_radius(&self) -> f64 {
        match *self {
            Piece::Sphere { radius, .. } => radius,
            Piece::Ellipsoid { pose, .. } => pose.bounding_radius(),
            Piece::Polyhedron(pose) => pose.bounding_radius(),
        }
    }
}

/// Contact of piece A with piece B. `cache` carries what the pair keeps from one step to the
/// next ([`coherence`]): on entry its last contact normal or separating direction, on exit the
/// one found now, so that both touching and merely close pairs start warm, and the distance
/// bound of a pair found apart, recorded with where the pair stands `now`. `mode` says
/// whether the polyhedron shortcuts may be taken, `rule` where two polyhedra's force acts.
#[inline(always)]
pub fn between(
    a: &Piece,
    b: &Piece,
    cache: &mut PairCache,
    now: &Stance,
    mode: Mode,
    rule: ContactPoint,
) -> Option<ContactGeometry> {
    match (a, b) {
        (Piece::Sphere { center: ca, radius: ra }, Piece::Sphere { center: cb, radius: rb }) => {
            sphere::sphere_sphere(ca, *ra, cb, *rb)
        }
        _ => curved(a, b, cache, now, mode, rule),
    }
}

/// The non-spherical pairs, kept out of line so that the sphere path stays small.
#[inline(never)]
fn curved(
    a: &Piece,
    b: &Piece,
    cache: &mut PairCache,
    now: &Stance,
    mode: Mode,
    rule: ContactPoint,
) -> Option<ContactGeometry> {
    let start = (cache.warm != Vector3::zeros()).then_some(cache.warm);
    let flip = |c: ContactGeometry| ContactGeometry { normal: -c.normal, ..c };
    let flip_apart = |a: Apart| Apart { direction: -a.direction, ..a };
    let (contact, apart) = match (a, b) {
        (Piece::Polyhedron(pa), Piece::Polyhedron(pb)) => {
            let (contact, apart, _) = polyhedron::polyhedron_polyhedron_coherent(
                pa,
                pb,
                start.as_ref(),
                cache.gap,
                &mut cache.features,
                mode,
                rule,
            );
            (contact, apart)
        }
        (Piece::Polyhedron(p), Piece::Sphere { center, radius }) => polyhedron::polyhedron_sphere(p, center, *radius),
        (Piece::Sphere { center, radius }, Piece::Polyhedron(p)) => {
            let (contact, apart) = polyhedron::polyhedron_sphere(p, center, *radius);
            (contact.map(flip), flip_apart(apart))
        }
        (Piece::Polyhedron(p), other) => polyhedron::polyhedron_ellipsoid(p, &other.ellipsoid(), start.as_ref()),
        (other, Piece::Polyhedron(p)) => {
            let (contact, apart) = polyhedron::polyhedron_ellipsoid(p, &other.ellipsoid(), start.map(|n| -n).as_ref());
            (contact.map(flip), flip_apart(apart))
        }
        _ => {
            let (ea, eb) = (a.ellipsoid(), b.ellipsoid());
            let (contact, stats) = ellipsoid::ellipsoid_ellipsoid_with_stats(&ea, &eb, start.as_ref());
            let apart = stats
                .separating
                .map_or(Apart::default(), |n| Apart { gap: ellipsoid::separation_gap(&ea, &eb, &n), direction: n });
            (contact, apart)
        }
    };
    match &contact {
        Some(c) => {
            cache.warm = c.normal;
            cache.gap = 0.0;
        }
        None => {
            cache.warm = apart.direction;
            cache.set_gap(apart.gap, now, a.bounding_radius() + b.bounding_radius());
        }
    }
    contact
}

/// Every point of a piece's contacts with the floor (wall 0) and the cylinder wall (wall 1):
/// `point(wall, key, contact, weight)`. Under [`ContactPoint::CentreOfPressure`] a polyhedron's
/// face lying on a wall spreads over its corners ([`manifold`]); every other contact is one
/// point of weight 1 keyed [`manifold::SINGLE`].
#[inline]
pub fn with_walls(
    p: &Piece,
    domain: &Domain,
    rule: ContactPoint,
    mut point: impl FnMut(u32, u64, &ContactGeometry, f64),
) {
    if let Piece::Polyhedron(pose) = p {
        polyhedron_walls(pose, domain, rule, &mut point);
        return;
    }
    if let Some(g) = with_floor(p) {
        point(0, manifold::SINGLE, &g, 1.0);
    }
    if let Some(g) = with_wall(p, domain) {
        point(1, manifold::SINGLE, &g, 1.0);
    }
}

/// A polyhedron's wall contacts: a manifold per wall under the centre of pressure, one point
/// (the paper's software's) under the witness rule.
#[inline(never)]
fn polyhedron_walls(
    pose: &PolyhedronPose,
    domain: &Domain,
    rule: ContactPoint,
    point: &mut impl FnMut(u32, u64, &ContactGeometry, f64),
) {
    // Each manifold is used where it is made: they are a few hundred bytes, and most grains
    // touch no wall.
    let mut points_of = |w: u32, m: &Manifold| {
        for j in 0..m.len {
            point(w, m.features[j], &m.point(j), m.weights[j]);
        }
    };
    let (origin, up) = (Vector3::zeros(), Vector3::z());
    let floor = match rule {
        ContactPoint::CentreOfPressure => polyhedron::polyhedron_plane_manifold(pose, &origin, &up),
        ContactPoint::Witness => polyhedron::polyhedron_plane_witness(pose, &origin, &up).map(Manifold::single),
    };
    if let Some(m) = floor {
        points_of(0, &m);
    }
    if let Domain::Cylinder { diameter } = *domain {
        let c = diameter / 2.0;
        let wall = match rule {
            ContactPoint::CentreOfPressure => polyhedron::polyhedron_cylinder_wall_manifold(pose, c, c, c),
            ContactPoint::Witness => polyhedron::polyhedron_cylinder_wall_witness(pose, c, c, c).map(Manifold::single),
        };
        if let Some(m) = wall {
            points_of(1, &m);
        }
    }
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
