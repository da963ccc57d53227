//! Contact geometry of convex polyhedra (grains from meshes) with each other, with spheres and
//! ellipsoids, with the floor and with the cylinder wall (issue 4, item 1).
//!
//! # Depth and normal: GJK + EPA (§3.1)
//! As in the paper's software, the depth is the minimum translational distance and comes from
//! GJK + EPA on support functions. With K = A − B the Minkowski difference, the bodies overlap
//! iff the origin lies in K, and the depth is the origin's distance to ∂K; the closest boundary
//! point is δ n with n the normal from A into B (the same δ = min over unit n of
//! h_A(n) + h_B(−n) − n·(x_B − x_A) as in the ellipsoid module).
//!
//! * GJK (Gilbert, Johnson & Keerthi 1988) with the signed-volume sub-algorithm (Montanari et
//!   al. 2017) decides overlap. It starts from the tetrahedron of the support points along three
//!   directions tilted 3° around the start direction and along its opposite: for a persisting
//!   contact (start = last step's normal) the first three usually span the face of K nearest the
//!   origin, so the tetrahedron already holds the origin; otherwise GJK goes on from it. A
//!   separating direction ends it early (a pair that has just parted costs one support query).
//!   When the origin lies on a lower-dimensional simplex (the symmetric cases of hand-built
//!   tests) the simplex is completed by support points off its span, or the pair is touching if
//!   K has none (depth 0, no contact).
//! * EPA (van den Bergen 2001) grows that polytope towards ∂K: the face nearest the origin is
//!   replaced by the support point along its normal until that point lies on the face's plane.
//!   For two polyhedra K is a polytope whose vertices are differences of vertices, so EPA ends on
//!   a true face of K after finitely many steps: depth and normal are exact to rounding.
//!
//! Support queries climb the vertex adjacency graph: from the start vertex to the best
//! neighbour until none is better. On a convex polyhedron a vertex no neighbour improves on is a
//! global maximum (the polyhedron lies in the cone its edges span), so the climb is exact. Each
//! query starts from the previous query's vertex of the same body (GJK and EPA ask in nearby
//! directions); the first one, and any turned by more than 90° from the previous, from a table
//! of the support vertices of the 26 directions of a 3 × 3 × 3 grid.
//!
//! # Contact point: the overlap's centre of pressure
//! A single point carries the contact force. EPA's witness points are arbitrary points of the
//! touching features: for two faces in contact (a cube resting on a face) any point of the
//! overlap of the two faces is a witness, and a force off the centre would tip the cube. The
//! point used here is the centroid of the overlap volume, i.e. the centre of pressure of a
//! Winkler (elastic foundation) contact, whose pressure is proportional to the local overlap:
//! for a face resting flat it is the centre of the shared area, and tilting the body moves it
//! towards the deeper side, so the contact pushes back (a resting cube is stable; the EPA
//! witness would make it rock between its corners). For vertex–face and edge–edge contacts it
//! is the centroid of the small overlapping tip, within O(δ) of the EPA witnesses. It varies
//! continuously with the poses. Along the normal the point is placed midway between the two
//! deepest points, as for spheres and ellipsoids.
//!
//! The overlap lies in the slab between B's lowest level s_B and A's highest s_A along n. Its
//! boundary is the part of ∂A inside B plus the part of ∂B inside A, and only the triangles of A
//! reaching above s_B and those of B reaching below s_A can contribute; they are found by
//! walking the vertex graph from the deepest vertex (the vertices beyond a level form a connected
//! set on a convex polyhedron). Each such triangle of A is clipped by the planes of B's (a
//! convex body's part in a half-space is cut out by the planes of its faces that reach into that
//! half-space, so these planes suffice) and vice versa, and the volume and first moments follow
//! from the clipped pieces by the divergence theorem: V = ∮ x·n dS / 3, ∫ x_i dV = ∮ x_i² n_i dS / 2.
//! Contacts between a polyhedron and the floor or the cylinder wall use the same construction
//! against the plane (the wall's tangent plane at the deepest point), where the cut face adds
//! nothing. Spheres and ellipsoids touch a polyhedron in a point, and there the point is midway
//! between the deepest points.
//!
//! # Accuracy (tests/contact_polyhedron.rs)
//! * polyhedron–polyhedron and –plane: exact to rounding. Over 325 random hull pairs the depth
//!   agrees with a brute-force separating-axis reference to 3e-16, the normal to 2e-15, the point
//!   with an independently built overlap centroid to 2e-15.
//! * polyhedron–sphere: exact (the sphere is its centre grown by its radius; the centre's
//!   distance to the polyhedron comes from GJK, or from the nearest face plane when inside).
//! * polyhedron–cylinder wall: the depth is the excess of the grain's farthest point from the axis
//!   (a scan of the vertices, so exact); it is the minimum translational distance up to a
//!   relative O((grain width / wall radius)²).
//! * polyhedron–ellipsoid: K has curved patches, where EPA converges only in the limit; it stops
//!   at a support gap of 1e-10 of the pair's size (normal then within ~1e-5). The answer is then
//!   polished by Newton on the feature of A that EPA ended on (vertex, edge or face), where the
//!   depth function is smooth, and the polish is kept only if it stays on that feature and in
//!   EPA's bracket: depth, normal and point exact to rounding (tests: a round ellipsoid agrees
//!   with the exact sphere contact to 1e-15; general ones are certified local minima to 3e-16
//!   and never deeper than parry's EPA lower bound). Overlaps deeper than the ellipsoid's
//!   smallest radius of curvature keep EPA's answer.
//!
//! # Symmetry
//! Polyhedron pairs are put in a canonical order (by centre, then orientation) before solving,
//! so that swapping A and B gives bit-for-bit the same point and depth and the negated normal.
//!
//! # Cost
//! Shapes precompute their adjacency once; a pose is a rotation matrix and a centre. The hot
//! path does not allocate: EPA's polytope (128 vertices, far more than a shallow contact needs)
//! and the clipped triangles (128 per body) live in per-thread buffers. A contact whose overlap
//! involves more triangles than those hold falls back to the EPA witness midpoint
//! ([`PolyhedronStats::centre_of_pressure`] tells). benches/contact_polyhedron.rs measures, per
//! shallow contact, 4.3 µs warm and 5.1 µs cold for 50-face grains, 6.1 and 7.5 µs for 300 faces
//! (parry3d's `query::contact`, which gives no centre of pressure and whose EPA now and then
//! stops early: 2.3 and 6.3 µs); a floor contact takes 0.6 µs.

use std::cell::RefCell;

use nalgebra::{Matrix3, Vector2, Vector3};
use thiserror::Error;

use super::ContactGeometry;
use super::ellipsoid::{EllipsoidPose, tangent_basis, unit};
use crate::grain::TriMesh;
use crate::grain::simplify::CONVEXITY_TOLERANCE;

type V3 = Vector3<f64>;
type V2 = Vector2<f64>;

