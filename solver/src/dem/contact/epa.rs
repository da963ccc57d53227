//! EPA (van den Bergen 2001): from a tetrahedron of K = A − B holding the origin, grows the
//! polytope towards ∂K: the face nearest the origin is replaced by the support point along its
//! normal until that point lies on the face's plane. The polytope lies inside K, so once the
//! nearest face is also a supporting plane of K its distance is the depth, exactly: for two
//! polyhedra K is a polytope whose vertices are differences of vertices, so EPA ends on a true
//! face of K after finitely many steps; for curved bodies it converges in the limit and stops at
//! a support gap.

use std::cell::RefCell;

use nalgebra::Vector3;

use super::support::{Convex, Cso, Point};

type V3 = Vector3<f64>;

/// Capacity of EPA's polytope. A shallow contact needs 5–20 vertices.
const EPA_VERTICES: usize = 128;
/// Live faces of a convex polytope with V vertices number 2V − 4; the horizon being replaced adds
/// at most V more before the old faces are recycled.
const EPA_FACES: usize = 3 * EPA_VERTICES;
/// The faces of the starting tetrahedron (outward for a negatively oriented p0 p1 p2 p3), and
/// for each face and edge k (from v[k] to v[k + 1]) the face across it and that edge's index there.
const TETRAHEDRON: [[u16; 3]; 4] = [[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
const TETRAHEDRON_ADJACENT: [[u16; 3]; 4] = [[1, 3, 2], [2, 3, 0], [0, 3, 1], [1, 2, 0]];
const TETRAHEDRON_EDGE: [[u8; 3]; 4] = [[2, 2, 0], [2, 0, 0], [2, 1, 0], [1, 1, 1]];

/// The end of EPA: normal from A into B, depth, the deepest points of A and of B (relative to
/// A's centre; a − b = depth · normal), and the points of K at the corners of the last face,
/// whose vertices name the features in contact.
#[derive(Debug, Clone, Copy)]
pub(super) struct Penetration {
    pub normal: V3,
    pub depth: f64,
    pub a: V3,
    pub b: V3,
    pub face: [Point; 3],
    /// EPA met its gap tolerance (false only if its polytope filled up or degenerated).
    pub converged: bool,
}

impl Penetration {
    /// EPA's witness midpoint (relative to A's centre): δn in signed barycentric coordinates of
    /// the last face, applied to its deepest points of A and of B. Signed, where `a` and `b` clamp
    /// them: EPA may end on either of two coplanar faces (an edge–edge contact's face of K is a
    /// parallelogram, two triangles), and the coordinates on the other one continue the same
    /// affine map, so the witnesses stay on the two edges with a − b = δn.
    pub fn witness(&self) -> V3 {
        let [p, q, r] = self.face;
        let lambda = barycentric(&self.face, &(self.normal * self.depth), &self.normal);
        let sum: f64 = lambda.iter().sum();
        if sum > 0.0 {
            ((p.a + p.b) * lambda[0] + (q.a + q.b) * lambda[1] + (r.a + r.b) * lambda[2]) * (0.5 / sum)
        } else {
            (self.a + self.b) * 0.5
        }
    }
}

/// EPA's first iteration on a tetrahedron whose face (p0, p1, p2) was last step's answer and
/// whose fourth corner lies far on the other side: if the tetrahedron holds the origin, that face
/// is the nearest, and the support point along its normal lies on its plane (within `gap`),
/// EPA would stop right there, and so does this, without building the polytope. `None` when
/// any of this fails: then EPA runs from the tetrahedron, or GJK from scratch.
pub(super) fn confirm<A: Convex, B: Convex>(
    cso: &mut Cso<A, B>,
    start: &[Point; 4],
    gap: f64,
    tiny: f64,
) -> Option<Penetration> {
    let [p0, mut p1, mut p2, apex] = *start;
    let mut cross = (p1.w - p0.w).cross(&(p2.w - p0.w));
    if cross.dot(&(apex.w - p0.w)) > 0.0 {
        std::mem::swap(&mut p1, &mut p2);
        cross = -cross;
    }
    let length = cross.norm();
    if length.is_nan() || length <= tiny * tiny {
        return None;
    }
    let normal = cross / length;
    let dist = normal.dot(&((p0.w + p1.w + p2.w) / 3.0));
    if dist <= 0.0 {
        return None;
    }
    // Each side face, oriented away from the base corner it misses, must lie farther out:
    // s·c > dist |s| for its normal s and centroid c, compared in squares (dist > 0), which
    // spares each side a root and a division.
    for (p, q, other) in [(&p0, &p1, &p2), (&p1, &p2, &p0), (&p2, &p0, &p1)] {
        let side = (q.w - p.w).cross(&(apex.w - p.w));
        let squared = side.norm_squared();
        if squared.is_nan() || squared <= tiny.powi(4) {
            return None;
        }
        let side = if side.dot(&(other.w - p.w)) > 0.0 { -side } else { side };
        let out = side.dot(&((p.w + q.w + apex.w) / 3.0));
        if out <= 0.0 || out * out <= dist * dist * squared {
            return None;
        }
    }
    let w = cso.support(&normal);
    (normal.dot(&w.w) - dist <= gap).then(|| penetration_on([p0, p1, p2], normal, dist, true))
}

/// EPA from the tetrahedron `start` (holding the origin) to a support gap of `gap`; `visible`
/// and `tiny` are the plane and area tolerances; iterations are counted in `iterations`.
pub(super) fn expand<A: Convex, B: Convex>(
    cso: &mut Cso<A, B>,
    start: &[Point; 4],
    gap: f64,
    visible: f64,
    tiny: f64,
    iterations: &mut u32,
) -> Option<Penetration> {
    EPA.with_borrow_mut(|polytope| polytope.run(cso, start, gap, visible, tiny, iterations))
}

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
        start: &[Point; 4],
        gap: f64,
        visible: f64,
        tiny: f64,
        iterations: &mut u32,
    ) -> Option<Penetration> {
        self.n_points = 0;
        self.n_faces = 0;
        self.n_free = 0;
        self.pass = 0;
        let mut p = *start;
        // Orient the tetrahedron so that the faces below have outward normals.
        if (p[1].w - p[0].w).dot(&(p[2].w - p[0].w).cross(&(p[3].w - p[0].w))) > 0.0 {
            p.swap(1, 2);
        }
        self.points[..4].copy_from_slice(&p);
        self.n_points = 4;
        for f in 0..4 {
            // A fresh polytope fills slots 0–3 in order, so the faces link by the fixed table.
            let slot = self.add_face(TETRAHEDRON[f], tiny)?;
            self.faces[slot as usize].adj = TETRAHEDRON_ADJACENT[f];
            self.faces[slot as usize].edge = TETRAHEDRON_EDGE[f];
        }
        loop {
            *iterations += 1;
            let best = (0..self.n_faces)
                .filter(|&f| self.faces[f].live)
                .min_by(|&f, &g| self.faces[f].dist.total_cmp(&self.faces[g].dist))
                .expect("the polytope has faces");
            let face = self.faces[best];
            let w = cso.support(&face.normal);
            let converged = face.normal.dot(&w.w) - face.dist <= gap;
            if converged || self.n_points == EPA_VERTICES {
                return Some(self.end(&face, converged));
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
                return Some(self.end(&face, false));
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
    fn end(&self, face: &Face, converged: bool) -> Penetration {
        penetration_on(face.v.map(|i| self.points[i as usize]), face.normal, face.dist, converged)
    }
}

/// Unnormalised signed barycentric coordinates of `o`, a point of the plane of the face
/// (p, q, r) whose unit normal is `n`: twice the areas of the sub-triangles opposite each corner.
fn barycentric(face: &[Point; 3], o: &V3, n: &V3) -> [f64; 3] {
    let [p, q, r] = face;
    [(q.w - o).cross(&(r.w - o)).dot(n), (r.w - o).cross(&(p.w - o)).dot(n), (p.w - o).cross(&(q.w - o)).dot(n)]
}

/// Depth, normal and deepest points from the face (p, q, r) nearest the origin: the origin's
/// projection onto it, δ n, in barycentric coordinates of the face's points.
fn penetration_on(face: [Point; 3], normal: V3, dist: f64, converged: bool) -> Penetration {
    let [p, q, r] = face;
    let lambda = barycentric(&face, &(normal * dist), &normal).map(|l| l.max(0.0));
    let sum: f64 = lambda.iter().sum();
    let lambda = if sum > 0.0 { lambda.map(|l| l / sum) } else { [1.0 / 3.0; 3] };
    Penetration {
        normal,
        depth: dist,
        a: p.a * lambda[0] + q.a * lambda[1] + r.a * lambda[2],
        b: p.b * lambda[0] + q.b * lambda[1] + r.b * lambda[2],
        face,
        converged,
    }
}
