//! Contact geometry of convex polyhedra (grains from meshes) with each other, with spheres and
//! ellipsoids, with the floor and with the cylinder wall (§3.1).
//!
//! # Depth and normal: GJK + EPA
//! As in the paper's software, the depth is the minimum translational distance and comes from
//! GJK + EPA on support functions ([`super::gjk`], [`super::epa`], [`super::support`]). With
//! K = A − B the Minkowski difference, the bodies overlap iff the origin lies in K, and the depth
//! is the origin's distance to ∂K; the closest boundary point is δ n with n the normal from A
//! into B (the same δ = min over unit n of h_A(n) + h_B(−n) − n·(x_B − x_A) as in the ellipsoid
//! module). For two polyhedra EPA ends on a true face of K: depth and normal are exact to
//! rounding. The contact point is the centroid of the overlap ([`super::centre_of_pressure`]).
//!
//! A pair in contact keeps the vertices of EPA's last face ([`super::coherence`]): the next
//! step starts EPA from the tetrahedron they make with a far point of K, skipping GJK, and a
//! contact whose features did not change is confirmed by one support query.
//!
//! # Accuracy (tests/contact_polyhedron.rs)
//! * polyhedron–polyhedron and –plane: exact to rounding, against a brute-force separating-axis
//!   reference (depth, normal) and an independently built overlap centroid (point).
//! * polyhedron–sphere: exact (the sphere is its centre grown by its radius; the centre's
//!   distance to the polyhedron comes from GJK, or from the nearest face plane when inside).
//! * polyhedron–cylinder wall: the depth is the excess of the grain's farthest point from the axis
//!   (a scan of the vertices, so exact); it is the minimum translational distance up to a
//!   relative O((grain width / wall radius)²).
//! * polyhedron–ellipsoid: K has curved patches, where EPA converges only in the limit; it stops
//!   at a support gap of 1e-10 of the pair's size (normal then within ~1e-5). The answer is then
//!   polished by Newton on the feature of A that EPA ended on (vertex, edge or face), where the
//!   depth function is smooth, and the polish is kept only if it stays on that feature and in
//!   EPA's bracket. Overlaps deeper than the ellipsoid's smallest radius of curvature keep EPA's
//!   answer.
//!
//! # Symmetry
//! Polyhedron pairs are put in a canonical order (by centre, then orientation) before solving,
//! so that swapping A and B gives bit-for-bit the same point and depth and the negated normal.

use nalgebra::{Matrix3, Vector2, Vector3};

use super::centre_of_pressure::{self, Overlap};
use super::coherence::{Features, Kept, Order};
use super::ellipsoid::{EllipsoidPose, tangent_basis, unit};
use super::epa::{self, Penetration};
use super::gjk::{self, Distance, Simplex};
use super::manifold::{self, Manifold};
pub use super::support::PolyhedronPose;
use super::support::{Centre, Convex, Cso, Point};
use super::{ContactGeometry, ContactPoint};

type V3 = Vector3<f64>;
type V2 = Vector2<f64>;

/// Newton iterations of the polyhedron–ellipsoid polish, and the step (radians) that ends it.
const POLISH_ITERATIONS: u32 = 16;
const POLISH_STEP: f64 = 1e-12;
/// Relative to the pair's size (sum of bounding radii): distances below this count as zero
/// (the origin on a simplex, or on ∂K: touching bodies).
const TOUCHING: f64 = 1e-13;
/// A pair found apart is taken to be still apart, without a new GJK distance query, while the
/// bound along its last separating direction keeps this fraction of the last bound.
const KEPT_GAP: f64 = 0.5;
/// EPA stops when the support point along the nearest face's normal lies within this (relative)
/// distance of that face: rounding for polyhedra...
const GAP_POLYTOPE: f64 = 1e-12;
/// ...and for curved bodies, where EPA converges only in the limit: close enough for the Newton
/// polish to start in its quadratic regime.
const GAP_SMOOTH: f64 = 1e-10;
/// A face counts as seen from a new EPA vertex unless the vertex lies this far behind its plane,
/// so that (nearly) coplanar faces merge instead of leaving slivers.
const VISIBLE: f64 = 1e-13;

