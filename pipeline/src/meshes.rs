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
    let source = resolve(source, base)?;
    let meshes = unnamed(prepare(&source, faces)?);
    Ok(MeshLibrary { digest: digest(&meshes), source, faces, meshes })
}

/// A library's source as it is stored: a builtin name, or a folder (relative to `base`) as an
/// absolute path.
pub fn resolve(source: &str, base: &Path) -> anyhow::Result<String> {
    Ok(match source {
        RHINE | PEBBLES => source.to_string(),
        folder => {
            let path = base.join(folder);
            let path = path.canonicalize().with_context(|| format!("{}", path.display()))?;
            path.display().to_string()
        }
    })
}

/// Fills in the meshes of a library read back from the store and checks they are the same.
pub fn reload(library: &mut MeshLibrary) -> anyhow::Result<()> {
    let meshes = unnamed(
        prepare(&library.source, library.faces)
            .with_context(|| format!("grains.meshes: the meshes of {} cannot be read", library.source))?,
    );
    if digest(&meshes) != library.digest {
        if is_builtin(&library.source) {
            return Err(anyhow!(
                "{}: this sedpack's built-in meshes differ from those the job was submitted with; finish it with the sedpack that submitted it",
                library.source
            ));
        }
        return Err(anyhow!("{}: the meshes changed since the job was submitted", library.source));
    }
    library.meshes = meshes;
    Ok(())
}

/// The meshes of a library (its source as [`load`] stores it), made convex, simplified and
/// normalised, with their names.
pub fn prepare(source: &str, faces: usize) -> anyhow::Result<Vec<(String, UnitMesh)>> {
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
            let unit = UnitMesh::new(&simplified.mesh).with_context(|| name.clone())?;
            Ok((name, unit))
        })
        .collect()
}

/// The meshes without their names, as a library keeps them.
fn unnamed(named: Vec<(String, UnitMesh)>) -> Vec<UnitMesh> {
    named.into_iter().map(|(_, mesh)| mesh).collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stored_library_whose_meshes_changed_is_refused_with_what_to_do() {
        let mut stored = load(RHINE, 100, Path::new(".")).unwrap();
        reload(&mut stored).unwrap();
        // A digest from another version of the built-in meshes (the pebbles of 0.1.0).
        stored.digest = "11f3cc3136ba87d4f2dd5e5e84891773".into();
        let error = format!("{:#}", reload(&mut stored).unwrap_err());
        assert!(error.contains("builtin:rhine") && error.contains("the sedpack that submitted it"), "{error}");
        let folder = tempfile::tempdir().unwrap();
        let (_, scan) = &rhine_meshes()[1];
        let obj: String = scan.vertices().iter().map(|v| format!("v {} {} {}\n", v.x, v.y, v.z)).collect::<String>()
            + &scan
                .triangles()
                .iter()
                .map(|t| format!("f {} {} {}\n", t[0] + 1, t[1] + 1, t[2] + 1))
                .collect::<String>();
        std::fs::write(folder.path().join("grain.obj"), &obj).unwrap();
        let mut stored = load(folder.path().to_str().unwrap(), 100, Path::new(".")).unwrap();
        // A second file in the folder since.
        std::fs::write(folder.path().join("other.obj"), &obj).unwrap();
        let error = format!("{:#}", reload(&mut stored).unwrap_err());
        assert!(error.contains("the meshes changed since the job was submitted"), "{error}");
    }
}
