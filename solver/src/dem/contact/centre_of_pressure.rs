//! The contact point of two polyhedra, or of a polyhedron and a wall: the centroid of the
//! overlap volume (the centre of pressure of a Winkler contact).
//!
//! A single point carries the contact force. EPA's witness points are arbitrary points of the
//! touching features: for two faces in contact (a cube resting on a face) any point of the
//! overlap of the two faces is a witness, and a force off the centre would tip the cube. The
//! point used here is the centroid of the overlap volume, i.e. the centre of pressure of a
//! Winkler (elastic foundation) contact, whose pressure is proportional to the local overlap:
//! for a face resting flat it is the centre of the shared area, and tilting the body moves it
//! towards the deeper side, so the contact pushes back. For vertex–face and edge–edge contacts it
//! is the centroid of the small overlapping tip, within O(δ) of the EPA witnesses. It varies
//! continuously with the poses. Along the normal the point is placed midway between the two
//! deepest points, as for spheres and ellipsoids.
//!
//! # Closed forms
//! Contacts in a bed are shallow and most touch a vertex to a face or an edge to an edge, where
//! the overlap is a pyramid or a tetrahedron:
//! * vertex a of one body into face f of the other: if every neighbour of a lies outside f's
//!   plane, the body's part beyond the plane is the pyramid of apex a over the polygon where its
//!   edges at a cross the plane; if that polygon lies inside f and a inside the other body, the
//!   pyramid is the overlap. Its centroid lies 3/4 of the way from a to the polygon's centroid.
//! * edge e_A into edge e_B: each body lies in the wedge of the two faces on its edge, and the
//!   two wedges meet in a tetrahedron whose corners are where each edge crosses the other wedge's
//!   faces; if each corner lies on its edge's segment and inside the face it crosses, all four
//!   corners belong to both bodies and the tetrahedron is the overlap. Its centroid is the mean
//!   of the corners.
//!
//! "a inside the other body" is tested against the tetrahedron of f and the other body's centre
//! of mass, which the convex body contains. When a test fails (a face lying on a face, a tip
//! reaching past an edge) the overlap is clipped as below.
//!
//! # Clipping
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
//! nothing. The clipped triangles (128 per body) live in per-thread buffers; a contact whose
//! overlap involves more than that falls back to the EPA witness midpoint.

use std::cell::RefCell;

use nalgebra::{Vector2, Vector3};

use super::ellipsoid::tangent_basis;
use super::epa::Penetration;
use super::support::PolyhedronPose;

type V3 = Vector3<f64>;
type V2 = Vector2<f64>;

/// Vertices above the level of the other body, and triangles touching them, that the overlap
/// integration can hold per body.
const CAP_VERTICES: usize = 64;
const CAP_TRIANGLES: usize = 128;

/// Where the contact point came from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Overlap {
    /// A vertex into a face: the centroid of a pyramid.
    Pyramid,
    /// An edge into an edge: the centroid of a tetrahedron.
    Tetrahedron,
    /// The clipped overlap volume.
    Clipped,
    /// The EPA witness midpoint: the rule asked for it ([`super::ContactPoint::Witness`]), or
    /// the overlap had too many triangles to clip.
    Witness,
}

/// The contact point of polyhedra A and B that EPA found overlapping by `end` (relative to A's
/// centre), with how it was found; `closed_forms` tries the pyramid and the tetrahedron first.
pub(super) fn contact_point(
    a: &PolyhedronPose,
    b: &PolyhedronPose,
    end: &Penetration,
    closed_forms: bool,
) -> (V3, Overlap) {
    let middle = (end.a + end.b) * 0.5;
    let n = end.normal;
    let closed = if closed_forms { closed_form(a, b, end) } else { None };
    if let Some((centroid, kind)) = closed {
        return (centroid - n * n.dot(&(centroid - middle)), kind);
    }
    let frame = Frame::new(&n);
    // Frame coordinates are taken from the witness midpoint, which lies near the overlap: small
    // coordinates keep the boundary integrals free of cancellation.
    let (top, bottom) = (n.dot(&(end.a - middle)), n.dot(&(end.b - middle)));
    let centroid = SLABS.with_borrow_mut(|slabs| {
        let [slab_a, slab_b] = &mut **slabs;
        slab_a.gather(a, &frame.coordinates(&-middle), &frame, 1.0, bottom)?;
        slab_b.gather(b, &frame.coordinates(&(b.center() - a.center() - middle)), &frame, -1.0, top)?;
        let mut integrals = Integrals::default();
        let flush = 8.0 * f64::EPSILON * (a.bounding_radius() + b.bounding_radius());
        slab_a.clipped_by(slab_b, true, flush, &mut integrals)?;
        slab_b.clipped_by(slab_a, false, flush, &mut integrals)?;
        integrals.centroid()
    });
    match centroid {
        Some(c) => (middle + frame.world(&V3::new(c.x, c.y, 0.0)), Overlap::Clipped),
        None => (middle, Overlap::Witness),
    }
}