/// How one polyhedron query was answered, for diagnostics, tests and benchmarks.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct PolyhedronStats {
    pub gjk_iterations: u32,
    pub epa_iterations: u32,
    /// Support queries on K (each is one query per body).
    pub support_queries: u32,
    /// EPA met its gap tolerance (false only if its polytope filled up or degenerated).
    pub converged: bool,
    /// EPA started from the last step's features, without GJK.
    pub warm_features: bool,
    /// How the contact point was found (None: no contact).
    pub overlap: Option<Overlap>,
}

impl PolyhedronStats {
    /// The point is the overlap's centre of pressure (false: the EPA witness midpoint).
    pub fn centre_of_pressure(&self) -> bool {
        matches!(self.overlap, Some(Overlap::Pyramid | Overlap::Tetrahedron | Overlap::Clipped))
    }
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
    let mut features = Features::default();
    let (contact, _, stats) =
        polyhedron_polyhedron_coherent(a, b, warm_normal, 0.0, &mut features, Mode::Full, ContactPoint::default());
    (contact, stats)
}

/// Which shortcuts a query may take: the engine's (features from the last step, the closed
/// forms of the centre of pressure) or none, to check them against.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Mode {
    Coherent,
    Full,
}

/// Contact of two polyhedra with frame coherence: `features` carries the last contact's
/// features in and this one's out ([`super::coherence`]). Also returns, for a pair found apart,
/// a lower bound on their distance (0 when touching or unknown), with the separating direction
/// left in place of the contact normal as the next warm start. `last_gap` is the bound the last
/// query found, with `warm_normal` its direction (0 if the pair was touching or is new). `rule`
/// says where the force acts: the centre of pressure, or EPA's witness midpoint.
pub fn polyhedron_polyhedron_coherent(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    warm_normal: Option<&V3>,
    last_gap: f64,
    features: &mut Features,
    mode: Mode,
    rule: ContactPoint,
) -> (Option<ContactGeometry>, Apart, PolyhedronStats) {
    let forward = canonical(a, b);
    let (order, first, second) = if forward { (Order::Forward, a, b) } else { (Order::Swapped, b, a) };
    let warm = warm_normal.map(|n| if forward { *n } else { -n });
    let cached = (mode == Mode::Coherent && features.order == order).then_some(features.kept);
    let (contact, apart, stats, kept) = solve_polyhedra(first, second, warm.as_ref(), last_gap, cached, mode, rule);
    *features = match kept {
        Kept::None => Features::default(),
        kept => Features { kept, order },
    };
    let flip = |c: ContactGeometry| if forward { c } else { ContactGeometry { normal: -c.normal, ..c } };
    let apart = Apart { direction: if forward { apart.direction } else { -apart.direction }, ..apart };
    (contact.map(flip), apart, stats)
}

/// Two bodies found apart: a lower bound on their distance and its direction from the first
/// body towards the second (zero when unknown).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Apart {
    pub gap: f64,
    pub direction: V3,
}