/// Tilt of GJK's three starting directions from the start direction (about 3°).
const TILT: f64 = 0.05;
const HALF_SQRT_3: f64 = 0.866_025_403_784_438_6;
/// GJK iterations before the origin is taken to sit on the boundary (depth 0); a polytope pair
/// needs far fewer (each iteration adds a support point strictly closer to the origin).
const GJK_ITERATIONS: u32 = 64;
/// Capacity of EPA's polytope. A shallow contact needs 5–20 vertices.
const EPA_VERTICES: usize = 128;
/// Live faces of a convex polytope with V vertices number 2V − 4; the horizon being replaced adds
/// at most V more before the old faces are recycled.
const EPA_FACES: usize = 3 * EPA_VERTICES;
/// Newton iterations of the polyhedron–ellipsoid polish, and the step (radians) that ends it.
const POLISH_ITERATIONS: u32 = 16;
const POLISH_STEP: f64 = 1e-12;
/// Relative to the pair's size (sum of bounding radii): distances below this count as zero
/// (the origin on a simplex, or on ∂K: touching bodies).
const TOUCHING: f64 = 1e-13;
/// EPA stops when the support point along the nearest face's normal lies within this (relative)
/// distance of that face: rounding for polyhedra...
const GAP_POLYTOPE: f64 = 1e-12;
/// ...and for curved bodies, where EPA converges only in the limit: close enough for the Newton
/// polish to start in its quadratic regime.
const GAP_SMOOTH: f64 = 1e-10;
/// A face counts as seen from a new EPA vertex unless the vertex lies this far behind its plane,
/// so that (nearly) coplanar faces merge instead of leaving slivers.
const VISIBLE: f64 = 1e-13;
/// GJK distance queries (polyhedron–sphere) stop when the gap between the bound from the support
/// point and the simplex's distance is below this fraction of the squared distance.
const DISTANCE_TOLERANCE: f64 = 1e-14;
/// Vertices above the level of the other body, and triangles touching them, that the overlap
/// integration can hold per body.
const CAP_VERTICES: usize = 64;
const CAP_TRIANGLES: usize = 128;
/// tan(π/8): a direction's component counts as 0 in the start table below this fraction of its
/// largest component, so each of the 26 grid directions covers a cone of about 22.5°.
const TABLE_CUT: f64 = 0.414_213_562_373_095_1;

/// Why a mesh cannot be used as a convex polyhedron.
#[derive(Debug, Error, PartialEq)]
pub enum PolyhedronError {
    #[error("the mesh is not convex: use its convex hull")]
    NotConvex,
}

/// A convex polyhedron in its body frame, with what the narrow phase needs precomputed.
///
/// The body frame is the grain's: centre of mass at the origin, principal axes of inertia along
/// x, y, z ([`crate::grain::UnitMesh::rescaled`] gives meshes in that frame).
#[derive(Debug, Clone)]
pub struct ConvexPolyhedron {
    vertices: Vec<V3>,
    /// Neighbours of vertex i: `neighbours[neighbour_start[i]..neighbour_start[i + 1]]`.
    neighbour_start: Vec<u32>,
    neighbours: Vec<u32>,
    triangles: Vec<[u32; 3]>,
    /// Outward unit normal of each triangle.
    normals: Vec<V3>,
    /// Triangles around vertex i: `incident[incident_start[i]..incident_start[i + 1]]`.
    incident_start: Vec<u32>,
    incident: Vec<u32>,
    /// Support vertex of each direction (i − 1, j − 1, k − 1) of the 3 × 3 × 3 grid, at index
    /// i + 3j + 9k (the centre entry is unused).
    starts: [u32; 27],
    bounding_radius: f64,
    inner_radius: f64,
}

impl ConvexPolyhedron {
    /// The polyhedron bounded by `mesh`, whose vertices are taken as body-frame coordinates.
    /// Vertices used by no triangle are dropped.
    pub fn new(mesh: &TriMesh) -> Result<Self, PolyhedronError> {
        if !mesh.is_convex(CONVEXITY_TOLERANCE) {
            return Err(PolyhedronError::NotConvex);
        }
        let mut index = vec![u32::MAX; mesh.vertices().len()];
        let mut vertices = Vec::new();
        let triangles: Vec<[u32; 3]> = mesh
            .triangles()
            .iter()
            .map(|tri| {
                tri.map(|v| {
                    if index[v as usize] == u32::MAX {
                        index[v as usize] = vertices.len() as u32;
                        vertices.push(mesh.vertices()[v as usize]);
                    }
                    index[v as usize]
                })
            })
            .collect();
        let n = vertices.len();
        // A closed oriented mesh traverses each edge once in each direction, so recording p → q
        // for every triangle edge lists each neighbour of p exactly once.
        let mut adjacency = vec![Vec::new(); n];
        let mut around = vec![Vec::new(); n];
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                adjacency[tri[k] as usize].push(tri[(k + 1) % 3]);
                around[tri[k] as usize].push(t as u32);
            }
            let [a, b, c] = tri.map(|v| vertices[v as usize]);
            normals.push((b - a).cross(&(c - a)).normalize());
        }
        let (neighbour_start, neighbours) = compressed(&adjacency);
        let (incident_start, incident) = compressed(&around);
        let bounding_radius = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let inner_radius =
            triangles.iter().zip(&normals).map(|(t, n)| n.dot(&vertices[t[0] as usize])).fold(f64::INFINITY, f64::min);
        let mut shape = Self {
            vertices,
            neighbour_start,
            neighbours,
            triangles,
            normals,
            incident_start,
            incident,
            starts: [0; 27],
            bounding_radius,
            inner_radius,
        };
        for (cell, start) in shape.starts.iter_mut().enumerate() {
            let direction = V3::new((cell % 3) as f64 - 1.0, (cell / 3 % 3) as f64 - 1.0, (cell / 9) as f64 - 1.0);
            *start = (0..n as u32)
                .max_by(|&p, &q| {
                    direction.dot(&shape.vertices[p as usize]).total_cmp(&direction.dot(&shape.vertices[q as usize]))
                })
                .expect("a valid mesh has vertices");
        }
        Ok(shape)
    }

    pub fn vertices(&self) -> &[V3] {
        &self.vertices
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Distance from the body origin to the nearest face plane: the radius of the largest ball
    /// about the origin inside the polyhedron, the scale against which overlaps are judged.
    pub fn inner_radius(&self) -> f64 {
        self.inner_radius
    }

    /// Radius of the smallest sphere about the body origin that holds the polyhedron.
    pub fn bounding_radius(&self) -> f64 {
        self.bounding_radius
    }

    fn neighbours_of(&self, v: u32) -> &[u32] {
        &self.neighbours[self.neighbour_start[v as usize] as usize..self.neighbour_start[v as usize + 1] as usize]
    }

    fn incident_to(&self, v: u32) -> &[u32] {
        &self.incident[self.incident_start[v as usize] as usize..self.incident_start[v as usize + 1] as usize]
    }

    /// Start vertex for a support query in body direction `d`: the table entry of its cone.
    fn start(&self, d: &V3) -> u32 {
        let cut = TABLE_CUT * d.amax();
        let cell = |c: f64| {
            if c > cut {
                2
            } else if c < -cut {
                0
            } else {
                1
            }
        };
        self.starts[cell(d.x) + 3 * cell(d.y) + 9 * cell(d.z)]
    }

    /// Vertex farthest along body direction `d`, climbing from `at` to the best neighbour
    /// while one improves.
    #[inline]
    fn climb(&self, d: &V3, mut at: u32) -> u32 {
        let mut best = self.vertices[at as usize].dot(d);
        loop {
            let from = at;
            for &w in self.neighbours_of(from) {
                let value = self.vertices[w as usize].dot(d);
                if value > best {
                    (best, at) = (value, w);
                }
            }
            if at == from {
                return at;
            }
        }
    }
}

/// Compressed rows of a list of lists.
fn compressed(rows: &[Vec<u32>]) -> (Vec<u32>, Vec<u32>) {
    let mut start = Vec::with_capacity(rows.len() + 1);
    let mut flat = Vec::with_capacity(rows.iter().map(Vec::len).sum());
    start.push(0);
    for row in rows {
        flat.extend_from_slice(row);
        start.push(flat.len() as u32);
    }
    (start, flat)
}

