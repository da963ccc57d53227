//! Mesh reading and validation, mass properties and the mass-equivalent ellipsoid (Appendix A).

mod common;

use common::{box_mesh, ellipsoid_mesh, rhine_mesh_path};
use nalgebra::{Rotation3, Vector3};
use solver::grain::{EquivalentEllipsoid, MeshDefect, MeshError, TriMesh, UnitMesh};

fn form_of(mesh: &TriMesh) -> [f64; 3] {
    let f = EquivalentEllipsoid::of(&mesh.mass_properties()).form().unwrap();
    [f.l, f.i, f.s]
}

#[test]
fn box_gives_l_equal_side_times_sqrt_5_over_3() {
    // A box of sides A ≥ B ≥ C and mass m has I_x = m(B² + C²)/12, so −I_x + I_y + I_z = m A²/6
    // and Eq. 25 gives a² = 5A²/12: L = 2a = A sqrt(5/3), likewise I = B sqrt(5/3), S = C sqrt(5/3).
    let (a, b, c) = (3.0, 2.0, 0.5);
    let (v, t) = box_mesh(a, b, c);
    let mesh = TriMesh::new(v, t).unwrap();
    let props = mesh.mass_properties();
    assert!((props.volume - a * b * c).abs() < 1e-12);
    assert!(props.center_of_mass.norm() < 1e-12);
    let k = (5.0f64 / 3.0).sqrt();
    let [l, i, s] = form_of(&mesh);
    for (got, want) in [(l, a * k), (i, b * k), (s, c * k)] {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
}

#[test]
fn mass_properties_are_invariant_to_rotation_and_translation() {
    let mesh = TriMesh::from_file(&rhine_mesh_path(0)).unwrap();
    let reference = form_of(&mesh);
    let volume = mesh.mass_properties().volume;
    for (axis, angle, shift) in [
        (Vector3::new(1.0, 2.0, 3.0), 0.7, Vector3::new(10.0, -3.0, 2.0)),
        (Vector3::new(-0.3, 0.1, 1.0), 2.9, Vector3::new(-1e3, 5e2, 1.0)),
    ] {
        let rotation = Rotation3::from_scaled_axis(axis.normalize() * angle);
        let moved = mesh.map_vertices(|v| rotation * v + shift);
        let props = moved.mass_properties();
        assert!((props.volume - volume).abs() < 1e-9 * volume);
        let expected_com = rotation * mesh.mass_properties().center_of_mass + shift;
        assert!((props.center_of_mass - expected_com).norm() < 1e-9 * shift.norm().max(1.0));
        for (got, want) in form_of(&moved).iter().zip(reference) {
            assert!((got - want).abs() < 1e-9 * want, "{got} vs {want}");
        }
    }
}

#[test]
fn refined_ellipsoid_mesh_converges_to_its_axes() {
    // Inscribed polyhedra approach the ellipsoid (3, 2, 1) at second order in the mesh spacing.
    let mut previous = f64::INFINITY;
    for rings in [8, 16, 32, 64, 128] {
        let (v, t) = ellipsoid_mesh(3.0, 2.0, 1.0, rings);
        let form = form_of(&TriMesh::new(v, t).unwrap());
        let error = form.iter().zip([6.0, 4.0, 2.0]).map(|(g, w)| ((g - w) / w).abs()).fold(0.0, f64::max);
        assert!(error < previous, "{rings} rings: error {error} did not decrease from {previous}");
        previous = error;
    }
    assert!(previous < 2e-4, "finest relative error {previous}");
}

/// Second moments of a convex mesh by sampling a regular grid of points inside it: an
/// independent (and much cruder) route to the mass-equivalent ellipsoid.
fn voxel_form(mesh: &TriMesh, n: usize) -> [f64; 3] {
    let planes: Vec<(Vector3<f64>, f64)> = (0..mesh.triangles().len())
        .map(|t| {
            let [a, b, c] = mesh.triangle(t);
            let normal = (b - a).cross(&(c - a)).normalize();
            (normal, normal.dot(&a))
        })
        .collect();
    let (mut lo, mut hi) = (Vector3::repeat(f64::INFINITY), Vector3::repeat(f64::NEG_INFINITY));
    for v in mesh.vertices() {
        lo = lo.inf(v);
        hi = hi.sup(v);
    }
    let h = (hi - lo) / n as f64;
    let mut points = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let p = lo + Vector3::new((i as f64 + 0.5) * h.x, (j as f64 + 0.5) * h.y, (k as f64 + 0.5) * h.z);
                if planes.iter().all(|(normal, d)| normal.dot(&p) <= *d) {
                    points.push(p);
                }
            }
        }
    }
    let count = points.len() as f64;
    let mean = points.iter().sum::<Vector3<f64>>() / count;
    let mut cov = nalgebra::Matrix3::zeros();
    for p in &points {
        cov += (p - mean) * (p - mean).transpose() / count;
    }
    // For an ellipsoid of semi-axis a the variance along it is a²/5, the same as Eqs. 25–27.
    let mut eig: Vec<f64> = cov.symmetric_eigenvalues().iter().map(|v| 2.0 * (5.0 * v).sqrt()).collect();
    eig.sort_by(|a, b| b.total_cmp(a));
    [eig[0], eig[1], eig[2]]
}

