//! GJK (Gilbert, Johnson & Keerthi 1988) on the Minkowski difference K = A − B, with the
//! signed-volume sub-algorithm (Montanari et al. 2017): whether two convex bodies overlap (the
//! origin lies in K), a tetrahedron of K around the origin for EPA when they do, and a lower
//! bound on their distance when they do not.
//!
//! The overlap test starts from the tetrahedron of the support points along three directions
//! tilted 3° around the start direction and along its opposite: for a persisting contact
//! (start = last step's normal) the first three usually span the face of K nearest the origin,
//! so the tetrahedron already holds the origin; otherwise GJK goes on from it. A separating
//! direction ends it early (a pair that has just parted costs one support query). When the
//! origin lies on a lower-dimensional simplex (the symmetric cases of hand-built tests) the
//! simplex is completed by support points off its span, or the pair is touching if K has none
//! (depth 0, no contact).

use nalgebra::Vector3;

use super::ellipsoid::{tangent_basis, unit};
use super::support::{Convex, Cso, Point};

type V3 = Vector3<f64>;

/// Tilt of GJK's three starting directions from the start direction (about 3°).
const TILT: f64 = 0.05;
const HALF_SQRT_3: f64 = 0.866_025_403_784_438_6;
/// GJK iterations before the origin is taken to sit on the boundary (depth 0); a polytope pair
/// needs far fewer (each iteration adds a support point strictly closer to the origin).
const GJK_ITERATIONS: u32 = 64;
/// GJK distance queries stop when the gap between the bound from the support point and the
/// simplex's distance is below this fraction of the squared distance.
const DISTANCE_TOLERANCE: f64 = 1e-14;
/// A separation bound within this fraction of the distance is good enough to keep: the pair is
/// looked at again once the bodies may have moved that far.
const SEPARATION_TOLERANCE: f64 = 0.05;

/// Up to four points of K.
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct Simplex {
    pub p: [Point; 4],
    pub len: usize,
}

impl Simplex {
    /// The points it holds.
    pub fn points(&self) -> &[Point] {
        &self.p[..self.len]
    }

    pub fn push(&mut self, p: Point) {
        self.p[self.len] = p;
        self.len += 1;
    }

    /// Keeps the smallest sub-simplex whose hull holds the point of the hull nearest the
    /// origin, and returns that point (signed-volume sub-algorithm).
    pub fn reduce(&mut self) -> V3 {
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

/// GJK as an overlap test: a simplex of K holding the origin (up to `tiny`), or the direction u
/// that separates K from the origin (h_K(u) < 0; zero when the origin lies on ∂K: touching
/// counts as separated, depth ≤ 0).
pub(super) fn overlap<A: Convex, B: Convex>(
    cso: &mut Cso<A, B>,
    start: &V3,
    tiny: f64,
    iterations: &mut u32,
) -> Result<Simplex, V3> {
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
            return Err(u);
        }
        simplex.push(w);
    }
    simplex.push(cso.support(&-start));
    let mut v = simplex.reduce();
    for _ in 0..GJK_ITERATIONS {
        *iterations += 1;
        if simplex.len == 4 || v.norm_squared() <= tiny * tiny {
            return Ok(simplex);
        }
        let w = cso.support(&-v);
        // min over K of v·x is v·w: if it is not negative, the plane v·x = 0 separates.
        if v.dot(&w.w) >= 0.0 {
            return Err(-v);
        }
        simplex.push(w);
        v = simplex.reduce();
    }
    Err(V3::zeros())
}

/// Completes a simplex holding the origin to a tetrahedron for EPA by support points off its
/// span, or `None` if K has none there: then K lies on one side of a plane through the origin,
/// which is on ∂K (depth 0).
pub(super) fn complete<A: Convex, B: Convex>(cso: &mut Cso<A, B>, mut simplex: Simplex, tiny: f64) -> Option<Simplex> {
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
pub(super) enum Distance {
    /// K is farther than the bound: a lower bound on its distance.
    Beyond(f64),
    /// The point of K nearest the origin.
    Near(V3),
    /// The origin lies in K (or within rounding of it).
    Inside,
}

/// GJK distance from the origin to K, stopping early once K is known to be farther than `bound`.
pub(super) fn distance<A: Convex, B: Convex>(cso: &mut Cso<A, B>, start: &V3, bound: f64, tiny: f64) -> Distance {
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
            return Distance::Beyond(vw / vv.sqrt());
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

/// A lower bound on the distance between two bodies known to be apart, with its direction: GJK
/// distance iterations from the separating direction `u` (h_K(u) < 0). For every unit n,
/// n·d − h_A(n) − h_B(−n) = −h_K(n) bounds the distance from below (the slab between the two
/// support planes separates the bodies); the best such bound seen is returned once it is
/// within [`SEPARATION_TOLERANCE`] of the simplex's distance, an upper bound. The direction n
/// points from A towards B.
pub(super) fn separation<A: Convex, B: Convex>(cso: &mut Cso<A, B>, u: &V3, tiny: f64) -> Separation {
    let Some(u) = unit(u) else { return Separation { gap: 0.0, direction: V3::zeros(), simplex: Simplex::default() } };
    let first = cso.support(&u);
    separation_from(cso, &u, first, &[], tiny)
}

/// A lower bound on the distance of two bodies, its direction, and the simplex GJK ended on
/// (the feature of K nearest the origin).
pub(super) struct Separation {
    pub gap: f64,
    pub direction: V3,
    pub simplex: Simplex,
}

/// [`separation`] from the unit direction `u` whose support point `first` is already known,
/// and from `warm`, points of K near the origin (the last query's simplex at the new poses):
/// any points of K bound the distance from above, so GJK may start from them. Out of line, so
/// that its simplices do not weigh on the callers' common paths.
#[inline(never)]
pub(super) fn separation_from<A: Convex, B: Convex>(
    cso: &mut Cso<A, B>,
    u: &V3,
    first: Point,
    warm: &[Point],
    tiny: f64,
) -> Separation {
    let mut best = (-u.dot(&first.w), *u);
    let mut simplex = Simplex::default();
    simplex.push(first);
    for p in warm {
        if !simplex.points().iter().any(|q| (q.vertex_a, q.vertex_b) == (p.vertex_a, p.vertex_b)) {
            simplex.push(*p);
        }
    }
    let mut v = simplex.reduce();
    for _ in 0..GJK_ITERATIONS {
        // Four points hold the origin: impossible for bodies apart along `u`, but for rounding.
        if simplex.len == 4 {
            break;
        }
        let vv = v.norm_squared();
        if vv <= tiny * tiny {
            break;
        }
        let w = cso.support(&-v);
        let length = vv.sqrt();
        let lower = v.dot(&w.w) / length;
        if lower > best.0 {
            best = (lower, -v / length);
        }
        if best.0 >= (1.0 - SEPARATION_TOLERANCE) * length {
            break;
        }
        simplex.push(w);
        v = simplex.reduce();
    }
    Separation { gap: best.0.max(0.0), direction: best.1, simplex }
}
