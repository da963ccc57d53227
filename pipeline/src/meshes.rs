//! Mesh libraries of job files (`grains.meshes`, `grains.faces`): the shipped Rhine scans,
//! generated pebbles or a folder of STL/OBJ files, made convex, simplified to at most n_F faces
//! (§5.2.1) and normalised to unit L, I, S (Fig. 5b), with a digest that pins a stored job to
//! the meshes it was submitted with.

use std::path::Path;

use anyhow::{Context, anyhow};
use sha2::{Digest, Sha256};
use solver::grain::pebble::pebble_library;
use solver::grain::simplify::{DEFAULT_MAX_FACES, simplify};
use solver::grain::{MeshLibrary, TriMesh, UnitMesh, folder_meshes, rhine_meshes};

pub const RHINE: &str = "builtin:rhine";
pub const PEBBLES: &str = "builtin:pebbles";
/// Pebbles in `builtin:pebbles`, generated from seed 1.
const PEBBLE_COUNT: usize = 20;

/// Whether a library is one shipped with sedpack rather than a folder.
pub fn is_builtin(source: &str) -> bool {
    [RHINE, PEBBLES].contains(&source)
}

/// Loads and prepares a library. A folder is given relative to `base` (the job file's folder)
/// and stored as an absolute path.
pub fn load(source: &str, faces: usize, base: &Path) -> anyhow::Result<MeshLibrary> {
    let source = match source {
        RHINE | PEBBLES => source.to_string(),
        folder => {
            let path = base.join(folder);
            let path = path.canonicalize().with_context(|| format!("{}", path.display()))?;
            path.display().to_string()
        }
    };
    let meshes = prepare(&source, faces)?;
    Ok(MeshLibrary { digest: digest(&meshes), source, faces, meshes })
}

/// Fills in the meshes of a library read back from the store and checks they are the same.
pub fn reload(library: &mut MeshLibrary) -> anyhow::Result<()> {
    let meshes = prepare(&library.source, library.faces)
        .with_context(|| format!("grains.meshes: the meshes of {} cannot be read", library.source))?;
    if digest(&meshes) != library.digest {
        return Err(anyhow!("{}: the meshes changed since the job was submitted", library.source));
    }
    library.meshes = meshes;
    Ok(())
}

fn prepare(source: &str, faces: usize) -> anyhow::Result<Vec<UnitMesh>> {
    let named: Vec<(String, TriMesh)> = match source {
        RHINE => rhine_meshes(),
        PEBBLES => pebble_library(PEBBLE_COUNT, 1, faces.min(DEFAULT_MAX_FACES))
            .map_err(|e| anyhow!("{PEBBLES}: a pebble mesh {e}"))?
            .into_iter()
            .enumerate()
            .map(|(k, m)| (format!("pebble {k}"), m))
            .collect(),
        folder => folder_meshes(Path::new(folder))?,
    };
    if named.is_empty() {
        return Err(anyhow!("{source}: no STL or OBJ meshes in this folder"));
    }
    named
        .into_iter()
        .map(|(name, mesh)| {
            // Grains are convex polyhedra; the paper took convex hulls of its scans too (§2.2).
            let convex = if mesh.is_convex(solver::grain::simplify::CONVEXITY_TOLERANCE) {
                mesh
            } else {
                eprintln!("sedpack: warning: {name}: the mesh is not convex; using its convex hull (§2.2)");
                TriMesh::convex_hull(mesh.vertices()).map_err(|e| anyhow!("{name}: convex hull {e}"))?
            };
            let simplified = simplify(&convex, faces).with_context(|| name.clone())?;
            UnitMesh::new(&simplified.mesh).with_context(|| name.clone())
        })
        .collect()
}

/// SHA-256 of the normalised meshes: vertices, triangles and own forms, in order.
fn digest(meshes: &[UnitMesh]) -> String {
    let mut hash = Sha256::new();
    for m in meshes {
        for v in m.mesh().vertices() {
            for c in v.iter() {
                hash.update(c.to_le_bytes());
            }
        }
        for t in m.mesh().triangles() {
            for i in t {
                hash.update(i.to_le_bytes());
            }
        }
        let f = m.original_form();
        for c in [f.l, f.i, f.s] {
            hash.update(c.to_le_bytes());
        }
    }
    hash.finalize().iter().take(16).map(|b| format!("{b:02x}")).collect()
}