/// A polyhedron placed in the world for one time step: its shape, rotation and centre.
#[derive(Debug, Clone, Copy)]
pub struct PolyhedronPose<'a> {
    shape: &'a ConvexPolyhedron,
    /// Body → world.
    rotation: Matrix3<f64>,
    center: V3,
}

impl<'a> PolyhedronPose<'a> {
    /// The shape's body frame turned by the proper rotation `rotation` and moved to `center`.
    pub fn new(shape: &'a ConvexPolyhedron, center: V3, rotation: &Matrix3<f64>) -> Self {
        debug_assert!(
            (rotation.transpose() * rotation - Matrix3::identity()).amax() < 1e-9 && rotation.determinant() > 0.0,
            "not a proper rotation: {rotation}"
        );
        Self { shape, rotation: *rotation, center }
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

    pub fn rotation(&self) -> &Matrix3<f64> {
        &self.rotation
    }

    /// Farthest point of the polyhedron in world direction `n` (any non-zero length).
    pub fn support(&self, n: &V3) -> V3 {
        let mut hint = self.shape.start(&self.rotation.tr_mul(n));
        self.center + self.reach(n, &mut hint)
    }

    /// Vertex `v` in the world frame relative to the centre.
    #[inline]
    fn vertex(&self, v: u32) -> V3 {
        self.rotation * self.shape.vertices[v as usize]
    }
}

/// A convex body as GJK and EPA see it.
trait Convex {
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
        self.shape.bounding_radius
    }

    fn cold_hint(&self, d: &V3) -> u32 {
        self.shape.start(&self.rotation.tr_mul(d))
    }

    #[inline]
    fn reach(&self, d: &V3, hint: &mut u32) -> V3 {
        *hint = self.shape.climb(&self.rotation.tr_mul(d), *hint);
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
struct Centre(V3);

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
/// centre (which keeps the coordinates small whatever the bodies' positions).
#[derive(Debug, Clone, Copy, Default)]
struct Point {
    w: V3,
    a: V3,
    b: V3,
    /// A's vertex (for a polyhedron A), which tells the feature EPA ends on.
    vertex: u32,
}

/// The support function of K.
struct Cso<'p, A, B> {
    a: &'p A,
    b: &'p B,
    /// x_B − x_A.
    d: V3,
    hint_a: u32,
    hint_b: u32,
    /// Direction of the previous query.
    last: V3,
    queries: u32,
}

impl<'p, A: Convex, B: Convex> Cso<'p, A, B> {
    fn new(a: &'p A, b: &'p B, start: &V3) -> Self {
        let (hint_a, hint_b) = (a.cold_hint(start), b.cold_hint(&-start));
        Self { a, b, d: b.center() - a.center(), hint_a, hint_b, last: *start, queries: 0 }
    }

    #[inline]
    fn support(&mut self, n: &V3) -> Point {
        self.queries += 1;
        // A direction turned by more than 90° from the previous one (GJK's far side) climbs
        // from the start table rather than across the whole body.
        if n.dot(&self.last) < 0.0 {
            (self.hint_a, self.hint_b) = (self.a.cold_hint(n), self.b.cold_hint(&-n));
        }
        self.last = *n;
        let a = self.a.reach(n, &mut self.hint_a);
        let b = self.b.reach(&-n, &mut self.hint_b) + self.d;
        Point { w: a - b, a, b, vertex: self.hint_a }
    }
}

/// How one polyhedron query was answered, for diagnostics, tests and benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PolyhedronStats {
    pub gjk_iterations: u32,
    pub epa_iterations: u32,
    /// Support queries on K (each is one query per body).
    pub support_queries: u32,
    /// EPA met its gap tolerance (false only if its polytope filled up or degenerated).
    pub converged: bool,
    /// The point is the overlap's centre of pressure (false: the EPA witness midpoint).
    pub centre_of_pressure: bool,
}

/// Contact of two convex polyhedra, or `None` when they do not overlap.
///
/// `warm_normal` is this pair's normal (from A to B) at the previous time step, if the contact
/// persists.
pub fn polyhedron_polyhedron(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    warm_normal: Option<&V3>,
) -> Option<ContactGeometry> {
    polyhedron_polyhedron_with_stats(a, b, warm_normal).0
}

/// [`polyhedron_polyhedron`], also telling how the answer was found.
pub fn polyhedron_polyhedron_with_stats(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    warm_normal: Option<&V3>,
) -> (Option<ContactGeometry>, PolyhedronStats) {
    if canonical(a, b) {
        solve_polyhedra(a, b, warm_normal)
    } else {
        let (contact, stats) = solve_polyhedra(b, a, warm_normal.map(|n| -n).as_ref());
        (contact.map(|c| ContactGeometry { normal: -c.normal, ..c }), stats)
    }
}

/// Whether (a, b) is the canonical order of the pair: by centre, then by rotation. Identical
/// poses of identical shapes are one body twice, where any normal is as good as its opposite.
fn canonical(a: &PolyhedronPose, b: &PolyhedronPose) -> bool {
    let keys = a.center.iter().zip(b.center.iter()).chain(a.rotation.iter().zip(b.rotation.iter()));
    for (p, q) in keys {
        match p.total_cmp(q) {
            std::cmp::Ordering::Less => return true,
            std::cmp::Ordering::Greater => return false,
            std::cmp::Ordering::Equal => {}
        }
    }
    true
}

fn solve_polyhedra(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    warm_normal: Option<&V3>,
) -> (Option<ContactGeometry>, PolyhedronStats) {
    let mut stats = PolyhedronStats::default();
    let Some(end) = penetration(a, b, warm_normal, GAP_POLYTOPE, &mut stats) else {
        return (None, stats);
    };
    let frame = Frame::new(&end.normal);
    // Frame coordinates are taken from the witness midpoint, which lies near the overlap: small
    // coordinates keep the boundary integrals free of cancellation.
    let middle = (end.a + end.b) * 0.5;
    let (top, bottom) = (end.normal.dot(&(end.a - middle)), end.normal.dot(&(end.b - middle)));
    let centroid = SLABS.with_borrow_mut(|slabs| {
        let [slab_a, slab_b] = &mut **slabs;
        slab_a.gather(a, &frame.coordinates(&-middle), &frame, 1.0, bottom)?;
        slab_b.gather(b, &frame.coordinates(&(b.center - a.center - middle)), &frame, -1.0, top)?;
        let mut integrals = Integrals::default();
        slab_a.clipped_by(slab_b, &mut integrals)?;
        slab_b.clipped_by(slab_a, &mut integrals)?;
        integrals.centroid()
    });
    stats.centre_of_pressure = centroid.is_some();
    let offset = centroid.map_or(V3::zeros(), |c| frame.world(&V3::new(c.x, c.y, 0.0)));
    let point = a.center + middle + offset;
    (Some(ContactGeometry { point, normal: end.normal, depth: end.depth }), stats)
}

/// Contact of a polyhedron (body A) with an ellipsoid (body B), or `None` when they do not
/// overlap: EPA to a support gap of 1e-10 of the pair's size, then Newton on the polyhedron's
/// feature (module docs); the point is the midpoint of the deepest points.
pub fn polyhedron_ellipsoid(
    a: &PolyhedronPose,
    b: &EllipsoidPose,
    warm_normal: Option<&V3>,
) -> Option<ContactGeometry> {
    let mut stats = PolyhedronStats::default();
    let end = penetration(a, b, warm_normal, GAP_SMOOTH, &mut stats)?;
    let reach = a.shape.bounding_radius + b.bounding_radius();
    let (normal, depth) = polish(a, b, &end, GAP_SMOOTH * reach).unwrap_or((end.normal, end.depth));
    // EPA's witness points are barycentric mixtures of support points that may lie far apart on
    // the curved surface; the ellipsoid's own support point along −n is unique and exact.
    let deepest = b.support(&-normal);
    Some(ContactGeometry { point: deepest + normal * (0.5 * depth), normal, depth })
}