/// The overlap's centroid from EPA's last face when it names a vertex–face or an edge–edge
/// contact: in closed form when the tests of the module docs hold, else by clipping the pyramid
/// or tetrahedron by the two bodies' faces near the contact (a small polytope cut by planes that
/// mostly miss it), or `None` when the contact is of another kind.
fn closed_form(a: &PolyhedronPose, b: &PolyhedronPose, end: &Penetration) -> Option<(V3, Overlap)> {
    let va = distinct(end.face.map(|p| p.vertex_a));
    let vb = distinct(end.face.map(|p| p.vertex_b));
    let d = b.center() - a.center();
    let n = end.normal;
    // The levels along n of A's deepest point and of B's: the overlap lies between them.
    let (top, bottom) = (n.dot(&end.a), n.dot(&end.b));
    match (va.1, vb.1) {
        (1, 3) => {
            let face = [0, 1, 2].map(|k| end.face[k].b);
            match pyramid(a, va.0[0], &V3::zeros(), &face, &d, &n)? {
                Tip::Closed(c) => Some((c, Overlap::Pyramid)),
                Tip::Reaches => clipped_cell(&n, &[(b, d, -1.0, top)], Overlap::Pyramid),
            }
        }
        (3, 1) => {
            let face = [0, 1, 2].map(|k| end.face[k].a);
            match pyramid(b, vb.0[0], &d, &face, &V3::zeros(), &-n)? {
                Tip::Closed(c) => Some((c, Overlap::Pyramid)),
                Tip::Reaches => clipped_cell(&n, &[(a, V3::zeros(), 1.0, bottom)], Overlap::Pyramid),
            }
        }
        (2, 2) => match edge_edge(a, [va.0[0], va.0[1]], b, [vb.0[0], vb.0[1]], &d)? {
            Tip::Closed(c) => Some((c, Overlap::Tetrahedron)),
            Tip::Reaches => clipped_cell(&n, &[(a, V3::zeros(), 1.0, bottom), (b, d, -1.0, top)], Overlap::Tetrahedron),
        },
        _ => None,
    }
}

/// A pyramid or tetrahedron that is the overlap (its centroid), or that holds it but reaches
/// past a face of the other body (it is left in the thread's cell, to be clipped).
enum Tip {
    Closed(V3),
    Reaches,
}

/// The cell left by [`pyramid`] or [`edge_edge`] clipped by the faces near the contact of each
/// (body, centre, side, level) in `bodies`: those with a vertex beyond `level` on `side` along
/// the contact normal `n` (the faces that can cut anything in the slab of the overlap).
fn clipped_cell(n: &V3, bodies: &[(&PolyhedronPose, V3, f64, f64)], kind: Overlap) -> Option<(V3, Overlap)> {
    CELL.with_borrow_mut(|cell| {
        for (_, _, side, level) in bodies {
            // The overlap lies on `side` of the other body's deepest level (in the slab between).
            cell.clip(&(n * -side), -side * level)?;
        }
        for (body, center, side, level) in bodies {
            for_each_face_beyond(body, center, n, *side, *level, |m, x| cell.clip_through(m, x))?;
        }
        cell.centroid().map(|c| (c, kind))
    })
}

/// The distinct values of three, in order of appearance, and how many there are.
fn distinct(v: [u32; 3]) -> ([u32; 3], usize) {
    let mut out = [v[0]; 3];
    let mut count = 1;
    for &x in &v[1..] {
        if !out[..count].contains(&x) {
            out[count] = x;
            count += 1;
        }
    }
    (out, count)
}

/// The overlap of vertex `apex` of `body` (centred at `center`) with the triangle `face` of the
/// other body (whose centre of mass is `other_center`), `m` the unit normal pointing from the
/// apex's body into the face's; all relative to A's centre. When every neighbour of the apex
/// lies outside the face's plane the body's part beyond it is the pyramid of the module docs:
/// its centroid if it is the overlap, else the pyramid is left in the cell. `None` when a
/// neighbour lies beyond the plane too.
fn pyramid(body: &PolyhedronPose, apex: u32, center: &V3, face: &[V3; 3], other_center: &V3, m: &V3) -> Option<Tip> {
    let shape = body.shape();
    let p = center + body.vertex(apex);
    // Heights above the face's plane, into the other body.
    let level = m.dot(&face[0]);
    let height = |x: &V3| m.dot(x) - level;
    let h = height(&p);
    if h <= 0.0 {
        return None;
    }
    let cut = |w: u32| -> Option<V3> {
        let q = center + body.vertex(w);
        let hq = height(&q);
        (hq < 0.0).then(|| p + (q - p) * (h / (h - hq)))
    };
    let ring = shape.neighbours_of(apex);
    let mut cuts = [V3::zeros(); CELL_CORNERS];
    if ring.len() > CELL_CORNERS {
        return None;
    }
    for (c, &w) in cuts.iter_mut().zip(ring) {
        *c = cut(w)?;
    }
    let cuts = &cuts[..ring.len()];
    let inward = edge_normals(face);
    let inside = |x: &V3| (0..3).all(|k| inward[k].dot(&(x - face[k])) >= 0.0);
    // The apex lies in the other body when it lies in the tetrahedron of the face and that
    // body's centre.
    let side = |x: &V3, u: &V3, v: &V3| (u - other_center).cross(&(v - other_center)).dot(&(x - other_center));
    let apex_inside = (0..3).all(|k| {
        let (u, v, w) = (face[k], face[(k + 1) % 3], face[(k + 2) % 3]);
        side(&p, &u, &v) * side(&w, &u, &v) >= 0.0
    });
    if !(apex_inside && cuts.iter().all(inside)) {
        return CELL.with_borrow_mut(|cell| cell.pyramid(&p, cuts, m).map(|_| Tip::Reaches));
    }
    // The base polygon's area centroid, fanned from the apex's foot.
    let foot = p - m * h;
    let (mut area, mut moment) = (0.0, V3::zeros());
    for k in 0..cuts.len() {
        let (c1, c2) = (cuts[k], cuts[(k + 1) % cuts.len()]);
        let signed = (c1 - foot).cross(&(c2 - foot)).dot(m);
        area += signed;
        moment += (foot + c1 + c2) * signed;
    }
    if area == 0.0 || !area.is_finite() {
        return None;
    }
    let base = moment / (3.0 * area);
    Some(Tip::Closed(p + (base - p) * 0.75))
}

