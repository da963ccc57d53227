//! Closed triangle meshes of grains: reading STL and OBJ, validation, and the rigid-body mass
//! properties (volume, centre of mass, inertia tensor) the mass-equivalent ellipsoid needs.

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use nalgebra::{Matrix3, Vector3};
use thiserror::Error;

/// A triangle whose area is below this fraction of the squared bounding-box diagonal counts as
/// degenerate: it has no normal, so the mesh cannot be a proper closed surface.
const DEGENERATE_AREA: f64 = 1e-14;

/// What is wrong with a mesh's geometry or topology.
#[derive(Debug, Error, PartialEq)]
pub enum MeshDefect {
    #[error("has no triangles")]
    Empty,
    #[error("has a non-finite vertex coordinate (vertex {0})")]
    NonFinite(usize),
    #[error("triangle {triangle} refers to vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange { triangle: usize, vertex: u32, count: usize },
    #[error("is not closed: {count} edge(s) belong to a single triangle, e.g. vertices {a}–{b}")]
    Open { count: usize, a: u32, b: u32 },
    #[error("is not a manifold surface: edge {a}–{b} belongs to {triangles} triangles")]
    NonManifold { a: u32, b: u32, triangles: usize },
    #[error("has inconsistently oriented triangles: edge {a}–{b} is traversed twice in the same direction")]
    InconsistentOrientation { a: u32, b: u32 },
    #[error("is degenerate: triangle {0} has (near) zero area")]
    DegenerateTriangle(usize),
    #[error("is degenerate: it encloses no volume")]
    ZeroVolume,
    #[error("has no convex hull: {0}")]
    Hull(String),
}

/// A mesh file that could not be used, with the file named.
#[derive(Debug, Error)]
pub enum MeshError {
    #[error("{}: {error}", path.display())]
    Io { path: PathBuf, error: std::io::Error },
    #[error("{}: line {line}: {message}", path.display())]
    Parse { path: PathBuf, line: usize, message: String },
    #[error("{}: unsupported mesh format (expected .stl or .obj)", path.display())]
    Format { path: PathBuf },
    #[error("{}: mesh {defect}", path.display())]
    Defect { path: PathBuf, defect: MeshDefect },
}

/// A closed, consistently oriented triangle mesh with outward normals.
#[derive(Debug, Clone, PartialEq)]
pub struct TriMesh {
    vertices: Vec<Vector3<f64>>,
    triangles: Vec<[u32; 3]>,
}

/// Volume, centre of mass and inertia tensor of a solid of unit density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MassProperties {
    pub volume: f64,
    pub center_of_mass: Vector3<f64>,
    /// Inertia tensor about the centre of mass, per unit density (multiply by ρ for kg m²).
    pub inertia: Matrix3<f64>,
}