/// Newton polish of a polyhedron–ellipsoid EPA result on the polyhedron's feature at the
/// minimum: EPA's last face tells whether it is a vertex, an edge or a face of A, and on it the
/// depth function f(n) = h_A(n) + h_E(−n) − n·d is smooth. A face fixes n outright; on an edge
/// n turns about the edge (Newton on a circle); at a vertex n is free (Newton on the sphere).
/// The result is kept only if A's support along it is still that feature and the depth lies in
/// EPA's bracket [δ, δ + gap]; otherwise (or if the Hessian is not positive definite, which
/// takes an overlap deeper than the ellipsoid's smallest radius of curvature) EPA's answer
/// stands.
fn polish(a: &PolyhedronPose, e: &EllipsoidPose, end: &Penetration, gap: f64) -> Option<(V3, f64)> {
    let shape2 = e.shape2();
    let d = *EllipsoidPose::center(e) - a.center;
    let mut feature = [end.vertices[0]; 3];
    let mut corners = 1;
    for &v in &end.vertices[1..] {
        if !feature[..corners].contains(&v) {
            feature[corners] = v;
            corners += 1;
        }
    }
    let v = feature.map(|i| a.vertex(i));
    let reach = |n: &V3| n.dot(&(shape2 * n)).sqrt();
    let (normal, depth) = match corners {
        1 => newton_on_sphere(&(v[0] - d), shape2, &end.normal)?,
        2 => newton_on_circle(&(v[0] - d), &(v[1] - v[0]), shape2, &end.normal)?,
        _ => {
            let cross = (v[1] - v[0]).cross(&(v[2] - v[0]));
            let n = unit(&cross)?;
            let n = if n.dot(&end.normal) < 0.0 { -n } else { n };
            (n, n.dot(&(v[0] - d)) + reach(&n))
        }
    };
    let tolerance = TOUCHING * (a.shape.bounding_radius + e.bounding_radius());
    let mut hint = feature[0];
    let top = a.reach(&normal, &mut hint).dot(&normal);
    let on_feature = top - normal.dot(&v[0]) <= tolerance;
    let bracketed = depth >= end.depth - tolerance && depth <= end.depth + gap + tolerance;
    (on_feature && bracketed).then_some((normal, depth))
}

/// Minimum over unit n of n·c + h(n), h(n) = √(nᵀ S n), by Riemannian Newton from `start`:
/// the depth of a vertex (c = vertex − ellipsoid centre) in an ellipsoid. `None` if the
/// Hessian is not positive definite or Newton does not settle.
fn newton_on_sphere(c: &V3, shape2: &Matrix3<f64>, start: &V3) -> Option<(V3, f64)> {
    let mut n = *start;
    for _ in 0..POLISH_ITERATIONS {
        let sn = shape2 * n;
        let h = n.dot(&sn).sqrt();
        let gradient = c + sn / h;
        let value = n.dot(&gradient);
        let hessian = (shape2 - sn * sn.transpose() / (h * h)) / h;
        let (t1, t2) = tangent_basis(&n);
        let (h1, h2) = (hessian * t1, hessian * t2);
        let (a11, a12, a22) = (t1.dot(&h1) - value, t1.dot(&h2), t2.dot(&h2) - value);
        let det = a11 * a22 - a12 * a12;
        if a11 <= 0.0 || det <= 0.0 {
            return None;
        }
        let (g1, g2) = (t1.dot(&gradient), t2.dot(&gradient));
        let step = V2::new(a12 * g2 - a22 * g1, a12 * g1 - a11 * g2) / det;
        n = (n + t1 * step.x + t2 * step.y).normalize();
        if step.norm() <= POLISH_STEP {
            return Some((n, n.dot(c) + n.dot(&(shape2 * n)).sqrt()));
        }
    }
    None
}

/// Minimum of n·c + h(n) over the unit n perpendicular to `edge`, by Newton on that circle
/// from the projection of `start`: the depth of an edge (c = an end − ellipsoid centre).
fn newton_on_circle(c: &V3, edge: &V3, shape2: &Matrix3<f64>, start: &V3) -> Option<(V3, f64)> {
    let e = unit(edge)?;
    let u = unit(&(start - e * e.dot(start)))?;
    let w = e.cross(&u);
    let mut angle: f64 = 0.0;
    for _ in 0..POLISH_ITERATIONS {
        let (sin, cos) = angle.sin_cos();
        let (n, t) = (u * cos + w * sin, w * cos - u * sin);
        let sn = shape2 * n;
        let h = n.dot(&sn).sqrt();
        let gradient = c + sn / h;
        let st = shape2 * t;
        // d²/dθ² of h(n(θ)) is tᵀ∇²h t − n·∇h, and of n·c it is −n·c: together tᵀ∇²h t − f.
        let curvature = (t.dot(&st) - (t.dot(&sn) / h).powi(2)) / h - n.dot(&gradient);
        if curvature <= 0.0 {
            return None;
        }
        let step = -t.dot(&gradient) / curvature;
        angle += step;
        if step.abs() <= POLISH_STEP {
            let (sin, cos) = angle.sin_cos();
            let n = u * cos + w * sin;
            return Some((n, n.dot(c) + n.dot(&(shape2 * n)).sqrt()));
        }
    }
    None
}

/// Contact of a polyhedron (body A) with a sphere (body B), exact.
///
/// The sphere is its centre c grown by its radius r, so with g the distance from c to the
/// polyhedron the depth is r − g outside (normal from the nearest point to c) and r + g inside
/// (g to the nearest face plane, normal that face's).
pub fn polyhedron_sphere(a: &PolyhedronPose, center: &V3, radius: f64) -> Option<ContactGeometry> {
    let d = center - a.center;
    let reach = a.shape.bounding_radius + radius;
    if d.norm_squared() >= reach * reach {
        return None;
    }
    let start = unit(&d).unwrap_or_else(V3::z);
    let centre = Centre(*center);
    let mut cso = Cso::new(a, &centre, &start);
    let tiny = TOUCHING * reach;
    match distance(&mut cso, &start, radius, tiny) {
        Distance::Beyond => None,
        Distance::Near(v) => {
            // v = (nearest point of A) − c, so the normal from A into the sphere is −v/|v|.
            let g = v.norm();
            let normal = -v / g;
            let depth = radius - g;
            // Midway between A's nearest point c − g n and the sphere's deepest point c − r n.
            (depth > 0.0).then(|| ContactGeometry { point: center - normal * (0.5 * (g + radius)), normal, depth })
        }
        Distance::Inside => {
            let local = a.rotation.tr_mul(&d);
            let (g, t) = a
                .shape
                .normals
                .iter()
                .zip(&a.shape.triangles)
                .enumerate()
                .map(|(t, (n, tri))| (n.dot(&(a.shape.vertices[tri[0] as usize] - local)), t))
                .min_by(|p, q| p.0.total_cmp(&q.0))
                .expect("a polyhedron has faces");
            let normal = a.rotation * a.shape.normals[t];
            // Midway between the face point c + g n and the sphere's deepest point c − r n.
            Some(ContactGeometry { point: center + normal * (0.5 * (g - radius)), normal, depth: radius + g })
        }
    }
}