/// For each edge k (from corner k to k + 1) of a counter-clockwise triangle, a normal in its
/// plane pointing into it: x lies in the triangle when every one has x − corner k along it.
/// ((c_{k+1} − c_k) × (x − c_k)) · s = (s × (c_{k+1} − c_k)) · (x − c_k), s the triangle's spin.
fn edge_normals(corners: &[V3; 3]) -> [V3; 3] {
    let spin = (corners[1] - corners[0]).cross(&(corners[2] - corners[0]));
    [0, 1, 2].map(|k| spin.cross(&(corners[(k + 1) % 3] - corners[k])))
}

/// The overlap of edge `ea` of A (centred at the origin) with edge `eb` of B (centred at `d`):
/// the tetrahedron where the wedges of the two faces on each edge meet. Its centroid if it is
/// the overlap, else it is left in the cell; `None` if the wedges do not meet in one.
fn edge_edge(a: &PolyhedronPose, ea: [u32; 2], b: &PolyhedronPose, eb: [u32; 2], d: &V3) -> Option<Tip> {
    let (apices_a, apices_b) = (a.shape().edge_apices(ea[0], ea[1])?, b.shape().edge_apices(eb[0], eb[1])?);
    let wedge_a = Wedge::of(a, ea, apices_a, &V3::zeros());
    let wedge_b = Wedge::of(b, eb, apices_b, d);
    let (pa, ok_a) = wedge_b.crossings(&wedge_a.edge)?;
    let (pb, ok_b) = wedge_a.crossings(&wedge_b.edge)?;
    if ok_a && ok_b {
        return Some(Tip::Closed((pa[0] + pa[1] + pb[0] + pb[1]) * 0.25));
    }
    // The tetrahedron's faces: on each face plane of one wedge, the other edge's crossing with
    // it and both crossings on this wedge's own edge. The wedges bound it only if each face's
    // outward normal points away from the corner off it.
    let bounded = [
        (&wedge_a.normals[0], pb[1]),
        (&wedge_a.normals[1], pb[0]),
        (&wedge_b.normals[0], pa[1]),
        (&wedge_b.normals[1], pa[0]),
    ]
    .iter()
    .zip([pa[0], pa[0], pb[0], pb[0]])
    .all(|((normal, off), on)| normal.dot(&(off - on)) < 0.0);
    // Nearly parallel edges make a tetrahedron reaching far beyond the grains, whose clipping
    // down to the overlap would lose the digits that matter: those contacts are clipped whole.
    let near = [pa[0], pa[1], pb[0], pb[1]]
        .iter()
        .all(|x| x.norm() <= a.bounding_radius() && (x - d).norm() <= b.bounding_radius());
    if !bounded || !near {
        return None;
    }
    CELL.with_borrow_mut(|cell| {
        cell.clear(&((pa[0] + pa[1] + pb[0] + pb[1]) * 0.25));
        let [a0, a1, b0, b1] = [pa[0], pa[1], pb[0], pb[1]].map(|x| cell.vertex(&x));
        let [a0, a1, b0, b1] = [a0?, a1?, b0?, b1?];
        cell.face(&wedge_a.normals[0], &[a0, a1, b0])?;
        cell.face(&wedge_a.normals[1], &[a0, a1, b1])?;
        cell.face(&wedge_b.normals[0], &[b0, b1, a0])?;
        cell.face(&wedge_b.normals[1], &[b0, b1, a1])?;
        cell.bound();
        Some(Tip::Reaches)
    })
}

/// The two faces of a body on one of its edges.
struct Wedge {
    /// The edge's ends.
    edge: [V3; 2],
    /// The faces (p, q, r₁) and (p, r₂, q), counter-clockwise seen from outside.
    faces: [[V3; 3]; 2],
    /// Their outward normals (not of unit length).
    normals: [V3; 2],
}

impl Wedge {
    /// The wedge on edge `on` of `body` (centred at `center`), whose faces have the third
    /// corners `apices` (the shape's edge apices; made here without an `Option`, which the
    /// contact loop would copy).
    fn of(body: &PolyhedronPose, on: [u32; 2], [r1, r2]: [u32; 2], center: &V3) -> Self {
        let (p, q) = (center + body.vertex(on[0]), center + body.vertex(on[1]));
        let faces = [[p, q, center + body.vertex(r1)], [p, center + body.vertex(r2), q]];
        let normals = faces.map(|c| (c[1] - c[0]).cross(&(c[2] - c[0])));
        Self { edge: [p, q], faces, normals }
    }

    /// Where the segment `edge` crosses the planes of the two faces, and whether each crossing
    /// lies on the segment and inside its face; `None` if the segment is parallel to one.
    fn crossings(&self, edge: &[V3; 2]) -> Option<([V3; 2], bool)> {
        let direction = edge[1] - edge[0];
        let mut out = [V3::zeros(); 2];
        let mut ok = true;
        for ((slot, corners), normal) in out.iter_mut().zip(&self.faces).zip(&self.normals) {
            let along = normal.dot(&direction);
            if along == 0.0 {
                return None;
            }
            let s = normal.dot(&(corners[0] - edge[0])) / along;
            let x = edge[0] + direction * s;
            ok &= (0.0..=1.0).contains(&s)
                && (0..3).all(|k| (corners[(k + 1) % 3] - corners[k]).cross(&(x - corners[k])).dot(normal) >= 0.0);
            *slot = x;
        }
        Some((out, ok))
    }
}