impl TriMesh {
    /// Validates a mesh: closed, manifold, consistently oriented, without degenerate triangles,
    /// enclosing a volume. An inside-out mesh (all normals inward) is turned outward.
    pub fn new(vertices: Vec<Vector3<f64>>, triangles: Vec<[u32; 3]>) -> Result<Self, MeshDefect> {
        if triangles.is_empty() {
            return Err(MeshDefect::Empty);
        }
        if let Some(i) = vertices.iter().position(|v| !v.iter().all(|x| x.is_finite())) {
            return Err(MeshDefect::NonFinite(i));
        }
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&v) = tri.iter().find(|&&v| v as usize >= vertices.len()) {
                return Err(MeshDefect::IndexOutOfRange { triangle: t, vertex: v, count: vertices.len() });
            }
        }
        check_closed_and_oriented(&triangles)?;
        let mut mesh = Self { vertices, triangles };
        let diagonal2 = mesh.bounding_box_diagonal().powi(2);
        for t in 0..mesh.triangles.len() {
            let [a, b, c] = mesh.triangle(t);
            if 0.5 * (b - a).cross(&(c - a)).norm() <= DEGENERATE_AREA * diagonal2 {
                return Err(MeshDefect::DegenerateTriangle(t));
            }
        }
        let volume = mesh.mass_properties().volume;
        if volume.abs() <= DEGENERATE_AREA * diagonal2.powf(1.5) {
            return Err(MeshDefect::ZeroVolume);
        }
        if volume < 0.0 {
            for tri in &mut mesh.triangles {
                tri.swap(1, 2);
            }
        }
        Ok(mesh)
    }

    /// The convex hull of a point cloud (quickhull, through parry3d).
    pub fn convex_hull(points: &[Vector3<f64>]) -> Result<Self, MeshDefect> {
        let input: Vec<_> = points.iter().map(|p| parry3d_f64::math::Vector::new(p.x, p.y, p.z)).collect();
        let (vertices, triangles) =
            parry3d_f64::transformation::try_convex_hull(&input).map_err(|e| MeshDefect::Hull(format!("{e:?}")))?;
        Self::new(vertices.iter().map(|v| Vector3::new(v.x, v.y, v.z)).collect(), triangles)
    }

    /// Reads an STL (ASCII or binary) or OBJ file, chosen by extension.
    pub fn from_file(path: &Path) -> Result<Self, MeshError> {
        let bytes = std::fs::read(path).map_err(|error| MeshError::Io { path: path.into(), error })?;
        Self::from_bytes(&bytes, path)
    }

    /// Parses the bytes of an STL or OBJ file, the format chosen by the extension of `path`,
    /// which errors also name.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, MeshError> {
        let ext = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase);
        let (vertices, triangles) = match ext.as_deref() {
            Some("stl") => parse_stl(bytes),
            Some("obj") => parse_obj(bytes),
            _ => return Err(MeshError::Format { path: path.into() }),
        }
        .map_err(|(line, message)| MeshError::Parse { path: path.into(), line, message })?;
        Self::new(vertices, triangles).map_err(|defect| MeshError::Defect { path: path.into(), defect })
    }

    pub fn vertices(&self) -> &[Vector3<f64>] {
        &self.vertices
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    pub fn triangle(&self, t: usize) -> [Vector3<f64>; 3] {
        self.triangles[t].map(|v| self.vertices[v as usize])
    }

    /// Surface area: the triangles' areas summed.
    pub fn surface(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.triangle(t);
                0.5 * (b - a).cross(&(c - a)).norm()
            })
            .sum()
    }

    fn bounding_box_diagonal(&self) -> f64 {
        let mut lo = Vector3::repeat(f64::INFINITY);
        let mut hi = Vector3::repeat(f64::NEG_INFINITY);
        for v in &self.vertices {
            lo = lo.inf(v);
            hi = hi.sup(v);
        }
        (hi - lo).norm()
    }

    /// Exact mass properties of the enclosed solid (unit density), by summing signed tetrahedra
    /// spanned by each triangle and a reference point inside the vertex cloud.
    pub fn mass_properties(&self) -> MassProperties {
        let reference = self.vertices.iter().sum::<Vector3<f64>>() / self.vertices.len() as f64;
        let mut volume = 0.0;
        let mut first = Vector3::zeros();
        let mut second = Matrix3::zeros();
        for t in 0..self.triangles.len() {
            let [a, b, c] = self.triangle(t).map(|v| v - reference);
            let det = a.dot(&b.cross(&c));
            let sum = a + b + c;
            volume += det / 6.0;
            first += det / 24.0 * sum;
            // ∫ x xᵀ dV over the tetrahedron (0, a, b, c).
            second += det / 120.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + sum * sum.transpose());
        }
        let centroid = first / volume;
        let second_about_com = second - volume * centroid * centroid.transpose();
        let inertia = Matrix3::identity() * second_about_com.trace() - second_about_com;
        MassProperties { volume, center_of_mass: centroid + reference, inertia }
    }

    /// The same mesh with every vertex mapped by `f` (which must preserve orientation).
    pub fn map_vertices(&self, f: impl Fn(&Vector3<f64>) -> Vector3<f64>) -> Self {
        Self { vertices: self.vertices.iter().map(f).collect(), triangles: self.triangles.clone() }
    }

    /// Whether the solid is convex: no edge folds inward by more than `tolerance` times the
    /// bounding-box diagonal (the far vertex of each triangle's neighbour across an edge lies on or
    /// below the triangle's plane).
    ///
    /// A closed, connected surface that is locally convex at every edge bounds a convex solid, so
    /// the check is O(faces) rather than a comparison of every vertex with every face plane. The
    /// Euler characteristic V − E + F = 2 rules out several separate components (each closed
    /// locally convex component is a sphere and adds 2).
    pub fn is_convex(&self, tolerance: f64) -> bool {
        let mut used = vec![false; self.vertices.len()];
        for &v in self.triangles.iter().flatten() {
            used[v as usize] = true;
        }
        let (v, f) = (used.iter().filter(|&&u| u).count() as i64, self.triangles.len() as i64);
        if 2 * (v + f) - 3 * f != 4 {
            return false;
        }
        let slack = tolerance * self.bounding_box_diagonal();
        let mut apex: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * self.triangles.len());
        for tri in &self.triangles {
            for k in 0..3 {
                apex.insert((tri[k], tri[(k + 1) % 3]), tri[(k + 2) % 3]);
            }
        }
        (0..self.triangles.len()).all(|t| {
            let tri = self.triangles[t];
            let [a, b, c] = self.triangle(t);
            let normal = (b - a).cross(&(c - a)).normalize();
            (0..3).all(|k| {
                // The neighbour across edge (p, q) traverses it as (q, p).
                let far = apex[&(tri[(k + 1) % 3], tri[k])];
                normal.dot(&(self.vertices[far as usize] - a)) <= slack
            })
        })
    }
}