/// Whether (a, b) is the canonical order of the pair: by centre, then by orientation. Identical
/// poses of identical shapes are one body twice, where any normal is as good as its opposite.
fn canonical(a: &PolyhedronPose, b: &PolyhedronPose) -> bool {
    let keys = a.center().iter().zip(b.center().iter()).chain(a.map().iter().zip(b.map().iter()));
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
    last_gap: f64,
    cached: Option<Kept>,
    mode: Mode,
    rule: ContactPoint,
) -> (Option<ContactGeometry>, Apart, PolyhedronStats, Kept) {
    let mut stats = PolyhedronStats::default();
    let d = *b.center() - *a.center();
    let reach = a.bounding_radius() + b.bounding_radius();
    let distance = d.norm();
    if distance >= reach {
        return (None, Apart { gap: distance - reach, direction: d / distance }, stats, Kept::None);
    }
    let tiny = TOUCHING * reach;
    let (polytope_gap, visible) = (GAP_POLYTOPE * reach, VISIBLE * reach);
    let warm = warm_normal.and_then(unit);
    let start = warm.or_else(|| unit(&d)).unwrap_or_else(V3::z);
    let mut far = None;
    let mut end = None;
    let from_features = match cached {
        Some(Kept::Contact { a: fa, b: fb }) => Some(warm_tetrahedron(a, b, &d, &fa, &fb)),
        _ => None,
    };
    let mut cso = match from_features {
        Some((tetrahedron, apex)) => {
            let p = &tetrahedron[0];
            let mut cso = Cso::warm(a, b, &start, p.vertex_a, p.vertex_b);
            // A confirmed face has the origin strictly inside all four faces of the tetrahedron;
            // only the expansion needs that checked.
            end = epa::confirm(&mut cso, &tetrahedron, polytope_gap, tiny);
            if end.is_none() && holds_origin(&tetrahedron) {
                end = epa::expand(&mut cso, &tetrahedron, polytope_gap, visible, tiny, &mut stats.epa_iterations);
            }
            if end.is_some() {
                stats.warm_features = true;
                stats.epa_iterations = stats.epa_iterations.max(1);
                far = Some(apex);
            }
            cso
        }
        None => {
            let mut cso = match cached {
                Some(Kept::Apart { a: fa, b: fb, .. }) => Cso::warm(a, b, &start, u32::from(fa[0]), u32::from(fb[0])),
                _ => Cso::new(a, b, &start),
            };
            if mode == Mode::Coherent && last_gap > 0.0 && warm.is_some() {
                // n·d − h_A(n) − h_B(−n) = −h_K(n) bounds the distance for any unit n; along the
                // last separating direction it stays close to the distance while the pair moves
                // little, so a pair that is still clearly apart costs this one query, and one
                // still apart along it needs no overlap test before its distance is sought.
                // Kept along it, the pair keeps its last feature of K for GJK's next start.
                let first = cso.support(&start);
                let gap = -start.dot(&first.w);
                let apart = if gap >= KEPT_GAP * last_gap {
                    let kept = match cached {
                        Some(kept @ Kept::Apart { .. }) => kept,
                        _ => kept_apart(&[first]),
                    };
                    Some((Apart { gap, direction: start }, kept))
                } else {
                    (gap > tiny).then(|| separation_again(&mut cso, &start, first, cached, tiny))
                };
                if let Some((apart, kept)) = apart {
                    stats.support_queries = cso.queries;
                    return (None, apart, stats, kept);
                }
            }
            cso
        }
    };
    if end.is_none() {
        end = match gjk::overlap(&mut cso, &start, tiny, &mut stats.gjk_iterations) {
            Ok(simplex) => gjk::complete(&mut cso, simplex, tiny)
                .and_then(|s| epa::expand(&mut cso, &s.p, polytope_gap, visible, tiny, &mut stats.epa_iterations)),
            Err(u) => {
                let (apart, kept) = if mode == Mode::Coherent && u != V3::zeros() {
                    found_apart(&gjk::separation(&mut cso, &u, tiny))
                } else {
                    (Apart { gap: 0.0, direction: u }, Kept::None)
                };
                stats.support_queries = cso.queries;
                return (None, apart, stats, kept);
            }
        };
    }
    stats.converged = end.is_some_and(|e| e.converged);
    let Some(end) = end.as_ref().filter(|e| e.depth > 0.0) else {
        stats.support_queries = cso.queries;
        return (None, Apart::default(), stats, Kept::None);
    };
    let apex = far.unwrap_or_else(|| {
        let p = cso.support(&-end.normal);
        (p.vertex_a, p.vertex_b)
    });
    stats.support_queries = cso.queries;
    let (point, overlap) = match rule {
        ContactPoint::CentreOfPressure => centre_of_pressure::contact_point(a, b, end, mode == Mode::Coherent),
        ContactPoint::Witness => (end.witness(), Overlap::Witness),
    };
    stats.overlap = Some(overlap);
    let kept = features_of(end, apex);
    (
        Some(ContactGeometry { point: a.center() + point, normal: end.normal, depth: end.depth }),
        Apart::default(),
        stats,
        kept,
    )
}

/// The vertices to keep of EPA's last face and a far point of K, if they fit in 16 bits.
fn features_of(end: &Penetration, apex: (u32, u32)) -> Kept {
    let a = [end.face[0].vertex_a, end.face[1].vertex_a, end.face[2].vertex_a, apex.0];
    let b = [end.face[0].vertex_b, end.face[1].vertex_b, end.face[2].vertex_b, apex.1];
    let narrow = |v: [u32; 4]| -> Option<[u16; 4]> {
        let mut out = [0u16; 4];
        for (o, x) in out.iter_mut().zip(v) {
            *o = u16::try_from(x).ok()?;
        }
        Some(out)
    };
    match (narrow(a), narrow(b)) {
        (Some(a), Some(b)) => Kept::Contact { a, b },
        _ => Kept::None,
    }
}