/// Calls `clip` with an outward normal (of any length) and a corner of every face of `body`
/// (centred at `center`) with a vertex beyond `level` on `side` along `axis`. `None` if there
/// are more than the buffers hold, or if `clip` says so.
fn for_each_face_beyond(
    body: &PolyhedronPose,
    center: &V3,
    axis: &V3,
    side: f64,
    level: f64,
    mut clip: impl FnMut(&V3, &V3) -> Option<()>,
) -> Option<()> {
    let shape = body.shape();
    // Heights along the axis in the body's own frame: one product per vertex met.
    let (local, base) = (body.local(&(axis * side)), side * (level - axis.dot(center)));
    let beyond = |v: u32| local.dot(&shape.vertices()[v as usize]) > base;
    triangles_beyond(body, &(axis * side), beyond, |t| {
        clip(&body.normal_direction(t), &(center + body.vertex(shape.triangles()[t as usize][0])))
    })
}

/// Calls `visit` once with every triangle of `body` that has a vertex for which `beyond`
/// holds, found by walking the vertex graph from the vertex farthest along world direction
/// `toward` through the vertices beyond (those beyond a plane are connected on a convex
/// polyhedron). `None` if there are more than the buffers hold, or if `visit` says so.
fn triangles_beyond(
    body: &PolyhedronPose,
    toward: &V3,
    beyond: impl Fn(u32) -> bool,
    mut visit: impl FnMut(u32) -> Option<()>,
) -> Option<()> {
    let shape = body.shape();
    let direction = body.local(toward);
    let top = shape.climb(&direction, shape.start(&direction));
    if !beyond(top) {
        return Some(());
    }
    MARKS.with_borrow_mut(|marks| {
        let mark = marks.next(shape.vertices().len(), shape.triangles().len());
        let mut seen = [0u32; CAP_VERTICES];
        let mut n_seen = 1;
        seen[0] = top;
        marks.vertex[top as usize] = mark;
        let mut n_taken = 0;
        let mut next = 0;
        while next < n_seen {
            let v = seen[next];
            next += 1;
            for &t in shape.incident_to(v) {
                if marks.triangle[t as usize] == mark {
                    continue;
                }
                if n_taken == CAP_TRIANGLES {
                    return None;
                }
                marks.triangle[t as usize] = mark;
                n_taken += 1;
                visit(t)?;
            }
            for &w in shape.neighbours_of(v) {
                if marks.vertex[w as usize] != mark && beyond(w) {
                    if n_seen == CAP_VERTICES {
                        return None;
                    }
                    marks.vertex[w as usize] = mark;
                    seen[n_seen] = w;
                    n_seen += 1;
                }
            }
        }
        Some(())
    })
}

/// Which vertices and triangles a walk has met: each walk marks them with a new number, so
/// that nothing is cleared between walks.
#[derive(Debug, Default)]
struct Marks {
    vertex: Vec<u32>,
    triangle: Vec<u32>,
    current: u32,
}

impl Marks {
    /// The mark of a new walk on a shape of this many vertices and triangles.
    fn next(&mut self, vertices: usize, triangles: usize) -> u32 {
        if self.vertex.len() < vertices {
            self.vertex.resize(vertices, 0);
        }
        if self.triangle.len() < triangles {
            self.triangle.resize(triangles, 0);
        }
        if self.current == u32::MAX {
            self.vertex.fill(0);
            self.triangle.fill(0);
            self.current = 0;
        }
        self.current += 1;
        self.current
    }
}

thread_local! {
    static MARKS: RefCell<Marks> = RefCell::new(Marks::default());
}

/// Vertices, faces and corners per face a cell can hold.
const CELL_VERTICES: usize = 96;
const CELL_FACES: usize = 32;
const CELL_CORNERS: usize = 24;

/// One face of a cell: its corners (indices of the cell's vertices), counter-clockwise seen from
/// outside.
#[derive(Debug, Clone, Copy)]
struct CellFace {
    len: usize,
    corners: [u8; CELL_CORNERS],
}

/// A small convex polytope (a pyramid or tetrahedron of the overlap's size) cut down plane by
/// plane, in coordinates relative to `origin` (which keeps them as small as the cell). Faces
/// share their vertices and a cut computes each crossing once, so the faces stay a closed
/// surface however close a plane comes to a vertex.
struct Cell {
    vertices: [V3; CELL_VERTICES],
    n_vertices: usize,
    faces: [CellFace; CELL_FACES],
    n_faces: usize,
    origin: V3,
    /// A ball about `center` holding the cell: planes that miss it are skipped at once.
    center: V3,
    radius: f64,
    /// Per vertex during a cut: its plane value, and the vertex it becomes after compaction.
    value: [f64; CELL_VERTICES],
    renumber: [u8; CELL_VERTICES],
    /// The kept vertices in their new order during compaction (here, so that no cut zeroes a
    /// buffer of its own).
    moved: [V3; CELL_VERTICES],
    /// The crossings made by the current cut: edge (in, out) → new vertex.
    crossings: [(u8, u8, u8); CELL_FACES],
    n_crossings: usize,
}