fn check_closed_and_oriented(triangles: &[[u32; 3]]) -> Result<(), MeshDefect> {
    let mut directed: HashMap<(u32, u32), usize> = HashMap::with_capacity(3 * triangles.len());
    for tri in triangles {
        for k in 0..3 {
            *directed.entry((tri[k], tri[(k + 1) % 3])).or_default() += 1;
        }
    }
    let mut open = Vec::new();
    for (&(a, b), &n) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if n + back > 2 {
            return Err(MeshDefect::NonManifold { a: a.min(b), b: a.max(b), triangles: n + back });
        }
        if n == 2 {
            return Err(MeshDefect::InconsistentOrientation { a, b });
        }
        if back == 0 {
            open.push((a.min(b), a.max(b)));
        }
    }
    if let Some(&(a, b)) = open.iter().min() {
        return Err(MeshDefect::Open { count: open.len(), a, b });
    }
    Ok(())
}

type Parsed = Result<(Vec<Vector3<f64>>, Vec<[u32; 3]>), (usize, String)>;

/// Merges bit-identical vertices, as STL stores every triangle's corners separately.
#[derive(Default)]
struct Welder {
    index: HashMap<[u64; 3], u32>,
    vertices: Vec<Vector3<f64>>,
}

impl Welder {
    fn add(&mut self, v: Vector3<f64>) -> u32 {
        // Adding 0.0 turns −0.0 into +0.0 so that the two weld together.
        let key = [v.x + 0.0, v.y + 0.0, v.z + 0.0].map(f64::to_bits);
        let next = self.vertices.len() as u32;
        *self.index.entry(key).or_insert_with(|| {
            self.vertices.push(v);
            next
        })
    }
}

fn parse_stl(bytes: &[u8]) -> Parsed {
    if bytes.len() >= 84 {
        let count = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as usize;
        if bytes.len() == 84 + 50 * count {
            return Ok(parse_binary_stl(&bytes[84..], count));
        }
    }
    if !bytes.trim_ascii_start().starts_with(b"solid") {
        return Err((
            1,
            "neither ASCII STL (no leading 'solid') nor binary STL (size does not match the triangle count)".into(),
        ));
    }
    let text = std::str::from_utf8(bytes).map_err(|e| (1, format!("ASCII STL is not valid UTF-8: {e}")))?;
    let mut welder = Welder::default();
    let mut corners = Vec::with_capacity(3);
    let mut triangles = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("vertex") => {
                let v = parse_coordinates(words, n + 1)?;
                corners.push(welder.add(v));
            }
            Some("endloop") => {
                if corners.len() != 3 {
                    return Err((n + 1, format!("facet has {} vertices, expected 3", corners.len())));
                }
                triangles.push([corners[0], corners[1], corners[2]]);
                corners.clear();
            }
            _ => {}
        }
    }
    Ok((welder.vertices, triangles))
}

fn parse_binary_stl(records: &[u8], count: usize) -> (Vec<Vector3<f64>>, Vec<[u32; 3]>) {
    let mut welder = Welder::default();
    let mut triangles = Vec::with_capacity(count);
    for record in records.chunks_exact(50) {
        let mut tri = [0u32; 3];
        for (k, corner) in tri.iter_mut().enumerate() {
            let at = 12 + 12 * k;
            let c = |j: usize| f32::from_le_bytes(record[at + 4 * j..at + 4 * j + 4].try_into().unwrap()) as f64;
            *corner = welder.add(Vector3::new(c(0), c(1), c(2)));
        }
        triangles.push(tri);
    }
    (welder.vertices, triangles)
}

fn parse_coordinates<'a>(
    mut words: impl Iterator<Item = &'a str>,
    line: usize,
) -> Result<Vector3<f64>, (usize, String)> {
    let mut c = [0.0; 3];
    for x in &mut c {
        let word = words.next().ok_or((line, "expected three coordinates".to_string()))?;
        *x = word.parse().map_err(|_| (line, format!("'{word}' is not a number")))?;
    }
    Ok(Vector3::from(c))
}

fn parse_obj(bytes: &[u8]) -> Parsed {
    let text = std::str::from_utf8(bytes).map_err(|e| (1, format!("OBJ is not valid UTF-8: {e}")))?;
    let mut vertices = Vec::new();
    let mut triangles = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => vertices.push(parse_coordinates(words, n + 1)?),
            Some("f") => {
                let mut corners = Vec::with_capacity(4);
                for word in words {
                    let index = word.split('/').next().unwrap_or("");
                    let i: i64 = index.parse().map_err(|_| (n + 1, format!("'{word}' is not a vertex index")))?;
                    // OBJ indices are 1-based; negative ones count back from the last vertex.
                    let resolved = if i > 0 { i - 1 } else { vertices.len() as i64 + i };
                    if i == 0 || resolved < 0 {
                        return Err((n + 1, format!("vertex index {i} is out of range")));
                    }
                    corners.push(resolved as u32);
                }
                if corners.len() < 3 {
                    return Err((n + 1, "a face needs at least 3 vertices".into()));
                }
                for k in 1..corners.len() - 1 {
                    triangles.push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    Ok((vertices, triangles))
}