#[test]
fn rhine_meshes_load_and_match_an_independent_voxel_estimate() {
    for k in 0..2 {
        let mesh = TriMesh::from_file(&rhine_mesh_path(k)).unwrap();
        let exact = form_of(&mesh);
        let voxels = voxel_form(&mesh, 120);
        // 120³ cells: the voxel estimate of each axis is good to a few tenths of a percent.
        for (e, v) in exact.iter().zip(voxels) {
            assert!(((e - v) / e).abs() < 5e-3, "mesh {k}: exact {e} vs voxel {v}");
        }
        assert!(exact[0] >= exact[1] && exact[1] >= exact[2]);
    }
}

#[test]
fn unit_mesh_has_unit_form_and_rescales_exactly() {
    let mesh = TriMesh::from_file(&rhine_mesh_path(1)).unwrap();
    let unit = UnitMesh::new(&mesh).unwrap();
    let props = unit.mesh().mass_properties();
    assert!(props.center_of_mass.norm() < 1e-12);
    for (r, c) in [(0, 1), (0, 2), (1, 2)] {
        assert!(props.inertia[(r, c)].abs() < 1e-12 * props.inertia.trace(), "principal axes along x, y, z");
    }
    for got in form_of(unit.mesh()) {
        assert!((got - 1.0).abs() < 1e-10);
    }
    let target = solver::grain::FormParameters::new(0.03, 0.02, 0.007).unwrap();
    let [l, i, s] = form_of(&unit.rescaled(&target));
    assert!((l - 0.03).abs() < 1e-12 && (i - 0.02).abs() < 1e-12 && (s - 0.007).abs() < 1e-12);
    assert_eq!(unit.original_form().l, form_of(&mesh)[0]);
}