thread_local! {
    static CELL: RefCell<Box<Cell>> = RefCell::new(Box::new(Cell {
        vertices: [V3::zeros(); CELL_VERTICES],
        n_vertices: 0,
        faces: [CellFace { len: 0, corners: [0; CELL_CORNERS] }; CELL_FACES],
        n_faces: 0,
        origin: V3::zeros(),
        center: V3::zeros(),
        radius: 0.0,
        value: [0.0; CELL_VERTICES],
        renumber: [0; CELL_VERTICES],
        moved: [V3::zeros(); CELL_VERTICES],
        crossings: [(0, 0, 0); CELL_FACES],
        n_crossings: 0,
    }));
}

impl Cell {
    /// An empty cell with coordinates taken from `origin`.
    fn clear(&mut self, origin: &V3) {
        self.n_vertices = 0;
        self.n_faces = 0;
        self.origin = *origin;
    }

    /// Adds a vertex (relative to A's centre).
    fn vertex(&mut self, x: &V3) -> Option<u8> {
        if self.n_vertices == CELL_VERTICES {
            return None;
        }
        self.vertices[self.n_vertices] = x - self.origin;
        self.n_vertices += 1;
        Some((self.n_vertices - 1) as u8)
    }

    /// Adds a face on these vertices, turned counter-clockwise about `normal` (outward, any
    /// length).
    fn face(&mut self, normal: &V3, corners: &[u8]) -> Option<()> {
        if self.n_faces == CELL_FACES || corners.len() > CELL_CORNERS || corners.len() < 3 {
            return None;
        }
        let p = |k: usize| self.vertices[corners[k] as usize];
        let turn: V3 = (1..corners.len() - 1).map(|k| (p(k) - p(0)).cross(&(p(k + 1) - p(0)))).sum();
        let face = &mut self.faces[self.n_faces];
        face.len = corners.len();
        face.corners[..corners.len()].copy_from_slice(corners);
        if turn.dot(normal) < 0.0 {
            face.corners[..corners.len()].reverse();
        }
        self.n_faces += 1;
        Some(())
    }

    /// The pyramid of apex `p` over the polygon `base` (its corners in the apex's neighbours'
    /// order), whose plane has the normal `m` pointing from the apex's body into the other.
    fn pyramid(&mut self, p: &V3, base: &[V3], m: &V3) -> Option<()> {
        self.clear(p);
        let apex = self.vertex(p)?;
        let mut ring = [0u8; CELL_CORNERS];
        for (slot, c) in ring.iter_mut().zip(base) {
            *slot = self.vertex(c)?;
        }
        let ring = &ring[..base.len()];
        self.face(&-m, ring)?;
        for k in 0..ring.len() {
            let (c1, c2) = (ring[k], ring[(k + 1) % ring.len()]);
            let normal = (base[k] - p).cross(&(base[(k + 1) % base.len()] - p));
            self.face(&normal, &[apex, c1, c2])?;
        }
        self.bound();
        Some(())
    }

    /// The ball holding the cell's vertices.
    fn bound(&mut self) {
        let used = &self.vertices[..self.n_vertices];
        self.center = used.iter().sum::<V3>() / used.len().max(1) as f64;
        // One root for the largest distance (the root is monotonic, so the same value).
        self.radius = used.iter().map(|v| (v - self.center).norm_squared()).fold(0.0, f64::max).sqrt();
    }

    /// [`Cell::clip`] by the plane through `x` with outward normal `m` of any length. Most planes
    /// miss the cell's ball, which is decided first from m·(x − centre) > r |m| squared, without
    /// the root and division of a unit normal; a plane not clearly missing it (a relative margin
    /// of 1e-9 on the squares) goes to `clip`, which decides as before, so the result is the same.
    fn clip_through(&mut self, m: &V3, x: &V3) -> Option<()> {
        let s = m.dot(&(x - self.origin - self.center));
        if s > 0.0 && s * s > self.radius * self.radius * m.norm_squared() * (1.0 + 1e-9) {
            return Some(());
        }
        let normal = m.normalize();
        self.clip(&normal, normal.dot(x))
    }

