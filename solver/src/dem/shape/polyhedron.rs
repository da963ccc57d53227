//! Convex polyhedron grains (a scanned or generated mesh, §3.1): one base shape per mesh of the
//! library, shared by every grain drawn from it, and per grain only the diagonal stretch to its
//! form (Fig. 5c) and the quantities derived from it.
//!
//! A grain's body frame is its principal-axes frame, centre of mass at the origin. Stretching a
//! mesh along its principal axes keeps them principal and keeps it convex, with the same
//! vertices, edges and faces: a grain is the base's vertices v mapped to S v, S = diag(scale), so
//! its support point in body direction d is the base's in S d, and its face normals are S⁻¹ n.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

use crate::grain::simplify::CONVEXITY_TOLERANCE;
use crate::grain::{EquivalentEllipsoid, FormParameters, MassProperties, TriMesh};

type V3 = Vector3<f64>;

/// Reflex folds below this fraction of the bounding radius are rounding: a hull with none
/// larger is convex to the precision of its coordinates, so hill climbing is exact on it.
const STRICT_CONVEXITY: f64 = 1e-13;
/// tan(π/8): a direction's component counts as 0 in the start table below this fraction of its
/// largest component, so each of the 26 grid directions covers a cone of about 22.5°.
const TABLE_CUT: f64 = 0.414_213_562_373_095_1;

/// Why a mesh cannot be used as a convex polyhedron.
#[derive(Debug, Error, PartialEq)]
pub enum PolyhedronError {
    #[error("the mesh is not convex: use its convex hull")]
    NotConvex,
    #[error("the convex hull of the mesh's vertices could not be built: {0}")]
    Hull(String),
    #[error("the stretch {0:?} is not positive and finite")]
    Scale([f64; 3]),
}

/// A convex polyhedron in its body frame, with the adjacency the narrow phase walks.
///
/// The hull is convex to rounding: a mesh convex only to [`CONVEXITY_TOLERANCE`] (hulls of
/// scans built with a tolerance leave edges folded inward by ~1e-8 of their size) is replaced by
/// the convex hull of its vertices, so that climbing from any start vertex ends at the same
/// support value.
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
    mass: MassProperties,
}

impl PartialEq for ConvexPolyhedron {
    fn eq(&self, other: &Self) -> bool {
        self.vertices == other.vertices && self.triangles == other.triangles
    }
}

impl ConvexPolyhedron {
    /// The polyhedron bounded by `mesh`, whose vertices are taken as body-frame coordinates.
    /// Vertices used by no triangle are dropped; a mesh convex within [`CONVEXITY_TOLERANCE`]
    /// but not to rounding is replaced by the hull of its vertices.
    pub fn new(mesh: &TriMesh) -> Result<Self, PolyhedronError> {
        if !mesh.is_convex(CONVEXITY_TOLERANCE) {
            return Err(PolyhedronError::NotConvex);
        }
        let strict = if mesh.is_convex(STRICT_CONVEXITY) {
            mesh.clone()
        } else {
            let hull = TriMesh::convex_hull(mesh.vertices()).map_err(|e| PolyhedronError::Hull(e.to_string()))?;
            if !hull.is_convex(STRICT_CONVEXITY) {
                return Err(PolyhedronError::Hull("its hull is not convex to rounding".into()));
            }
            hull
        };
        Ok(Self::from_convex(&strict))
    }