/// Contact of a polyhedron (body A) with the plane through `plane_point` whose unit normal
/// `plane_normal` points into the domain (body B is the wall behind it); the normal returned
/// points into the wall. Exact; the point is the centroid of the part beyond the plane, at
/// half the depth.
pub fn polyhedron_plane(a: &PolyhedronPose, plane_point: &V3, plane_normal: &V3) -> Option<ContactGeometry> {
    let n = -plane_normal;
    let level = n.dot(&(plane_point - a.center));
    if level >= a.shape.bounding_radius {
        return None;
    }
    let mut hint = a.cold_hint(&n);
    let top = n.dot(&a.reach(&n, &mut hint));
    let depth = top - level;
    (depth > 0.0).then(|| against_plane(a, &n, level, depth))
}

/// Contact of a polyhedron (body A) inside a vertical cylinder wall (body B) of the given axis
/// and radius, or `None` while the grain lies wholly inside.
///
/// The deepest point is the vertex farthest from the axis (a convex function is largest at a
/// vertex; all vertices are scanned, so it is exact); depth = its distance from the axis minus
/// the radius, normal = radially outward through it. The point is that of a plane contact with
/// the wall's tangent plane there, which differs from the curved wall by the sag
/// (grain width)²/(8 radius) across the contact.
pub fn polyhedron_cylinder_wall(a: &PolyhedronPose, axis_x: f64, axis_y: f64, radius: f64) -> Option<ContactGeometry> {
    let offset = V2::new(a.center.x - axis_x, a.center.y - axis_y);
    if offset.norm() + a.shape.bounding_radius <= radius {
        return None;
    }
    let rows = a.rotation.fixed_rows::<2>(0).into_owned();
    let (far, farthest) = a
        .shape
        .vertices
        .iter()
        .map(|v| {
            let h = offset + rows * v;
            (h.norm_squared(), h)
        })
        .max_by(|p, q| p.0.total_cmp(&q.0))
        .expect("a polyhedron has vertices");
    let distance = far.sqrt();
    let depth = distance - radius;
    if depth <= 0.0 {
        return None;
    }
    let out = farthest / distance;
    let n = V3::new(out.x, out.y, 0.0);
    // The tangent plane's level along n, measured from the centre.
    let level = radius - offset.dot(&out);
    Some(against_plane(a, &n, level, depth))
}

/// Contact with the half-space {n·(x − x_A) ≥ level} that A enters by `depth`.
fn against_plane(a: &PolyhedronPose, n: &V3, level: f64, depth: f64) -> ContactGeometry {
    let frame = Frame::new(n);
    let mut hint = a.cold_hint(n);
    let deepest = a.reach(n, &mut hint);
    // Frame coordinates from the deepest point's foot on the plane: the plane is z = 0 there,
    // and the cut face lying in it adds nothing to the integrals (x·n = 0 and n_t1 = n_t2 = 0).
    let foot = deepest - n * (n.dot(&deepest) - level);
    let centroid = SLABS.with_borrow_mut(|slabs| {
        let slab = &mut slabs[0];
        slab.gather(a, &frame.coordinates(&-foot), &frame, 1.0, 0.0)?;
        let mut integrals = Integrals::default();
        slab.beyond(0.0, &mut integrals)?;
        integrals.centroid()
    });
    let offset = centroid.map_or(V3::zeros(), |c| frame.world(&V3::new(c.x, c.y, 0.0)));
    let point = a.center + foot + n * (0.5 * depth) + offset;
    ContactGeometry { point, normal: *n, depth }
}

/// The end of EPA: normal from A into B, depth, and the deepest points of A and of B (relative
/// to A's centre; a − b = depth · normal).
struct Penetration {
    normal: V3,
    depth: f64,
    a: V3,
    b: V3,
    /// A's vertices at the corners of EPA's last face.
    vertices: [u32; 3],
}

/// GJK, then EPA: the minimum translational distance of two convex bodies, or `None` if they
/// do not overlap.
fn penetration<A: Convex, B: Convex>(
    a: &A,
    b: &B,
    warm_normal: Option<&V3>,
    gap: f64,
    stats: &mut PolyhedronStats,
) -> Option<Penetration> {
    let d = b.center() - a.center();
    let reach = a.bounding_radius() + b.bounding_radius();
    if d.norm_squared() >= reach * reach {
        return None;
    }
    let start = warm_normal.and_then(unit).or_else(|| unit(&d)).unwrap_or_else(V3::z);
    let mut cso = Cso::new(a, b, &start);
    let tiny = TOUCHING * reach;
    let simplex = overlap(&mut cso, &start, tiny, stats).and_then(|s| complete(&mut cso, s, tiny));
    let end = simplex.and_then(|s| {
        EPA.with_borrow_mut(|polytope| polytope.run(&mut cso, &s, gap * reach, VISIBLE * reach, tiny, stats))
    });
    stats.support_queries = cso.queries;
    end.filter(|e| e.depth > 0.0)
}

// ---------------------------------------------------------------------------------------------
// GJK

/// Up to four points of K.
#[derive(Debug, Clone, Copy, Default)]
struct Simplex {
    p: [Point; 4],
    len: usize,
}

impl Simplex {
    fn push(&mut self, p: Point) {
        self.p[self.len] = p;
        self.len += 1;
    }

    /// Keeps the smallest sub-simplex whose hull holds the point of the hull nearest the
    /// origin, and returns that point (signed-volume sub-algorithm).
    fn reduce(&mut self) -> V3 {
        let w = [self.p[0].w, self.p[1].w, self.p[2].w, self.p[3].w];
        let (v, keep) = match self.len {
            1 => (w[0], 0b1),
            2 => nearest_on_segment(&w, 0, 1),
            3 => nearest_on_triangle(&w, 0, 1, 2),
            _ => nearest_on_tetrahedron(&w),
        };
        let mut kept = 0;
        for i in 0..self.len {
            if keep & (1 << i) != 0 {
                self.p[kept] = self.p[i];
                kept += 1;
            }
        }
        self.len = kept;
        v
    }
}

fn nearest_on_segment(w: &[V3; 4], i: usize, j: usize) -> (V3, u8) {
    let (p, q) = (w[i], w[j]);
    let t = q - p;
    let tt = t.norm_squared();
    let s = if tt > 0.0 { -p.dot(&t) / tt } else { 0.0 };
    if s <= 0.0 {
        (p, 1 << i)
    } else if s >= 1.0 {
        (q, 1 << j)
    } else {
        (p + t * s, 1 << i | 1 << j)
    }
}

fn nearest_on_triangle(w: &[V3; 4], i: usize, j: usize, k: usize) -> (V3, u8) {
    let (p, q, r) = (w[i], w[j], w[k]);
    let n = (q - p).cross(&(r - p));
    let nn = n.norm_squared();
    // Barycentric coordinates of the origin's projection, as signed areas (the projection is
    // along n, so the origin can stand in for it).
    let lambda = [q.cross(&r).dot(&n), r.cross(&p).dot(&n), p.cross(&q).dot(&n)];
    if nn > 0.0 && lambda.iter().all(|&l| l > 0.0) {
        return (n * (p.dot(&n) / nn), 1 << i | 1 << j | 1 << k);
    }
    // Otherwise the nearest point lies on an edge opposite a non-positive coordinate.
    let edges = [(j, k), (k, i), (i, j)];
    let mut best: Option<(V3, u8)> = None;
    for (e, &(s, t)) in edges.iter().enumerate() {
        if nn > 0.0 && lambda[e] > 0.0 {
            continue;
        }
        let candidate = nearest_on_segment(w, s, t);
        if best.is_none_or(|b| candidate.0.norm_squared() < b.0.norm_squared()) {
            best = Some(candidate);
        }
    }
    best.expect("a triangle has a non-positive barycentric coordinate unless its interior holds the projection")
}