    /// Keeps the part of the cell where normal · x ≤ offset (`normal` of unit length, x relative
    /// to A's centre), closing the cut with a new face. `None` if the result does not fit or the
    /// cut is not that of a convex polytope.
    fn clip(&mut self, normal: &V3, offset: f64) -> Option<()> {
        // Plane values are rounded to about an ulp of the terms subtracted here; a vertex within
        // that of the plane counts as on it, so that a plane through a face (the other body's
        // face the overlap rests on) cuts nothing.
        let noise = 8.0 * f64::EPSILON * offset.abs().max(normal.dot(&self.origin).abs());
        let offset = offset - normal.dot(&self.origin) + noise;
        if normal.dot(&self.center) + self.radius <= offset {
            return Some(());
        }
        let mut outside = false;
        for k in 0..self.n_vertices {
            self.value[k] = offset - normal.dot(&self.vertices[k]);
            outside |= self.value[k] < 0.0;
        }
        if !outside {
            return Some(());
        }
        self.n_crossings = 0;
        // Each cut face contributes one edge of the cap, from where the face re-enters the kept
        // part to where it leaves it (the reverse of the face's own direction along the cut).
        let mut segments = [(0u8, 0u8); CELL_FACES];
        let mut n_segments = 0;
        let mut kept = 0;
        for f in 0..self.n_faces {
            let face = self.faces[f];
            let corners = &face.corners[..face.len];
            if corners.iter().all(|&v| self.value[v as usize] >= 0.0) {
                self.faces[kept] = face;
                kept += 1;
                continue;
            }
            let mut out = CellFace { len: 0, corners: [0; CELL_CORNERS] };
            let (mut exit, mut entry) = (None, None);
            for i in 0..corners.len() {
                let (u, v) = (corners[i], corners[(i + 1) % corners.len()]);
                let (inside_u, inside_v) = (self.value[u as usize] >= 0.0, self.value[v as usize] >= 0.0);
                if inside_u {
                    if out.len == CELL_CORNERS {
                        return None;
                    }
                    out.corners[out.len] = u;
                    out.len += 1;
                }
                if inside_u != inside_v {
                    let x = self.crossing(u, v)?;
                    if out.len == CELL_CORNERS {
                        return None;
                    }
                    out.corners[out.len] = x;
                    out.len += 1;
                    let end = if inside_u { &mut exit } else { &mut entry };
                    if end.replace(x).is_some() {
                        return None;
                    }
                }
            }
            match (entry, exit) {
                (Some(entry), Some(exit)) => {
                    segments[n_segments] = (entry, exit);
                    n_segments += 1;
                }
                (None, None) => {}
                _ => return None,
            }
            if out.len >= 3 {
                self.faces[kept] = out;
                kept += 1;
            }
        }
        self.n_faces = kept;
        if n_segments >= 3 {
            // Chain the segments into the cap, counter-clockwise about `normal`.
            let mut cap = [0u8; CELL_CORNERS];
            if n_segments > CELL_CORNERS {
                return None;
            }
            let (first, mut at) = segments[0];
            cap[0] = first;
            for slot in cap.iter_mut().take(n_segments).skip(1) {
                *slot = at;
                at = segments[..n_segments].iter().find(|s| s.0 == at)?.1;
            }
            if at != first || self.n_faces == CELL_FACES {
                return None;
            }
            let face = &mut self.faces[self.n_faces];
            face.len = n_segments;
            face.corners[..n_segments].copy_from_slice(&cap[..n_segments]);
            self.n_faces += 1;
        }
        self.compact();
        Some(())
    }

    /// The vertex where edge (u, v) meets the plane, made once per edge.
    fn crossing(&mut self, u: u8, v: u8) -> Option<u8> {
        let (a, b) = if self.value[u as usize] >= 0.0 { (u, v) } else { (v, u) };
        if let Some(&(_, _, x)) = self.crossings[..self.n_crossings].iter().find(|c| c.0 == a && c.1 == b) {
            return Some(x);
        }
        if self.n_vertices == CELL_VERTICES || self.n_crossings == CELL_FACES {
            return None;
        }
        let (va, vb) = (self.value[a as usize], self.value[b as usize]);
        let (pa, pb) = (self.vertices[a as usize], self.vertices[b as usize]);
        self.vertices[self.n_vertices] = pa + (pb - pa) * (va / (va - vb));
        self.value[self.n_vertices] = 0.0;
        let x = self.n_vertices as u8;
        self.n_vertices += 1;
        self.crossings[self.n_crossings] = (a, b, x);
        self.n_crossings += 1;
        Some(x)
    }

    /// Drops the vertices no face uses any more, and bounds what is left.
    fn compact(&mut self) {
        self.renumber[..self.n_vertices].fill(u8::MAX);
        let mut next = 0usize;
        for face in &mut self.faces[..self.n_faces] {
            for c in &mut face.corners[..face.len] {
                if self.renumber[*c as usize] == u8::MAX {
                    self.renumber[*c as usize] = next as u8;
                    next += 1;
                }
                *c = self.renumber[*c as usize];
            }
        }
        for k in 0..self.n_vertices {
            let r = self.renumber[k];
            if r != u8::MAX {
                self.moved[r as usize] = self.vertices[k];
            }
        }
        self.vertices[..next].copy_from_slice(&self.moved[..next]);
        self.n_vertices = next;
        self.bound();
    }

    /// Centroid (relative to A's centre) of the cell, from its boundary by the divergence
    /// theorem; `None` if it has no volume.
    fn centroid(&self) -> Option<V3> {
        let (mut volume, mut moment) = (0.0, V3::zeros());
        for face in &self.faces[..self.n_faces] {
            let c = |k: usize| self.vertices[face.corners[k] as usize];
            for k in 1..face.len.saturating_sub(1) {
                let (a, b, d) = (c(0), c(k), c(k + 1));
                // Twice the vector area of the triangle, along its outward normal.
                let area = (b - a).cross(&(d - a));
                volume += area.dot(&(a + b + d)) / 18.0;
                let square =
                    |i: usize| a[i] * a[i] + b[i] * b[i] + d[i] * d[i] + a[i] * b[i] + b[i] * d[i] + d[i] * a[i];
                moment += V3::new(area.x * square(0), area.y * square(1), area.z * square(2)) / 24.0;
            }
        }
        (volume > 0.0 && volume.is_finite()).then(|| self.origin + moment / volume)
    }
}