/// The distance of a pair found apart again, by GJK from the support point `first` along the
/// last separating direction `start` and from the feature of K the last distance query ended
/// on; with the feature to keep. Out of line: the one-query answer is the common case, and it
/// stays small without GJK's simplices.
#[inline(never)]
fn separation_again(
    cso: &mut Cso<PolyhedronPose, PolyhedronPose>,
    start: &V3,
    first: Point,
    cached: Option<Kept>,
    tiny: f64,
) -> (Apart, Kept) {
    let warm = match cached {
        Some(Kept::Apart { a: fa, b: fb, len }) => warm_simplex(cso.a, cso.b, &cso.d, &fa, &fb, len),
        _ => Simplex::default(),
    };
    found_apart(&gjk::separation_from(cso, start, first, warm.points(), tiny))
}

/// A distance bound GJK found, with the feature of K it ended on to keep.
fn found_apart(s: &gjk::Separation) -> (Apart, Kept) {
    (Apart { gap: s.gap, direction: s.direction }, kept_apart(s.simplex.points()))
}

/// The vertices to keep of the points of K a pair found apart ended on (one to three: the
/// feature of K nearest the origin), if they fit in 16 bits.
fn kept_apart(points: &[Point]) -> Kept {
    let (mut a, mut b) = ([0u16; 3], [0u16; 3]);
    if !(1..=3).contains(&points.len()) {
        return Kept::None;
    }
    for (k, p) in points.iter().enumerate() {
        match (u16::try_from(p.vertex_a), u16::try_from(p.vertex_b)) {
            (Ok(va), Ok(vb)) => (a[k], b[k]) = (va, vb),
            _ => return Kept::None,
        }
    }
    Kept::Apart { a, b, len: points.len() as u8 }
}

/// The point of K of vertex `va` of A and `vb` of B at the current poses (B centred at `d` from A).
#[inline(always)]
fn point_of(a: &PolyhedronPose, b: &PolyhedronPose, d: &V3, va: u16, vb: u16) -> Point {
    let (va, vb) = (u32::from(va), u32::from(vb));
    let (pa, pb) = (a.vertex(va), b.vertex(vb) + d);
    Point { w: pa - pb, a: pa, b: pb, vertex_a: va, vertex_b: vb }
}

/// The points of K at the current poses on the last distance query's feature.
fn warm_simplex(a: &PolyhedronPose, b: &PolyhedronPose, d: &V3, fa: &[u16; 3], fb: &[u16; 3], len: u8) -> Simplex {
    let mut simplex = Simplex::default();
    for k in 0..usize::from(len) {
        simplex.push(point_of(a, b, d, fa[k], fb[k]));
    }
    simplex
}

/// The tetrahedron of K at the current poses on the last step's features, with its far point's
/// vertices.
fn warm_tetrahedron(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    d: &V3,
    fa: &[u16; 4],
    fb: &[u16; 4],
) -> ([Point; 4], (u32, u32)) {
    let p: [Point; 4] = std::array::from_fn(|k| point_of(a, b, d, fa[k], fb[k]));
    (p, (u32::from(fa[3]), u32::from(fb[3])))
}

/// Whether the tetrahedron holds the origin strictly inside (then EPA may start from it).
fn holds_origin(p: &[Point; 4]) -> bool {
    let volume = |a: &V3, b: &V3, c: &V3, d: &V3| (b - a).dot(&(c - a).cross(&(d - a)));
    let whole = volume(&p[0].w, &p[1].w, &p[2].w, &p[3].w);
    // The origin replacing corner k gives a volume of the whole's sign when it lies inside.
    whole != 0.0
        && (0..4).all(|k| {
            let mut corners = [p[0].w, p[1].w, p[2].w, p[3].w];
            corners[k] = V3::zeros();
            volume(&corners[0], &corners[1], &corners[2], &corners[3]) * whole > 0.0
        })
}