    fn from_convex(mesh: &TriMesh) -> Self {
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
        let mut around = vec![Vec::new(); n];
        let mut normals = Vec::with_capacity(triangles.len());
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                around[v as usize].push(t as u32);
            }
            let [a, b, c] = tri.map(|v| vertices[v as usize]);
            normals.push((b - a).cross(&(c - a)).normalize());
        }
        // Each vertex's neighbours and triangles in counter-clockwise order seen from outside:
        // triangle (v, x, y) is followed by the one holding (v, y, z).
        let mut adjacency = vec![Vec::new(); n];
        for (v, faces) in around.iter_mut().enumerate() {
            let others = |t: u32| {
                let tri = triangles[t as usize];
                let k = tri.iter().position(|&u| u as usize == v).expect("a triangle around v holds v");
                (tri[(k + 1) % 3], tri[(k + 2) % 3])
            };
            let mut ordered = Vec::with_capacity(faces.len());
            let mut t = faces[0];
            for _ in 0..faces.len() {
                ordered.push(t);
                let (x, y) = others(t);
                adjacency[v].push(x);
                t = *faces.iter().find(|&&u| others(u).0 == y).expect("a closed mesh has a triangle after each");
            }
            *faces = ordered;
        }
        let (neighbour_start, neighbours) = compressed(&adjacency);
        let (incident_start, incident) = compressed(&around);
        let bounding_radius = vertices.iter().map(|v| v.norm()).fold(0.0, f64::max);
        let inner_radius =
            triangles.iter().zip(&normals).map(|(t, n)| n.dot(&vertices[t[0] as usize])).fold(f64::INFINITY, f64::min);
        let mass = TriMesh::new(vertices.clone(), triangles.clone())
            .expect("a convex mesh's own triangles form a valid mesh")
            .mass_properties();
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
            mass,
        };
        for (cell, start) in shape.starts.iter_mut().enumerate() {
            let direction = V3::new((cell % 3) as f64 - 1.0, (cell / 3 % 3) as f64 - 1.0, (cell / 9) as f64 - 1.0);
            *start = (0..n as u32)
                .max_by(|&p, &q| {
                    direction.dot(&shape.vertices[p as usize]).total_cmp(&direction.dot(&shape.vertices[q as usize]))
                })
                .expect("a valid mesh has vertices");
        }
        shape
    }

    pub fn vertices(&self) -> &[V3] {
        &self.vertices
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Outward unit normal of each triangle.
    pub fn normals(&self) -> &[V3] {
        &self.normals
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

    /// Bytes of its vertex, adjacency and face tables.
    pub fn heap_bytes(&self) -> usize {
        use std::mem::size_of_val;
        size_of_val(&self.vertices[..])
            + size_of_val(&self.neighbour_start[..])
            + size_of_val(&self.neighbours[..])
            + size_of_val(&self.triangles[..])
            + size_of_val(&self.normals[..])
            + size_of_val(&self.incident_start[..])
            + size_of_val(&self.incident[..])
            + std::mem::size_of::<Self>()
    }

    /// Volume, centre of mass and inertia (per unit density) of the solid.
    pub fn mass_properties(&self) -> &MassProperties {
        &self.mass
    }

    /// Neighbours of vertex `v`, counter-clockwise seen from outside.
    #[inline]
    pub fn neighbours_of(&self, v: u32) -> &[u32] {
        &self.neighbours[self.neighbour_start[v as usize] as usize..self.neighbour_start[v as usize + 1] as usize]
    }

    /// Triangles around vertex `v` in the order of its neighbours: the k-th is
    /// (v, neighbour k, neighbour k + 1).
    #[inline]
    pub fn incident_to(&self, v: u32) -> &[u32] {
        &self.incident[self.incident_start[v as usize] as usize..self.incident_start[v as usize + 1] as usize]
    }

    /// Start vertex for a support query in body direction `d`: the table entry of its cone.
    #[inline]
    pub fn start(&self, d: &V3) -> u32 {
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
    /// while one improves. On a convex polyhedron a vertex that no neighbour improves on is a
    /// global maximum (the polyhedron lies in the cone its edges span), so the climb is exact.
    #[inline]
    pub fn climb(&self, d: &V3, mut at: u32) -> u32 {
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

    /// The third vertices of the two triangles on the edge (p, q): (p, q, r₁) and (p, r₂, q),
    /// both counter-clockwise.
    pub fn edge_apices(&self, p: u32, q: u32) -> Option<[u32; 2]> {
        let ring = self.neighbours_of(p);
        let k = ring.iter().position(|&w| w == q)?;
        let n = ring.len();
        Some([ring[(k + 1) % n], ring[(k + n - 1) % n]])
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

/// A convex polyhedron grain: a shared base shape stretched by `scale` along the body axes, with
/// its mass properties and bounds, precomputed once.
#[derive(Debug, Clone)]
pub struct Polyhedron {
    pub base: Arc<ConvexPolyhedron>,
    pub scale: V3,
    pub volume: f64,
    /// Principal moments per unit density along the body axes.
    pub inertia: V3,
    /// L, I, S of its mass-equivalent ellipsoid (Appendix A).
    pub form: FormParameters,
    pub bounding_radius: f64,
    /// Distance from the centre to the nearest face plane.
    pub inner_radius: f64,
}

impl PartialEq for Polyhedron {
    fn eq(&self, other: &Self) -> bool {
        self.base == other.base && self.scale == other.scale
    }
}

impl Polyhedron {
    /// A grain of `base` stretched by `scale` along its body axes. Its mass properties follow
    /// from the base's exactly: stretching by S multiplies volumes by det S and the second
    /// moments C about the centre of mass become det S · S C S.
    pub fn new(base: Arc<ConvexPolyhedron>, scale: V3) -> Result<Self, PolyhedronError> {
        if !scale.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(PolyhedronError::Scale(scale.into()));
        }
        let props = stretched(base.mass_properties(), &scale);
        let form = EquivalentEllipsoid::of(&props).form().map_err(|_| PolyhedronError::NotConvex)?;
        let bounding_radius = base.vertices.iter().map(|v| v.component_mul(&scale).norm()).fold(0.0, f64::max);
        let inner_radius = base
            .triangles
            .iter()
            .zip(&base.normals)
            .map(|(t, n)| {
                // The face plane n·v = c becomes (S⁻¹n)·x = c, at distance c/|S⁻¹n| from the origin.
                n.dot(&base.vertices[t[0] as usize]) / n.component_div(&scale).norm()
            })
            .fold(f64::INFINITY, f64::min);
        Ok(Self {
            volume: props.volume,
            inertia: props.inertia.diagonal(),
            form,
            bounding_radius,
            inner_radius,
            base,
            scale,
        })
    }

    /// A grain of `base` stretched so that its mass-equivalent ellipsoid (Appendix A) has the
    /// full axes L, I, S of `form` along x, y, z: Fig. 5c for a base normalised to unit L, I, S
    /// (Fig. 5b). Stretching along the principal axes scales each axis of the equivalent
    /// ellipsoid by its own factor, so the stretch is the form over the base's own axes (1 to
    /// within the rounding of the base's normalisation).
    pub fn with_form(base: Arc<ConvexPolyhedron>, form: &FormParameters) -> Result<Self, PolyhedronError> {
        let props = base.mass_properties();
        let inertia = props.inertia.diagonal();
        let total = inertia.sum();
        // Full axis along k: 2 √(5 (−I_k + I_other + I_third) / (2 V)) = 2 √(5 (total − 2 I_k) / (2 V)).
        let own = inertia.map(|ik| 2.0 * (5.0 * (total - 2.0 * ik) / (2.0 * props.volume)).sqrt());
        Self::new(base, V3::new(form.l, form.i, form.s).component_div(&own))
    }

    /// A grain of exactly this mesh (no stretch), with its own base shape.
    pub fn from_mesh(mesh: &TriMesh) -> Result<Self, PolyhedronError> {
        Self::new(Arc::new(ConvexPolyhedron::new(mesh)?), V3::repeat(1.0))
    }

    /// The grain's surface in its body frame.
    pub fn surface(&self) -> (Vec<V3>, Vec<[u32; 3]>) {
        (self.base.vertices.iter().map(|v| v.component_mul(&self.scale)).collect(), self.base.triangles.clone())
    }
}

/// Mass properties of a solid stretched by diag(`scale`).
fn stretched(props: &MassProperties, scale: &V3) -> MassProperties {
    let s = Matrix3::from_diagonal(scale);
    let det = scale.x * scale.y * scale.z;
    // I = tr(C) 1 − C for the second moments C, so C = tr(I)/2 · 1 − I.
    let second = Matrix3::identity() * (0.5 * props.inertia.trace()) - props.inertia;
    let stretched = s * second * s * det;
    MassProperties {
        volume: props.volume * det,
        center_of_mass: props.center_of_mass.component_mul(scale),
        inertia: Matrix3::identity() * stretched.trace() - stretched,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An axis-aligned box of half-sides (1, 1, 1) with each face as two triangles; the top face
    /// is split along the diagonal from (−1, −1, 1) to (1, 1, 1).
    fn cube() -> (Vec<V3>, Vec<[u32; 3]>) {
        let v = (0..8)
            .map(|k| {
                let s = |bit: u32| if k & (1 << bit) != 0 { 1.0 } else { -1.0 };
                V3::new(s(0), s(1), s(2))
            })
            .collect();
        let faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
        let t = faces.iter().flat_map(|f| [[f[0], f[1], f[2]], [f[0], f[2], f[3]]]).collect();
        (v, t)
    }

    #[test]
    fn a_stretched_grain_has_the_mass_properties_and_bounds_of_the_stretched_mesh() {
        let (v, _) = cube();
        let mesh = TriMesh::convex_hull(&[&v[..], &[V3::new(0.3, 0.2, 1.7)]].concat()).unwrap();
        let scale = V3::new(3.0, 2.0, 0.5);
        let grain = Polyhedron::new(Arc::new(ConvexPolyhedron::new(&mesh).unwrap()), scale).unwrap();
        let direct = mesh.map_vertices(|v| v.component_mul(&scale));
        let props = direct.mass_properties();
        assert!((grain.volume - props.volume).abs() < 1e-14 * props.volume);
        assert!((grain.inertia - props.inertia.diagonal()).amax() < 1e-13 * props.inertia.amax());
        let far = direct.vertices().iter().map(|p| p.norm()).fold(0.0, f64::max);
        assert_eq!(grain.bounding_radius, far);
        let inner = (0..direct.triangles().len())
            .map(|k| {
                let [a, b, c] = direct.triangle(k);
                (b - a).cross(&(c - a)).normalize().dot(&a)
            })
            .fold(f64::INFINITY, f64::min);
        assert!((grain.inner_radius - inner).abs() < 1e-14, "{} vs {inner}", grain.inner_radius);
    }

    #[test]
    fn a_hull_folded_inward_by_rounding_errors_is_rebuilt_strictly_convex() {
        // Raising corner (1, −1, 1) off the top square by 1e-9 folds the square inward along
        // its diagonal: within the tolerance of scanned hulls, but not convex to rounding.
        let (mut v, t) = cube();
        v[5].z += 1e-9;
        let mesh = TriMesh::new(v, t).unwrap();
        assert!(mesh.is_convex(CONVEXITY_TOLERANCE) && !mesh.is_convex(STRICT_CONVEXITY));
        let shape = ConvexPolyhedron::new(&mesh).unwrap();
        let rebuilt = TriMesh::new(shape.vertices().to_vec(), shape.triangles().to_vec()).unwrap();
        assert!(rebuilt.is_convex(STRICT_CONVEXITY));
        // Climbing from every vertex in every direction reaches the true maximum.
        for d in [V3::new(0.1, 0.2, 1.0), V3::new(-0.3, 0.05, 1.0), V3::new(1.0, 1.0, 1.0), V3::new(-1.0, -1.0, 1e-3)] {
            let best = shape.vertices().iter().map(|p| p.dot(&d)).fold(f64::NEG_INFINITY, f64::max);
            for start in 0..shape.vertices().len() as u32 {
                assert_eq!(shape.vertices()[shape.climb(&d, start) as usize].dot(&d), best);
            }
        }
    }
}