/// The contact point of polyhedron A with the half-space {n·(x − x_A) ≥ level} that it enters
/// by `depth` (relative to A's centre): the centroid of its part beyond the plane, at half the
/// depth. A single vertex beyond the plane makes a pyramid; more are clipped.
pub(super) fn against_plane(a: &PolyhedronPose, n: &V3, level: f64, deepest: u32, depth: f64) -> V3 {
    let tip = a.vertex(deepest);
    // Frame coordinates from the deepest point's foot on the plane: the plane is z = 0 there,
    // and the cut face lying in it adds nothing to the integrals (x·n = 0 and n_t1 = n_t2 = 0).
    let foot = tip - n * (n.dot(&tip) - level);
    let pyramid = plane_pyramid(a, n, level, deepest, &tip);
    let offset = match pyramid {
        Some(c) => c - n * n.dot(&(c - foot)) - foot,
        None => {
            let frame = Frame::new(n);
            let centroid = SLABS.with_borrow_mut(|slabs| {
                let slab = &mut slabs[0];
                slab.gather(a, &frame.coordinates(&-foot), &frame, 1.0, 0.0)?;
                let mut integrals = Integrals::default();
                slab.beyond(0.0, &mut integrals)?;
                integrals.centroid()
            });
            centroid.map_or(V3::zeros(), |c| frame.world(&V3::new(c.x, c.y, 0.0)))
        }
    };
    foot + n * (0.5 * depth) + offset
}

/// Centroid of A's part beyond the plane when only vertex `deepest` (at `tip`) lies beyond it.
fn plane_pyramid(a: &PolyhedronPose, n: &V3, level: f64, deepest: u32, tip: &V3) -> Option<V3> {
    let shape = a.shape();
    let h = n.dot(tip) - level;
    let foot = tip - n * h;
    let cut = |w: u32| -> Option<V3> {
        let q = a.vertex(w);
        let hq = n.dot(&q) - level;
        (hq < 0.0).then(|| tip + (q - tip) * (h / (h - hq)))
    };
    let ring = shape.neighbours_of(deepest);
    let first = cut(ring[0])?;
    let (mut area, mut moment, mut previous) = (0.0, V3::zeros(), first);
    for k in 1..=ring.len() {
        let next = if k == ring.len() { first } else { cut(ring[k])? };
        let signed = (previous - foot).cross(&(next - foot)).dot(n);
        area += signed;
        moment += (foot + previous + next) * signed;
        previous = next;
    }
    (area != 0.0 && area.is_finite()).then(|| tip + (moment / (3.0 * area) - tip) * 0.75)
}

