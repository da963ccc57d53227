//! The meshes a packing draws its grains from (§3.2): the two Rhine scans shipped with sedpack,
//! generated pebbles, or a user's folder, each simplified (§5.2.1) and normalised to unit
//! L, I, S (Fig. 5b).

use std::path::Path;

use serde::{Deserialize, Serialize};

use super::mesh::{MeshError, TriMesh};
use super::unit_mesh::UnitMesh;

/// The two Rhine gravel scans (convex hulls of CT scans, the example meshes of the paper's
/// software), embedded so that sedpack needs no files at run time.
pub fn rhine_meshes() -> Vec<(String, TriMesh)> {
    let files: [(&str, &[u8]); 2] = [
        ("rhine_scan_0.obj", include_bytes!("../../meshes/rhine_scan_0.obj")),
        ("rhine_scan_1.obj", include_bytes!("../../meshes/rhine_scan_1.obj")),
    ];
    files
        .iter()
        .map(|(name, bytes)| {
            let mesh = TriMesh::from_bytes(bytes, Path::new(name)).expect("the shipped Rhine meshes are valid");
            (name.to_string(), mesh)
        })
        .collect()
}

/// Every STL or OBJ file of a folder, in name order.
pub fn folder_meshes(folder: &Path) -> Result<Vec<(String, TriMesh)>, MeshError> {
    let entries = std::fs::read_dir(folder).map_err(|error| MeshError::Io { path: folder.into(), error })?;
    let mut paths: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| {
            p.extension()
                .and_then(|e| e.to_str())
                .is_some_and(|e| e.eq_ignore_ascii_case("stl") || e.eq_ignore_ascii_case("obj"))
        })
        .collect();
    paths.sort();
    paths.iter().map(|p| Ok((p.display().to_string(), TriMesh::from_file(p)?))).collect()
}

/// Normalised grain meshes with where they came from. Only the source, the face bound and the
/// digest are serialised: a stored job names its meshes and is run with the same ones.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeshLibrary {
    /// builtin:rhine, builtin:pebbles or a folder.
    pub source: String,
    /// Face bound of the simplification (§5.2.1, Table 4).
    pub faces: usize,
    /// Fingerprint of the normalised meshes.
    pub digest: String,
    #[serde(skip)]
    pub meshes: Vec<UnitMesh>,
}

impl PartialEq for MeshLibrary {
    fn eq(&self, other: &Self) -> bool {
        (&self.source, self.faces, &self.digest) == (&other.source, other.faces, &other.digest)
    }
}
