//! Support functions: the farthest point of a convex body along a direction, and of the
//! Minkowski difference K = A − B that GJK and EPA walk (§3.1).
//!
//! A polyhedron answers by hill climbing on its vertex graph from a hint (the previous answer,
//! or a table entry for the direction's cone); an ellipsoid in closed form; a sphere's centre
//! is a point.

use nalgebra::{Matrix3, Vector3};

use super::ellipsoid::EllipsoidPose;
use crate::dem::shape::{ConvexPolyhedron, Polyhedron, PolyhedronFrame};

type V3 = Vector3<f64>;

/// A polyhedron placed in the world for one time step: its base shape, the body-to-world map
/// R S of its stretch S and rotation R, and its centre.
#[derive(Debug, Clone, Copy)]
pub struct PolyhedronPose<'a> {
    shape: &'a ConvexPolyhedron,
    /// Base vertex → world offset from the centre: R S.
    map: Matrix3<f64>,
    /// Base face normal → world normal (up to length): R S⁻¹.
    normal_map: Matrix3<f64>,
    center: V3,
    bounding_radius: f64,
    inner_radius: f64,
}

impl<'a> PolyhedronPose<'a> {
    /// The shape itself (no stretch) turned by the proper rotation `rotation` and moved to
    /// `center`.
    pub fn new(shape: &'a ConvexPolyhedron, center: V3, rotation: &Matrix3<f64>) -> Self {
        debug_assert!(
            (rotation.transpose() * rotation - Matrix3::identity()).amax() < 1e-9 && rotation.determinant() > 0.0,
            "not a proper rotation: {rotation}"
        );
        Self {
            shape,
            map: *rotation,
            normal_map: *rotation,
            center,
            bounding_radius: shape.bounding_radius(),
            inner_radius: shape.inner_radius(),
        }
    }

    /// A grain at `center` with the maps of this step.
    #[inline]
    pub fn with_frame(grain: &'a Polyhedron, frame: &PolyhedronFrame, center: V3) -> Self {
        Self {
            shape: &grain.base,
            map: frame.map,
            normal_map: frame.normal_map,
            center,
            bounding_radius: grain.bounding_radius,
            inner_radius: grain.inner_radius,
        }
    }

    /// The same pose centred elsewhere (a periodic image, or the body's current position).
    #[inline]
    pub fn with_center(&self, center: V3) -> Self {
        Self { center, ..*self }
    }

    pub fn center(&self) -> &V3 {
        &self.center
    }

    pub fn shape(&self) -> &'a ConvexPolyhedron {
        self.shape
    }

    /// Base coordinates → world offsets from the centre (the rotation, for an unstretched shape).
    pub fn map(&self) -> &Matrix3<f64> {
        &self.map
    }

    pub fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    pub fn inner_radius(&self) -> f64 {
        self.inner_radius
    }

    /// Farthest point of the polyhedron in world direction `n` (any non-zero length).
    pub fn support(&self, n: &V3) -> V3 {
        let mut hint = self.cold_hint(n);
        self.center + self.reach(n, &mut hint)
    }

    /// Vertex `v` in the world frame relative to the centre.
    #[inline]
    pub fn vertex(&self, v: u32) -> V3 {
        self.map * self.shape.vertices()[v as usize]
    }

    /// World direction → the base direction whose support is the same vertex.
    #[inline]
    pub fn local(&self, d: &V3) -> V3 {
        self.map.tr_mul(d)
    }

    /// Outward unit normal of triangle `t` in the world frame.
    #[inline]
    pub fn normal(&self, t: u32) -> V3 {
        self.normal_direction(t).normalize()
    }

    /// Outward normal of triangle `t` in the world frame, of no particular length.
    #[inline]
    pub fn normal_direction(&self, t: u32) -> V3 {
        self.normal_map * self.shape.normals()[t as usize]
    }
}