fn nearest_on_tetrahedron(w: &[V3; 4]) -> (V3, u8) {
    let volume = |a: &V3, b: &V3, c: &V3, d: &V3| (b - a).dot(&(c - a).cross(&(d - a)));
    let o = V3::zeros();
    let det = volume(&w[0], &w[1], &w[2], &w[3]);
    // Volumes with vertex i replaced by the origin: the barycentric coordinates times det.
    let lambda = [
        volume(&o, &w[1], &w[2], &w[3]),
        volume(&w[0], &o, &w[2], &w[3]),
        volume(&w[0], &w[1], &o, &w[3]),
        volume(&w[0], &w[1], &w[2], &o),
    ];
    if det != 0.0 && lambda.iter().all(|&l| l * det >= 0.0) {
        return (V3::zeros(), 0b1111);
    }
    let faces = [(1, 2, 3), (0, 2, 3), (0, 1, 3), (0, 1, 2)];
    let mut best: Option<(V3, u8)> = None;
    for (i, &(p, q, r)) in faces.iter().enumerate() {
        if det != 0.0 && lambda[i] * det >= 0.0 {
            continue;
        }
        let candidate = nearest_on_triangle(w, p, q, r);
        if best.is_none_or(|b| candidate.0.norm_squared() < b.0.norm_squared()) {
            best = Some(candidate);
        }
    }
    best.expect("the origin is outside some face unless the tetrahedron holds it")
}

/// GJK as an overlap test: a simplex of K holding the origin (up to `tiny`), or `None` once a
/// direction separates K from the origin (touching counts as separated: depth ≤ 0).
fn overlap<A: Convex, B: Convex>(
    cso: &mut Cso<A, B>,
    start: &V3,
    tiny: f64,
    stats: &mut PolyhedronStats,
) -> Option<Simplex> {
    // Start from three support points around `start` and the far side of K. When `start` is
    // close to the contact normal (a persisting contact, or the centre line of a shallow one)
    // the three usually span the face of K nearest the origin and the tetrahedron already holds
    // the origin; otherwise GJK goes on from its nearest point. Each of the three also tests
    // its direction for separation, so a pair that has just parted costs one support query.
    let (t1, t2) = tangent_basis(start);
    let mut simplex = Simplex::default();
    for (c, s) in [(1.0, 0.0), (-0.5, HALF_SQRT_3), (-0.5, -HALF_SQRT_3)] {
        let u = start + (t1 * c + t2 * s) * TILT;
        let w = cso.support(&u);
        if u.dot(&w.w) < 0.0 {
            return None;
        }
        simplex.push(w);
    }
    simplex.push(cso.support(&-start));
    let mut v = simplex.reduce();
    for _ in 0..GJK_ITERATIONS {
        stats.gjk_iterations += 1;
        if simplex.len == 4 || v.norm_squared() <= tiny * tiny {
            return Some(simplex);
        }
        let w = cso.support(&-v);
        // min over K of v·x is v·w: if it is not negative, the plane v·x = 0 separates.
        if v.dot(&w.w) >= 0.0 {
            return None;
        }
        simplex.push(w);
        v = simplex.reduce();
    }
    None
}

/// Completes a simplex holding the origin to a tetrahedron for EPA by support points off its
/// span, or `None` if K has none there: then K lies on one side of a plane through the origin,
/// which is on ∂K (depth 0).
fn complete<A: Convex, B: Convex>(cso: &mut Cso<A, B>, mut simplex: Simplex, tiny: f64) -> Option<Simplex> {
    while simplex.len < 4 {
        let off = match simplex.len {
            1 => return None,
            2 => tangent_basis(&unit(&(simplex.p[1].w - simplex.p[0].w))?).0,
            _ => unit(&(simplex.p[1].w - simplex.p[0].w).cross(&(simplex.p[2].w - simplex.p[0].w)))?,
        };
        let w = cso.support(&off);
        if off.dot(&(w.w - simplex.p[0].w)) <= tiny {
            return None;
        }
        simplex.push(w);
    }
    Some(simplex)
}

/// Result of a GJK distance query from the origin to K.
enum Distance {
    /// K is farther than the bound.
    Beyond,
    /// The point of K nearest the origin.
    Near(V3),
    /// The origin lies in K (or within rounding of it).
    Inside,
}

/// GJK distance from the origin to K, stopping early once K is known to be farther than `bound`.
fn distance<A: Convex, B: Convex>(cso: &mut Cso<A, B>, start: &V3, bound: f64, tiny: f64) -> Distance {
    let mut simplex = Simplex::default();
    simplex.push(cso.support(start));
    let mut v = simplex.p[0].w;
    for _ in 0..GJK_ITERATIONS {
        let vv = v.norm_squared();
        if vv <= tiny * tiny {
            return Distance::Inside;
        }
        let w = cso.support(&-v);
        let vw = v.dot(&w.w);
        if vw > 0.0 && vw * vw > bound * bound * vv {
            return Distance::Beyond;
        }
        // v·w ≤ dist² ≤ |v|²: once the two agree, v is the nearest point.
        if vv - vw <= DISTANCE_TOLERANCE * vv + tiny * tiny {
            return Distance::Near(v);
        }
        simplex.push(w);
        v = simplex.reduce();
        if simplex.len == 4 {
            return Distance::Inside;
        }
    }
    Distance::Near(v)
}

// ---------------------------------------------------------------------------------------------
// EPA

#[derive(Debug, Clone, Copy, Default)]
struct Face {
    v: [u16; 3],
    /// Face across edge k (from v[k] to v[k + 1]) and that edge's index there.
    adj: [u16; 3],
    edge: [u8; 3],
    normal: V3,
    /// Signed distance of the face's plane from the origin.
    dist: f64,
    live: bool,
    /// Expansion in which the face was found visible.
    pass: u32,
}

/// EPA's polytope, kept per thread so that queries do not allocate.
struct Polytope {
    points: [Point; EPA_VERTICES],
    n_points: usize,
    faces: [Face; EPA_FACES],
    n_faces: usize,
    /// Slots of faces removed in earlier expansions, free for new faces.
    free: [u16; EPA_FACES],
    n_free: usize,
    /// Faces removed in the current expansion (recycled once it is complete).
    removed: [u16; EPA_FACES],
    n_removed: usize,
    pass: u32,
    /// The ring of new faces being built: first, last, count; and whether a new face was
    /// degenerate.
    ring: (u16, u16, usize),
    failed: bool,
}

thread_local! {
    static EPA: RefCell<Box<Polytope>> = RefCell::new(Box::new(Polytope {
        points: [Point::default(); EPA_VERTICES],
        n_points: 0,
        faces: [Face::default(); EPA_FACES],
        n_faces: 0,
        free: [0; EPA_FACES],
        n_free: 0,
        removed: [0; EPA_FACES],
        n_removed: 0,
        pass: 0,
        ring: (0, 0, 0),
        failed: false,
    }));
}