#[test]
fn defective_meshes_are_refused_with_their_defect() {
    let (v, mut t) = box_mesh(1.0, 1.0, 1.0);
    t.pop();
    assert!(matches!(TriMesh::new(v.clone(), t), Err(MeshDefect::Open { count: 3, .. })));

    let (_, mut t) = box_mesh(1.0, 1.0, 1.0);
    t[3].swap(0, 1);
    assert!(matches!(TriMesh::new(v.clone(), t), Err(MeshDefect::InconsistentOrientation { .. })));

    let (_, mut t) = box_mesh(1.0, 1.0, 1.0);
    let extra = t[0];
    t.push([extra[0], extra[2], extra[1]]);
    t.push(extra);
    assert!(matches!(TriMesh::new(v.clone(), t), Err(MeshDefect::NonManifold { .. })));

    // A flat "box" of zero height has zero-area side triangles.
    let (flat, t) = box_mesh(1.0, 1.0, 0.0);
    assert!(matches!(TriMesh::new(flat, t), Err(MeshDefect::DegenerateTriangle(_))));

    let (_, mut t) = box_mesh(1.0, 1.0, 1.0);
    t[0][1] = 99;
    assert!(matches!(TriMesh::new(v.clone(), t), Err(MeshDefect::IndexOutOfRange { vertex: 99, .. })));

    // Inside-out is not a defect: the mesh is turned outward.
    let (_, mut t) = box_mesh(2.0, 1.0, 1.0);
    t.iter_mut().for_each(|tri| tri.swap(1, 2));
    let (v2, _) = box_mesh(2.0, 1.0, 1.0);
    assert!((TriMesh::new(v2, t).unwrap().mass_properties().volume - 2.0).abs() < 1e-12);
}

fn write(dir: &tempfile::TempDir, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let path = dir.path().join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

#[test]
fn stl_ascii_binary_and_obj_files_read_the_same_solid() {
    let dir = tempfile::tempdir().unwrap();
    let (v, t) = box_mesh(3.0, 2.0, 1.0);
    let mut ascii = String::from("solid box\n");
    let mut binary = vec![0u8; 80];
    binary.extend_from_slice(&(t.len() as u32).to_le_bytes());
    for tri in &t {
        ascii.push_str("  facet normal 0 0 0\n    outer loop\n");
        binary.extend_from_slice(&[0u8; 12]);
        for &k in tri {
            let p = v[k as usize];
            ascii.push_str(&format!("      vertex {} {} {}\n", p.x, p.y, p.z));
            for x in [p.x, p.y, p.z] {
                binary.extend_from_slice(&(x as f32).to_le_bytes());
            }
        }
        ascii.push_str("    endloop\n  endfacet\n");
        binary.extend_from_slice(&[0u8; 2]);
    }
    ascii.push_str("endsolid box\n");
    // OBJ with quads, "v//n" references and negative (relative) indices.
    let mut obj = String::from("# box\n");
    for p in &v {
        obj.push_str(&format!("v {} {} {}\n", p.x, p.y, p.z));
    }
    obj.push_str("vn 0 0 1\n");
    for f in [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2]] {
        obj.push_str(&format!("f {}//1 {}//1 {}//1 {}//1\n", f[0] + 1, f[1] + 1, f[2] + 1, f[3] + 1));
    }
    obj.push_str("f -7 -5 -1 -3\n"); // vertices 1, 3, 7, 5 (0-based) counted back from 8
    for path in [
        write(&dir, "box.stl", ascii.as_bytes()),
        write(&dir, "box_binary.STL", &binary),
        write(&dir, "box.obj", obj.as_bytes()),
    ] {
        let mesh = TriMesh::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(mesh.vertices().len(), 8, "{}", path.display());
        assert!((mesh.mass_properties().volume - 6.0).abs() < 1e-9, "{}", path.display());
    }
}

#[test]
fn file_errors_name_the_file_and_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nothing.stl");
    let e = TriMesh::from_file(&missing).unwrap_err();
    assert!(matches!(e, MeshError::Io { .. }) && e.to_string().contains("nothing.stl"));

    let bad = write(&dir, "bad.obj", b"v 0 0 0\nv 1 0 x\n");
    let e = TriMesh::from_file(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.obj") && e.contains("line 2") && e.contains("'x'"), "{e}");

    let open = write(&dir, "open.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\n");
    let e = TriMesh::from_file(&open).unwrap_err().to_string();
    assert!(e.contains("open.obj") && e.contains("not closed"), "{e}");

    let e = TriMesh::from_file(&write(&dir, "grain.ply", b"ply")).unwrap_err().to_string();
    assert!(e.contains("unsupported mesh format"), "{e}");
}