/// A convex body as GJK and EPA see it.
pub(super) trait Convex {
    fn center(&self) -> V3;
    fn bounding_radius(&self) -> f64;
    /// Start value of the hint for a query along world direction `d`.
    fn cold_hint(&self, d: &V3) -> u32;
    /// Farthest point along world direction `d`, relative to the centre; `hint` carries the
    /// previous answer's vertex between calls (unused by smooth bodies).
    fn reach(&self, d: &V3, hint: &mut u32) -> V3;
}

impl Convex for PolyhedronPose<'_> {
    fn center(&self) -> V3 {
        self.center
    }

    fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    fn cold_hint(&self, d: &V3) -> u32 {
        self.shape.start(&self.local(d))
    }

    #[inline]
    fn reach(&self, d: &V3, hint: &mut u32) -> V3 {
        *hint = self.shape.climb(&self.local(d), *hint);
        self.vertex(*hint)
    }
}

impl Convex for EllipsoidPose {
    fn center(&self) -> V3 {
        *EllipsoidPose::center(self)
    }

    fn bounding_radius(&self) -> f64 {
        EllipsoidPose::bounding_radius(self)
    }

    fn cold_hint(&self, _: &V3) -> u32 {
        0
    }

    fn reach(&self, d: &V3, _: &mut u32) -> V3 {
        self.support(d) - EllipsoidPose::center(self)
    }
}

/// A point (the centre of a sphere, whose radius is added afterwards).
pub(super) struct Centre(pub V3);

impl Convex for Centre {
    fn center(&self) -> V3 {
        self.0
    }

    fn bounding_radius(&self) -> f64 {
        0.0
    }

    fn cold_hint(&self, _: &V3) -> u32 {
        0
    }

    fn reach(&self, _: &V3, _: &mut u32) -> V3 {
        V3::zeros()
    }
}

/// A point of K = A − B with the two points it is the difference of, all relative to A's
/// centre (which keeps the coordinates small whatever the bodies' positions), and the vertices
/// they are (for polyhedra), which name the features EPA ends on.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Point {
    pub w: V3,
    pub a: V3,
    pub b: V3,
    pub vertex_a: u32,
    pub vertex_b: u32,
}

/// The support function of K.
pub(super) struct Cso<'p, A, B> {
    pub a: &'p A,
    pub b: &'p B,
    /// x_B − x_A.
    pub d: V3,
    hint_a: u32,
    hint_b: u32,
    /// Direction of the previous query.
    last: V3,
    pub queries: u32,
}

impl<'p, A: Convex, B: Convex> Cso<'p, A, B> {
    pub fn new(a: &'p A, b: &'p B, start: &V3) -> Self {
        let (hint_a, hint_b) = (a.cold_hint(start), b.cold_hint(&-start));
        Self { a, b, d: b.center() - a.center(), hint_a, hint_b, last: *start, queries: 0 }
    }

    /// The support function with its climbs starting from these vertices (those of a nearby
    /// earlier answer along `start`).
    pub fn warm(a: &'p A, b: &'p B, start: &V3, hint_a: u32, hint_b: u32) -> Self {
        Self { a, b, d: b.center() - a.center(), hint_a, hint_b, last: *start, queries: 0 }
    }

    #[inline]
    pub fn support(&mut self, n: &V3) -> Point {
        self.queries += 1;
        // A direction turned by more than 90° from the previous one (GJK's far side) climbs
        // from the start table rather than across the whole body.
        if n.dot(&self.last) < 0.0 {
            (self.hint_a, self.hint_b) = (self.a.cold_hint(n), self.b.cold_hint(&-n));
        }
        self.last = *n;
        let a = self.a.reach(n, &mut self.hint_a);
        let b = self.b.reach(&-n, &mut self.hint_b) + self.d;
        Point { w: a - b, a, b, vertex_a: self.hint_a, vertex_b: self.hint_b }
    }
}