impl Polytope {
    fn run<A: Convex, B: Convex>(
        &mut self,
        cso: &mut Cso<A, B>,
        simplex: &Simplex,
        gap: f64,
        visible: f64,
        tiny: f64,
        stats: &mut PolyhedronStats,
    ) -> Option<Penetration> {
        self.n_points = 0;
        self.n_faces = 0;
        self.n_free = 0;
        self.pass = 0;
        let mut p = simplex.p;
        // Orient the tetrahedron so that the faces below have outward normals.
        if (p[1].w - p[0].w).dot(&(p[2].w - p[0].w).cross(&(p[3].w - p[0].w))) > 0.0 {
            p.swap(1, 2);
        }
        self.points[..4].copy_from_slice(&p);
        self.n_points = 4;
        for v in [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]] {
            self.add_face(v, tiny)?;
        }
        // Link the four faces: the face across edge (a, b) is the one holding (b, a).
        for f in 0..4 {
            for k in 0..3 {
                let (a, b) = (self.faces[f].v[k], self.faces[f].v[(k + 1) % 3]);
                for g in 0..4 {
                    if let Some(e) = (0..3).find(|&e| self.faces[g].v[e] == b && self.faces[g].v[(e + 1) % 3] == a) {
                        self.faces[f].adj[k] = g as u16;
                        self.faces[f].edge[k] = e as u8;
                    }
                }
            }
        }
        loop {
            stats.epa_iterations += 1;
            let best = (0..self.n_faces)
                .filter(|&f| self.faces[f].live)
                .min_by(|&f, &g| self.faces[f].dist.total_cmp(&self.faces[g].dist))
                .expect("the polytope has faces");
            let face = self.faces[best];
            let w = cso.support(&face.normal);
            let converged = face.normal.dot(&w.w) - face.dist <= gap;
            if converged || self.n_points == EPA_VERTICES {
                stats.converged = converged;
                return Some(self.end(&face));
            }
            self.points[self.n_points] = w;
            let new = self.n_points as u16;
            self.n_points += 1;
            self.pass += 1;
            self.faces[best].live = false;
            self.faces[best].pass = self.pass;
            self.removed[0] = best as u16;
            self.n_removed = 1;
            self.ring = (0, 0, 0);
            self.failed = false;
            for k in 0..3 {
                self.silhouette(face.adj[k], face.edge[k], new, visible, tiny);
            }
            if self.failed || self.ring.2 < 3 {
                // A degenerate new face: the polytope can no longer be trusted, the face before
                // the expansion can.
                stats.converged = false;
                return Some(self.end(&face));
            }
            let (first, last, _) = self.ring;
            self.link(last, 1, first, 2);
            self.free[self.n_free..self.n_free + self.n_removed].copy_from_slice(&self.removed[..self.n_removed]);
            self.n_free += self.n_removed;
        }
    }

    /// Walks from a removed face across its edge `e` into face `f`: removes `f` too if the new
    /// point `w` sees it, else makes the edge part of the horizon with a new face on it.
    fn silhouette(&mut self, f: u16, e: u8, w: u16, visible: f64, tiny: f64) {
        let face = self.faces[f as usize];
        if self.failed || face.pass == self.pass {
            return;
        }
        let (e1, e2) = ((e as usize + 1) % 3, (e as usize + 2) % 3);
        if face.normal.dot(&self.points[w as usize].w) - face.dist < -visible {
            let Some(new) = self.add_face([face.v[e1], face.v[e as usize], w], tiny) else {
                self.failed = true;
                return;
            };
            self.link(new, 0, f, e as usize);
            let (first, last, count) = self.ring;
            if count > 0 {
                self.link(last, 1, new, 2);
                self.ring = (first, new, count + 1);
            } else {
                self.ring = (new, new, 1);
            }
        } else {
            self.faces[f as usize].live = false;
            self.faces[f as usize].pass = self.pass;
            self.removed[self.n_removed] = f;
            self.n_removed += 1;
            self.silhouette(face.adj[e1], face.edge[e1], w, visible, tiny);
            self.silhouette(face.adj[e2], face.edge[e2], w, visible, tiny);
        }
    }

    fn link(&mut self, f: u16, e: usize, g: u16, h: usize) {
        self.faces[f as usize].adj[e] = g;
        self.faces[f as usize].edge[e] = h as u8;
        self.faces[g as usize].adj[h] = f;
        self.faces[g as usize].edge[h] = e as u8;
    }

    /// A new face on points `v` (counter-clockwise seen from outside), or `None` if it is
    /// degenerate or there is no room.
    fn add_face(&mut self, v: [u16; 3], tiny: f64) -> Option<u16> {
        let [a, b, c] = v.map(|i| self.points[i as usize].w);
        let cross = (b - a).cross(&(c - a));
        let length = cross.norm();
        if length.is_nan() || length <= tiny * tiny {
            return None;
        }
        let normal = cross / length;
        let slot = if self.n_free > 0 {
            self.n_free -= 1;
            self.free[self.n_free] as usize
        } else if self.n_faces < EPA_FACES {
            self.n_faces += 1;
            self.n_faces - 1
        } else {
            return None;
        };
        self.faces[slot] =
            Face { v, adj: [0; 3], edge: [0; 3], normal, dist: normal.dot(&((a + b + c) / 3.0)), live: true, pass: 0 };
        Some(slot as u16)
    }

    /// Depth, normal and deepest points from the face nearest the origin: the origin's
    /// projection onto it, δ n, in barycentric coordinates of the face's points.
    fn end(&self, face: &Face) -> Penetration {
        let [p, q, r] = face.v.map(|i| self.points[i as usize]);
        let o = face.normal * face.dist;
        let n = &face.normal;
        let lambda = [
            (q.w - o).cross(&(r.w - o)).dot(n).max(0.0),
            (r.w - o).cross(&(p.w - o)).dot(n).max(0.0),
            (p.w - o).cross(&(q.w - o)).dot(n).max(0.0),
        ];
        let sum: f64 = lambda.iter().sum();
        let lambda = if sum > 0.0 { lambda.map(|l| l / sum) } else { [1.0 / 3.0; 3] };
        Penetration {
            normal: face.normal,
            depth: face.dist,
            a: p.a * lambda[0] + q.a * lambda[1] + r.a * lambda[2],
            b: p.b * lambda[0] + q.b * lambda[1] + r.b * lambda[2],
            vertices: [p.vertex, q.vertex, r.vertex],
        }
    }
}

// ---------------------------------------------------------------------------------------------
// Centre of pressure

/// The contact plane's frame: tangents t1, t2 and normal n, right-handed.
struct Frame {
    t1: V3,
    t2: V3,
    n: V3,
}

impl Frame {
    fn new(n: &V3) -> Self {
        let (t1, t2) = tangent_basis(n);
        Self { t1, t2, n: *n }
    }

    /// World vector → frame coordinates (t1, t2, n).
    fn coordinates(&self, x: &V3) -> V3 {
        V3::new(self.t1.dot(x), self.t2.dot(x), self.n.dot(x))
    }

    /// Frame coordinates → world vector.
    fn world(&self, c: &V3) -> V3 {
        self.t1 * c.x + self.t2 * c.y + self.n * c.z
    }
}

/// A triangle of a body's surface in frame coordinates, with its outward unit normal and
/// plane offset (normal · x on the plane).
#[derive(Debug, Clone, Copy, Default)]
struct Facet {
    p: [V3; 3],
    normal: V3,
    offset: f64,
}

/// The triangles of one body that meet the slab where the two bodies can overlap.
struct Slab {
    facets: [Facet; CAP_TRIANGLES],
    len: usize,
    /// Tangential bounding box of the facets, which holds the projection of the body's part
    /// inside the slab.
    lo: V2,
    hi: V2,
}