/// The contact plane's frame: tangents t1, t2 and normal n, right-handed.
pub(super) struct Frame {
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
        let shape = pose.shape();
        let axes = [frame.t1, frame.t2, frame.n].map(|a| pose.local(&a));
        let at = |v: u32| {
            let x = &shape.vertices()[v as usize];
            V3::new(axes[0].dot(x), axes[1].dot(x), axes[2].dot(x)) + shift
        };
        let slab = self;
        slab.len = 0;
        slab.lo = V2::repeat(f64::INFINITY);
        slab.hi = V2::repeat(f64::NEG_INFINITY);
        triangles_beyond(
            pose,
            &(frame.n * side),
            |v| side * (at(v).z - level) > 0.0,
            |t| {
                let p = shape.triangles()[t as usize].map(at);
                let normal = frame.coordinates(&pose.normal(t));
                for corner in &p {
                    slab.lo = slab.lo.inf(&corner.xy());
                    slab.hi = slab.hi.sup(&corner.xy());
                }
                slab.facets[slab.len] = Facet { p, normal, offset: normal.dot(&p[0]) };
                slab.len += 1;
                Some(())
            },
        )
    }

    /// Adds the parts of these facets that lie inside all of `other`'s facet planes. A facet
    /// lying in one of those planes (grains side by side with faces flush, to within
    /// `tolerance`) is the same boundary as the other's facet there: it is not cut by that
    /// plane, and, facing the same way, it is counted by body A only (`first`).
    fn clipped_by(&self, other: &Slab, first: bool, tolerance: f64, integrals: &mut Integrals) -> Option<()> {
        let flush =
            |f: &Facet, g: &Facet| (f.normal - g.normal).amax() <= 1e-12 && (f.offset - g.offset).abs() <= tolerance;
        let mut polygon = Polygon::new();
        for facet in &self.facets[..self.len] {
            // A facet whose projection misses the other body's part in the slab is outside it.
            let [p, q, r] = facet.p.map(|c| c.xy());
            let (lo, hi) = (p.inf(&q).inf(&r), p.sup(&q).sup(&r));
            if lo.x > other.hi.x || lo.y > other.hi.y || hi.x < other.lo.x || hi.y < other.lo.y {
                continue;
            }
            polygon.reset(&facet.p);
            let mut lies_flush = false;
            for plane in &other.facets[..other.len] {
                if flush(facet, plane) {
                    lies_flush = true;
                    continue;
                }
                polygon.clip(|x| plane.offset - plane.normal.dot(x))?;
                if polygon.len == 0 {
                    break;
                }
            }
            if polygon.len > 0 && (first || !lies_flush) {
                integrals.add(&polygon, &facet.normal);
            }
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
                if len == POLYGON_CORNERS {
                    return None;
                }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube [0, 1]³ as a cell.
    fn cube(cell: &mut Cell) {
        cell.clear(&V3::new(0.5, 0.5, 0.5));
        let v: Vec<u8> = (0..8)
            .map(|k| cell.vertex(&V3::new((k & 1) as f64, (k >> 1 & 1) as f64, (k >> 2 & 1) as f64)).unwrap())
            .collect();
        let faces = [
            (-V3::x(), [0, 2, 6, 4]),
            (V3::x(), [1, 3, 7, 5]),
            (-V3::y(), [0, 1, 5, 4]),
            (V3::y(), [2, 3, 7, 6]),
            (-V3::z(), [0, 1, 3, 2]),
            (V3::z(), [4, 5, 7, 6]),
        ];
        for (normal, f) in faces {
            cell.face(&normal, &f.map(|k| v[k])).unwrap();
        }
        cell.bound();
    }

    #[test]
    fn a_plane_given_by_any_normal_and_a_point_cuts_as_its_unit_normal_and_offset_do() {
        // The unit cube's ball has centre (0.5, 0.5, 0.5) and radius √3/2 ≈ 0.866. Each plane
        // through x with normal m (of length 3 or 0.2) must leave the cell exactly as `clip`
        // with the unit normal and n·x does: planes missing the ball (decided without a unit
        // normal), one grazing it, and planes through the cell.
        let planes = [
            (V3::new(3.0, 0.0, 0.0), V3::new(1.4, 0.0, 0.0)),
            (V3::new(0.2, 0.2, 0.2), V3::new(1.0, 1.0, 1.0) * (0.5 + 0.5)),
            (V3::new(0.0, 0.0, -3.0), V3::new(0.0, 0.0, 0.5 - 3f64.sqrt() / 2.0)),
            (V3::new(3.0, 3.0, 0.0), V3::new(0.3, 0.3, 0.0)),
            (V3::new(0.0, 0.2, 0.2), V3::new(0.0, 0.6, 0.6)),
        ];
        let state = |cell: &Cell| (cell.n_vertices, cell.n_faces, cell.centroid());
        for (m, x) in planes {
            let through = CELL.with_borrow_mut(|cell| {
                cube(cell);
                cell.clip_through(&m, &x).unwrap();
                state(cell)
            });
            let unit = CELL.with_borrow_mut(|cell| {
                cube(cell);
                let n = m.normalize();
                cell.clip(&n, n.dot(&x)).unwrap();
                state(cell)
            });
            assert_eq!(through, unit, "plane {m} through {x}");
        }
    }

    #[test]
    fn a_walk_never_sees_the_marks_of_an_earlier_one_even_when_the_counter_wraps() {
        let mut marks = Marks::default();
        let first = marks.next(4, 3);
        marks.vertex[2] = first;
        marks.triangle[1] = first;
        // A larger shape next: its new entries must not carry the current mark either.
        let second = marks.next(6, 5);
        assert_ne!(second, first);
        assert!(marks.vertex.iter().chain(&marks.triangle).all(|&m| m != second));
        marks.vertex[5] = second;
        marks.current = u32::MAX;
        let third = marks.next(6, 5);
        assert!(marks.vertex.iter().chain(&marks.triangle).all(|&m| m != third), "{marks:?}");
    }

    #[test]
    fn a_polygon_cut_into_more_corners_than_it_holds_gives_up_instead_of_overflowing() {
        // n planes tangent to a circle of radius 0.8 inside a triangle of inradius 1 leave the
        // regular n-gon around the circle, which has n corners.
        let tangent = |angle: f64, radius: f64| move |x: &V3| radius - (angle.cos() * x.x + angle.sin() * x.y);
        let step = std::f64::consts::TAU / POLYGON_CORNERS as f64;
        let full = || {
            let mut polygon = Polygon::new();
            let s = 3f64.sqrt();
            polygon.reset(&[V3::new(0.0, 2.0, 0.0), V3::new(-s, -1.0, 0.0), V3::new(s, -1.0, 0.0)]);
            for k in 0..POLYGON_CORNERS {
                polygon.clip(tangent(k as f64 * step, 0.8)).expect("fits");
            }
            polygon
        };
        assert_eq!(full().corners().len(), POLYGON_CORNERS);
        // Cutting off any one corner would make one more than fit, wherever it lies in the list.
        for k in 0..POLYGON_CORNERS {
            let mut polygon = full();
            assert!(polygon.clip(tangent((k as f64 + 0.5) * step, 0.805)).is_none(), "corner {k}");
        }
    }

    #[test]
    fn a_cell_cut_by_planes_has_the_centroid_of_what_is_left() {
        CELL.with_borrow_mut(|cell| {
            cube(cell);
            let c = cell.centroid().unwrap();
            assert!((c - V3::new(0.5, 0.5, 0.5)).norm() < 1e-15, "{c}");
            // x ≤ 0.25 leaves the slab [0, 0.25] × [0, 1]².
            cell.clip(&V3::x(), 0.25).unwrap();
            let c = cell.centroid().unwrap();
            assert!((c - V3::new(0.125, 0.5, 0.5)).norm() < 1e-15, "{c}");
            // x + y ≤ 0.25 (unit normal) leaves the prism over the triangle (0,0), (0.25,0), (0,0.25).
            let n = V3::new(1.0, 1.0, 0.0).normalize();
            cell.clip(&n, 0.25 * n.x).unwrap();
            let c = cell.centroid().unwrap();
            assert!((c - V3::new(0.25 / 3.0, 0.25 / 3.0, 0.5)).norm() < 1e-15, "{c}");
            // The plane of a face and a plane through an edge cut nothing off.
            let faces = cell.n_faces;
            cell.clip(&-V3::x(), 0.0).unwrap();
            cell.clip(&V3::new(-1.0, -1.0, 0.0).normalize(), 0.0).unwrap();
            assert_eq!(cell.n_faces, faces);
            assert!((cell.centroid().unwrap() - c).norm() < 1e-15);
            // A plane across the top leaves a wedge whose centroid is known in closed form:
            // z ≤ 0.5 halves the prism.
            cell.clip(&V3::z(), 0.5).unwrap();
            let c = cell.centroid().unwrap();
            assert!((c - V3::new(0.25 / 3.0, 0.25 / 3.0, 0.25)).norm() < 1e-14, "{c}");
        });
    }
}