/// Contact of a polyhedron (body A) with an ellipsoid (body B), or `None` when they do not
/// overlap: EPA to a support gap of 1e-10 of the pair's size, then Newton on the polyhedron's
/// feature (module docs); the point is the midpoint of the deepest points. For a pair found
/// apart, also a lower bound on the distance.
pub fn polyhedron_ellipsoid(
    a: &PolyhedronPose,
    b: &EllipsoidPose,
    warm_normal: Option<&V3>,
) -> (Option<ContactGeometry>, Apart) {
    let reach = a.bounding_radius() + b.bounding_radius();
    let end = match penetration(a, b, warm_normal, GAP_SMOOTH) {
        Ok(end) => end,
        Err(apart) => return (None, apart),
    };
    let (normal, depth) = polish(a, b, &end, GAP_SMOOTH * reach).unwrap_or((end.normal, end.depth));
    // EPA's witness points are barycentric mixtures of support points that may lie far apart on
    // the curved surface; the ellipsoid's own support point along −n is unique and exact.
    let deepest = b.support(&-normal);
    (Some(ContactGeometry { point: deepest + normal * (0.5 * depth), normal, depth }), Apart::default())
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
    let d = *EllipsoidPose::center(e) - a.center();
    let vertices = end.face.map(|p| p.vertex_a);
    let mut feature = [vertices[0]; 3];
    let mut corners = 1;
    for &v in &vertices[1..] {
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
    let tolerance = TOUCHING * (a.bounding_radius() + e.bounding_radius());
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

/// Contact of a polyhedron (body A) with a sphere (body B), exact, or for a pair apart a lower
/// bound on the distance.
///
/// The sphere is its centre c grown by its radius r, so with g the distance from c to the
/// polyhedron the depth is r − g outside (normal from the nearest point to c) and r + g inside
/// (g to the nearest face plane, normal that face's).
pub fn polyhedron_sphere(a: &PolyhedronPose, center: &V3, radius: f64) -> (Option<ContactGeometry>, Apart) {
    let d = center - a.center();
    let reach = a.bounding_radius() + radius;
    let distance = d.norm();
    if distance >= reach {
        return (None, Apart { gap: distance - reach, direction: d / distance });
    }
    let start = unit(&d).unwrap_or_else(V3::z);
    let centre = Centre(*center);
    let mut cso = Cso::new(a, &centre, &start);
    let tiny = TOUCHING * reach;
    let contact = match gjk::distance(&mut cso, &start, radius, tiny) {
        Distance::Beyond(lower) => return (None, Apart { gap: lower - radius, direction: start }),
        Distance::Near(v) => {
            // v = (nearest point of A) − c, so the normal from A into the sphere is −v/|v|.
            let g = v.norm();
            let normal = -v / g;
            let depth = radius - g;
            if depth <= 0.0 {
                return (None, Apart { gap: -depth, direction: normal });
            }
            // Midway between A's nearest point c − g n and the sphere's deepest point c − r n.
            ContactGeometry { point: center - normal * (0.5 * (g + radius)), normal, depth }
        }
        Distance::Inside => {
            let (g, normal) = (0..a.shape().triangles().len() as u32)
                .map(|t| {
                    let n = a.normal(t);
                    (n.dot(&(a.vertex(a.shape().triangles()[t as usize][0]) - d)), n)
                })
                .min_by(|p, q| p.0.total_cmp(&q.0))
                .expect("a polyhedron has faces");
            // Midway between the face point c + g n and the sphere's deepest point c − r n.
            ContactGeometry { point: center + normal * (0.5 * (g - radius)), normal, depth: radius + g }
        }
    };
    (Some(contact), Apart::default())
}

/// Contact of a polyhedron (body A) with the plane through `plane_point` whose unit normal
/// `plane_normal` points into the domain (body B is the wall behind it); the normal returned
/// points into the wall. Exact; the point is the centroid of the part beyond the plane, at
/// half the depth.
pub fn polyhedron_plane(a: &PolyhedronPose, plane_point: &V3, plane_normal: &V3) -> Option<ContactGeometry> {
    plane_depth(a, plane_point, plane_normal)
        .map(|(n, level, deepest, depth)| plane_contact(a, &n, level, deepest, depth))
}

/// How A enters the wall behind the plane: the normal into the wall, the plane's level along it
/// from A's centre, A's vertex farthest in and its depth; `None` while A lies wholly in front.
fn plane_depth(a: &PolyhedronPose, plane_point: &V3, plane_normal: &V3) -> Option<(V3, f64, u32, f64)> {
    let n = -plane_normal;
    let level = n.dot(&(plane_point - a.center()));
    if level >= a.bounding_radius() {
        return None;
    }
    let mut deepest = a.cold_hint(&n);
    let top = n.dot(&a.reach(&n, &mut deepest));
    let depth = top - level;
    (depth > 0.0).then_some((n, level, deepest, depth))
}

/// Contact of a polyhedron (body A) inside a vertical cylinder wall (body B) of the given axis
/// and radius, or `None` while the grain lies wholly inside.
///
/// The deepest point is the vertex farthest from the axis (a convex function is largest at a
/// vertex; all vertices are scanned, so it is exact, unless a bound from the grain's support
/// along the radial and its bounding sphere shows every vertex inside); depth = its distance
/// from the axis minus the radius, normal = radially outward through it. The point is that of a plane contact with
/// the wall's tangent plane there, which differs from the curved wall by the sag
/// (grain width)²/(8 radius) across the contact.
pub fn polyhedron_cylinder_wall(a: &PolyhedronPose, axis_x: f64, axis_y: f64, radius: f64) -> Option<ContactGeometry> {
    cylinder_depth(a, axis_x, axis_y, radius)
        .map(|(n, level, deepest, depth)| plane_contact(a, &n, level, deepest, depth))
}

/// [`polyhedron_plane`] with the point of the paper's software: A's deepest vertex moved back
/// half the depth towards the plane.
pub fn polyhedron_plane_witness(a: &PolyhedronPose, plane_point: &V3, plane_normal: &V3) -> Option<ContactGeometry> {
    plane_depth(a, plane_point, plane_normal).map(|(n, _, deepest, depth)| witness_contact(a, &n, deepest, depth))
}

/// [`polyhedron_cylinder_wall`] with the point of the paper's software: the vertex farthest
/// from the axis moved back half the depth towards the wall.
pub fn polyhedron_cylinder_wall_witness(
    a: &PolyhedronPose,
    axis_x: f64,
    axis_y: f64,
    radius: f64,
) -> Option<ContactGeometry> {
    cylinder_depth(a, axis_x, axis_y, radius).map(|(n, _, deepest, depth)| witness_contact(a, &n, deepest, depth))
}

/// A's contact with a wall at its vertex `deepest`, `depth` beyond the wall's plane along `n`:
/// midway between that vertex and the plane.
fn witness_contact(a: &PolyhedronPose, n: &V3, deepest: u32, depth: f64) -> ContactGeometry {
    ContactGeometry { point: a.center() + a.vertex(deepest) - n * (0.5 * depth), normal: *n, depth }
}

/// How A enters the cylinder wall: the normal into the wall through A's vertex farthest from the
/// axis, the tangent plane's level along it from A's centre, that vertex and its depth; `None`
/// while A lies wholly inside.
fn cylinder_depth(a: &PolyhedronPose, axis_x: f64, axis_y: f64, radius: f64) -> Option<(V3, f64, u32, f64)> {
    let offset = V2::new(a.center().x - axis_x, a.center().y - axis_y);
    let (o, rho) = (offset.norm(), a.bounding_radius());
    if o + rho <= radius {
        return None;
    }
    // Exact early out, cheaper than the scan: with t = u·h ≤ s (the support along the outward
    // radial u) and |h − offset| ≤ ρ, |h|² ≤ t² + ρ² − (t − o)² = ρ² − o² + 2 t o ≤ ρ² − o² + 2 s o.
    // The margin keeps the answer the scan's where rounding could make a graze count.
    if o > 0.0 {
        let u = V3::new(offset.x / o, offset.y / o, 0.0);
        let mut hint = a.cold_hint(&u);
        let s = o + u.dot(&a.reach(&u, &mut hint));
        if rho * rho - o * o + 2.0 * s * o <= radius * radius * (1.0 - 1e-12) {
            return None;
        }
    }
    let rows = a.map().fixed_rows::<2>(0).into_owned();
    let (far, farthest, deepest) = (0..a.shape().vertices().len() as u32)
        .map(|v| {
            let h = offset + rows * a.shape().vertices()[v as usize];
            (h.norm_squared(), h, v)
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
    Some((n, level, deepest, depth))
}

/// GJK, then EPA: the minimum translational distance of two convex bodies, or, if they do not
/// overlap, a lower bound on their distance.
fn penetration<A: Convex, B: Convex>(a: &A, b: &B, warm_normal: Option<&V3>, gap: f64) -> Result<Penetration, Apart> {
    let d = b.center() - a.center();
    let reach = a.bounding_radius() + b.bounding_radius();
    let distance = d.norm();
    if distance >= reach {
        return Err(Apart { gap: distance - reach, direction: d / distance });
    }
    let start = warm_normal.and_then(unit).or_else(|| unit(&d)).unwrap_or_else(V3::z);
    let mut cso = Cso::new(a, b, &start);
    let tiny = TOUCHING * reach;
    let mut iterations = 0;
    let simplex = match gjk::overlap(&mut cso, &start, tiny, &mut iterations) {
        Ok(simplex) => simplex,
        Err(u) if u == V3::zeros() => return Err(Apart::default()),
        Err(u) => {
            let s = gjk::separation(&mut cso, &u, tiny);
            return Err(Apart { gap: s.gap, direction: s.direction });
        }
    };
    let end = gjk::complete(&mut cso, simplex, tiny)
        .and_then(|s| epa::expand(&mut cso, &s.p, gap * reach, VISIBLE * reach, tiny, &mut iterations));
    end.filter(|e| e.depth > 0.0).ok_or_else(Apart::default)
}

/// [`polyhedron_plane`] as a manifold ([`super::manifold`]): a face lying on the plane spreads
/// the contact over its corners.
pub fn polyhedron_plane_manifold(a: &PolyhedronPose, plane_point: &V3, plane_normal: &V3) -> Option<Manifold> {
    plane_depth(a, plane_point, plane_normal)
        .map(|(n, level, deepest, depth)| manifold_beyond(a, &n, level, deepest, depth))
}

/// [`polyhedron_cylinder_wall`] as a manifold on the wall's tangent plane.
pub fn polyhedron_cylinder_wall_manifold(
    a: &PolyhedronPose,
    axis_x: f64,
    axis_y: f64,
    radius: f64,
) -> Option<Manifold> {
    let (n, level, deepest, depth) = cylinder_depth(a, axis_x, axis_y, radius)?;
    Some(manifold_beyond(a, &n, level, deepest, depth))
}

/// The manifold of A entering the half-space {n·(x − x_A) ≥ level} by `depth`. The footprint
/// is the projection of A's part beyond the plane: the hull of its vertices beyond (walked from
/// `deepest`; they are connected) and of the points where its edges leaving them cross the plane,
/// keyed by vertex and by edge. A crossing within 1e-3 of the grain's size of an end of its edge
/// is that vertex: a face lying flat has its side edges cross the plane right at its corners, and
/// a corner just lifting off stays one point.
fn manifold_beyond(a: &PolyhedronPose, n: &V3, level: f64, deepest: u32, depth: f64) -> Manifold {
    let geometry = plane_contact(a, n, level, deepest, depth);
    let shape = a.shape();
    let hair = 1e-3 * a.bounding_radius();
    let mut beyond = [0u32; 64];
    let mut corners = [(V3::zeros(), 0u64); 64];
    beyond[0] = deepest;
    corners[0] = (a.center() + a.vertex(deepest), u64::from(deepest));
    let (mut n_beyond, mut len, mut next) = (1, 1, 0);
    while next < n_beyond {
        let v = beyond[next];
        next += 1;
        let x = a.vertex(v);
        let hv = n.dot(&x) - level;
        for &w in shape.neighbours_of(v) {
            let y = a.vertex(w);
            let hw = n.dot(&y) - level;
            if hw > 0.0 {
                if !beyond[..n_beyond].contains(&w) {
                    if n_beyond == beyond.len() || len == corners.len() {
                        return Manifold::single(geometry);
                    }
                    beyond[n_beyond] = w;
                    corners[len] = (a.center() + y, u64::from(w));
                    n_beyond += 1;
                    len += 1;
                }
            } else {
                let crossing = x + (y - x) * (hv / (hv - hw));
                // Near either end the crossing is that vertex (a corner just lifting off keeps
                // its key, and with it its history).
                let (point, key) = if (crossing - x).norm() <= hair {
                    continue;
                } else if (crossing - y).norm() <= hair {
                    (y, u64::from(w))
                } else {
                    (crossing, manifold::edge_key(v, w))
                };
                if corners[..len].iter().any(|c| c.1 == key) {
                    continue;
                }
                if len == corners.len() {
                    return Manifold::single(geometry);
                }
                corners[len] = (a.center() + point, key);
                len += 1;
            }
        }
    }
    Manifold::spread(geometry, &corners[..len])
}

/// Contact with the half-space {n·(x − x_A) ≥ level} that A enters by `depth`, its vertex
/// `deepest` farthest in.
fn plane_contact(a: &PolyhedronPose, n: &V3, level: f64, deepest: u32, depth: f64) -> ContactGeometry {
    let point = *a.center() + centre_of_pressure::against_plane(a, n, level, deepest, depth);
    ContactGeometry { point, normal: *n, depth }
}