thread_local! {
    /// The two bodies' slabs, kept per thread so that queries neither allocate nor clear them.
    static SLABS: RefCell<Box<[Slab; 2]>> = RefCell::new(Box::new(std::array::from_fn(|_| Slab {
        facets: [Facet::default(); CAP_TRIANGLES],
        len: 0,
        lo: V2::zeros(),
        hi: V2::zeros(),
    })));
}

impl Slab {
    /// Triangles of `pose` with a vertex beyond `level` on `side` (heights along n; frame
    /// coordinates relative to an origin from which the pose's centre lies at `shift`), found
    /// by walking the vertex graph from the vertex farthest towards `side` through the vertices
    /// beyond `level` (a connected set on a convex polyhedron). `None` if they do not fit.
    fn gather(&mut self, pose: &PolyhedronPose, shift: &V3, frame: &Frame, side: f64, level: f64) -> Option<()> {
        let shape = pose.shape;
        let axes = [frame.t1, frame.t2, frame.n].map(|a| pose.rotation.tr_mul(&a));
        let at = |v: u32| {
            let x = &shape.vertices[v as usize];
            V3::new(axes[0].dot(x), axes[1].dot(x), axes[2].dot(x)) + shift
        };
        let beyond = |v: u32| side * (at(v).z - level) > 0.0;
        let slab = self;
        slab.len = 0;
        slab.lo = V2::repeat(f64::INFINITY);
        slab.hi = V2::repeat(f64::NEG_INFINITY);
        let top = shape.climb(&(axes[2] * side), shape.start(&(axes[2] * side)));
        if !beyond(top) {
            return Some(());
        }
        let mut seen = [0u32; CAP_VERTICES];
        let mut n_seen = 1;
        seen[0] = top;
        let mut taken = [0u32; CAP_TRIANGLES];
        let mut next = 0;
        while next < n_seen {
            let v = seen[next];
            next += 1;
            for &t in shape.incident_to(v) {
                if taken[..slab.len].contains(&t) {
                    continue;
                }
                if slab.len == CAP_TRIANGLES {
                    return None;
                }
                let p = shape.triangles[t as usize].map(at);
                let normal = V3::new(
                    axes[0].dot(&shape.normals[t as usize]),
                    axes[1].dot(&shape.normals[t as usize]),
                    axes[2].dot(&shape.normals[t as usize]),
                );
                taken[slab.len] = t;
                for corner in &p {
                    slab.lo = slab.lo.inf(&corner.xy());
                    slab.hi = slab.hi.sup(&corner.xy());
                }
                slab.facets[slab.len] = Facet { p, normal, offset: normal.dot(&p[0]) };
                slab.len += 1;
            }
            for &w in shape.neighbours_of(v) {
                if beyond(w) && !seen[..n_seen].contains(&w) {
                    if n_seen == CAP_VERTICES {
                        return None;
                    }
                    seen[n_seen] = w;
                    n_seen += 1;
                }
            }
        }
        Some(())
    }

    /// Adds the parts of these facets that lie inside all of `other`'s facet planes.
    fn clipped_by(&self, other: &Slab, integrals: &mut Integrals) -> Option<()> {
        let mut polygon = Polygon::new();
        for facet in &self.facets[..self.len] {
            // A facet whose projection misses the other body's part in the slab is outside it.
            let [p, q, r] = facet.p.map(|c| c.xy());
            let (lo, hi) = (p.inf(&q).inf(&r), p.sup(&q).sup(&r));
            if lo.x > other.hi.x || lo.y > other.hi.y || hi.x < other.lo.x || hi.y < other.lo.y {
                continue;
            }
            polygon.reset(&facet.p);
            for plane in &other.facets[..other.len] {
                polygon.clip(|x| plane.offset - plane.normal.dot(x))?;
            }
            integrals.add(&polygon, &facet.normal);
        }
        Some(())
    }

    /// Adds the parts of these facets beyond the plane z = `level`.
    fn beyond(&self, level: f64, integrals: &mut Integrals) -> Option<()> {
        let mut polygon = Polygon::new();
        for facet in &self.facets[..self.len] {
            polygon.reset(&facet.p);
            polygon.clip(|x| x.z - level)?;
            integrals.add(&polygon, &facet.normal);
        }
        Some(())
    }
}

/// Most corners a clipped facet may have.
const POLYGON_CORNERS: usize = 24;

/// A convex planar polygon being clipped, in two buffers that take turns as source and
/// destination (no copying).
struct Polygon {
    p: [[V3; POLYGON_CORNERS]; 2],
    current: usize,
    len: usize,
}

impl Polygon {
    fn new() -> Self {
        Self { p: [[V3::zeros(); POLYGON_CORNERS]; 2], current: 0, len: 0 }
    }

    /// Starts over from a triangle (the buffers are reused from facet to facet).
    fn reset(&mut self, p: &[V3; 3]) {
        self.p[0][..3].copy_from_slice(p);
        self.current = 0;
        self.len = 3;
    }

    fn corners(&self) -> &[V3] {
        &self.p[self.current][..self.len]
    }

    /// Keeps the part where the affine function `f` is non-negative (Sutherland–Hodgman);
    /// `None` if the result would not fit.
    fn clip(&mut self, f: impl Fn(&V3) -> f64) -> Option<()> {
        // Most planes leave the polygon whole (or remove it): decide that first, without
        // storing the values.
        let (mut inside, mut outside) = (false, false);
        for p in self.corners() {
            if f(p) >= 0.0 {
                inside = true;
            } else {
                outside = true;
            }
        }
        if !outside {
            return Some(());
        }
        if !inside {
            self.len = 0;
            return Some(());
        }
        let [first, second] = &mut self.p;
        let (old, new) = if self.current == 0 { (&*first, second) } else { (&*second, first) };
        let mut len = 0;
        let mut fi = f(&old[0]);
        for i in 0..self.len {
            let j = (i + 1) % self.len;
            let fj = f(&old[j]);
            if fi >= 0.0 {
                new[len] = old[i];
                len += 1;
            }
            if (fi >= 0.0) != (fj >= 0.0) {
                if len == POLYGON_CORNERS {
                    return None;
                }
                new[len] = old[i] + (old[j] - old[i]) * (fi / (fi - fj));
                len += 1;
            }
            fi = fj;
        }
        self.current = 1 - self.current;
        self.len = len;
        Some(())
    }
}

/// Volume and tangential first moments of a closed region from its boundary, by the divergence
/// theorem: V = ∮ x·n dS / 3 and ∫ x_i dV = ∮ x_i² n_i dS / 2.
#[derive(Default)]
struct Integrals {
    volume: f64,
    first: V2,
}

impl Integrals {
    /// Adds a planar boundary piece with outward unit normal `normal`, fanned from its first
    /// corner; on a triangle (a, b, c) of area A, ∫ x_i² = A (a_i² + b_i² + c_i² + a_i b_i +
    /// b_i c_i + c_i a_i) / 6.
    fn add(&mut self, polygon: &Polygon, normal: &V3) {
        let p = polygon.corners();
        for i in 1..p.len().saturating_sub(1) {
            let (a, b, c) = (p[0], p[i], p[i + 1]);
            let area = 0.5 * (b - a).cross(&(c - a)).dot(normal);
            self.volume += area * normal.dot(&(a + b + c)) / 9.0;
            let square = |k: usize| a[k] * a[k] + b[k] * b[k] + c[k] * c[k] + a[k] * b[k] + b[k] * c[k] + c[k] * a[k];
            self.first += V2::new(normal.x * square(0), normal.y * square(1)) * (area / 12.0);
        }
    }

    fn centroid(&self) -> Option<V2> {
        (self.volume > 0.0 && self.volume.is_finite()).then(|| self.first / self.volume)
    }
}
