//! End-to-end tests of `sedpack forms`, `sample` and `predict`, running the built binary.

mod common;

use common::{fails, json, repo, sedpack};

#[test]
fn forms_lis_prints_table1_factors() {
    let v = json(&["forms", "--lis", "4", "2", "1", "--json"]);
    // By hand: FL = 1/2, EQ = 1/4, DRI = 2/3, OPI = 10(2/3 − 1/2)·4 = 20/3, D = sqrt(2.5).
    assert_eq!(v["FL"], 0.5);
    assert_eq!(v["EQ"], 0.25);
    assert!((v["DRI"].as_f64().unwrap() - 2.0 / 3.0).abs() < 1e-12);
    assert!((v["OPI"].as_f64().unwrap() - 20.0 / 3.0).abs() < 1e-12);
    assert!((v["inv_EQ"].as_f64().unwrap() - 4.0).abs() < 1e-12);
    assert!((v["D"].as_f64().unwrap() - 2.5f64.sqrt()).abs() < 1e-12);
    assert!((v["volume"].as_f64().unwrap() - std::f64::consts::PI * 8.0 / 6.0).abs() < 1e-12);
    let text = sedpack(&["forms", "--lis", "4", "2", "1"]);
    assert!(String::from_utf8_lossy(&text.stdout).contains("WFI"));
}

#[test]
fn forms_of_a_sphere_reports_undefined_factors_as_null_with_a_note() {
    let v = json(&["forms", "--lis", "1", "1", "1", "--json"]);
    assert!(v["DRI"].is_null() && v["OPI"].is_null() && v["inv_DRI"].is_null());
    let notes = v["notes"].as_array().unwrap();
    assert!(notes.iter().any(|n| n.as_str().unwrap().starts_with("DRI is undefined for L = S")));
}

#[test]
fn forms_mesh_gives_the_box_axes() {
    // A 3 × 2 × 1 box has L = 3 sqrt(5/3), I = 2 sqrt(5/3), S = sqrt(5/3) (Appendix A by hand).
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("box.obj");
    let mut obj = String::new();
    for k in 0..8 {
        let s = |bit: u32, a: f64| if k & (1 << bit) != 0 { a / 2.0 } else { -a / 2.0 };
        obj.push_str(&format!("v {} {} {}\n", s(0, 3.0), s(1, 2.0), s(2, 1.0)));
    }
    obj.push_str("f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
    std::fs::write(&path, obj).unwrap();
    let v = json(&["forms", "--mesh", path.to_str().unwrap(), "--json"]);
    let k = (5.0f64 / 3.0).sqrt();
    for (key, want) in [("L", 3.0 * k), ("I", 2.0 * k), ("S", k), ("volume", 6.0)] {
        assert!((v[key].as_f64().unwrap() - want).abs() < 1e-9, "{key}");
    }
    let rhine = json(&["forms", "--mesh", &repo("solver/meshes/rhine_scan_1.obj"), "--json"]);
    assert!(rhine["FL"].as_f64().unwrap() > 0.1 && rhine["EL"].as_f64().unwrap() <= 1.0);
}

#[test]
fn forms_library_gives_each_meshs_form_and_angularity_and_their_means() {
    // A folder with a 3 × 2 × 1 box and a unit cube, worked by hand: the box has FL = S/I = 1/2,
    // EL = I/L = 2/3 (its equivalent ellipsoid's axes are the box's times sqrt(5/3)); Wadell's
    // sphericity is π^(1/3) (6V)^(2/3) / A: V = 6, A = 22 for the box, V = 1, A = 6 for the cube,
    // whose equivalent ellipsoid is a sphere (sphericity 1), so its relative sphericity is its
    // own.
    let dir = tempfile::tempdir().unwrap();
    let write_box = |name: &str, a: [f64; 3]| {
        let mut obj = String::new();
        for k in 0..8 {
            let s = |bit: usize| if k & (1 << bit) != 0 { a[bit] / 2.0 } else { -a[bit] / 2.0 };
            obj.push_str(&format!("v {} {} {}\n", s(0), s(1), s(2)));
        }
        obj.push_str("f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
        std::fs::write(dir.path().join(name), obj).unwrap();
    };
    write_box("box.obj", [3.0, 2.0, 1.0]);
    write_box("cube.obj", [1.0, 1.0, 1.0]);
    let v = json(&["forms", "--library", dir.path().to_str().unwrap(), "--json"]);
    let wadell = |volume: f64, area: f64| std::f64::consts::PI.cbrt() * (6.0 * volume).powf(2.0 / 3.0) / area;
    let meshes = v["meshes"].as_array().unwrap();
    assert_eq!(meshes.len(), 2);
    let (boxed, cube) = (&meshes[0], &meshes[1]);
    assert_eq!(boxed["mesh"], "box.obj");
    assert_eq!(cube["triangles"], 12);
    let close = |x: &serde_json::Value, want: f64| (x.as_f64().unwrap() - want).abs() < 1e-9;
    assert!(close(&boxed["FL"], 0.5) && close(&boxed["EL"], 2.0 / 3.0));
    assert!(close(&boxed["sphericity"], wadell(6.0, 22.0)));
    assert!(close(&cube["sphericity"], wadell(1.0, 6.0)) && close(&cube["relative_sphericity"], wadell(1.0, 6.0)));
    assert!(close(&v["summary"]["sphericity"]["mean"], 0.5 * (wadell(6.0, 22.0) + wadell(1.0, 6.0))));
    // With the form removed a box is a cube: its largest facet is a sixth of its surface.
    assert!(close(&boxed["largest_facet"], 1.0 / 6.0) && close(&cube["largest_facet"], 1.0 / 6.0));
    // A cube's inertia-equivalent sphere has radius a with a²/5 = 1/12 (per unit mass, side 1):
    // its corners, √3/2 from the centre, lie 3/√5 radii out.
    let corner = 3.0 / 5f64.sqrt();
    assert!(close(&boxed["farthest_vertex"], corner) && close(&cube["farthest_vertex"], corner));
    assert!(close(&v["summary"]["FL"]["mean"], 0.75) && close(&v["summary"]["FL"]["std"], 0.5f64.sqrt() * 0.5));
    assert!(close(&v["table2"]["mu_FL"], 0.647));
    fails(&["forms", "--library", "no-such-folder"], &["--library no-such-folder", "folder of meshes"]);
    fails(&["forms", "--lis", "3", "2", "1", "--faces", "100"], &["--faces", "--mesh or a --library"]);
}

#[test]
fn forms_bonded_builds_the_rod_of_three_spheres() {
    // L = 3, I = S = 1 is a rod (I/L < 2/3, S/I > 2/3): a row of spheres of diameter
    // sqrt(S·I) = 1 spanning L, i.e. three touching unit spheres centred at −1, 0, 1 (§2.4);
    // volume 3·π/6 = π/2, like the ellipsoid π·3·1·1/6, and I_x = 3·(2/5)(π/6)(1/2)² = π/20.
    let v = json(&["forms", "--bonded", "3", "1", "1", "--json"]);
    assert_eq!(v["class"], "rod");
    let spheres = v["spheres"].as_array().unwrap();
    assert_eq!(spheres.len(), 3);
    let mut xs: Vec<f64> = spheres.iter().map(|s| s["center"][0].as_f64().unwrap()).collect();
    xs.sort_by(f64::total_cmp);
    for (x, want) in xs.iter().zip([-1.0, 0.0, 1.0]) {
        assert!((x - want).abs() < 1e-12);
    }
    let pi = std::f64::consts::PI;
    assert!((v["volume"].as_f64().unwrap() - pi / 2.0).abs() < 1e-12);
    assert!((v["ellipsoid"]["volume"].as_f64().unwrap() - pi / 2.0).abs() < 1e-12);
    assert!((v["inertia"][0].as_f64().unwrap() - pi / 20.0).abs() < 1e-12);
    fails(&["forms", "--bonded", "1", "2", "1"], &["--bonded", "L ≥ I ≥ S"]);
}

#[test]
fn forms_of_a_distribution_give_equancy_statistics() {
    let v = json(&[
        "forms",
        "--mu-fl",
        "0.647",
        "--sigma-fl",
        "0.175",
        "--mu-el",
        "0.682",
        "--sigma-el",
        "0.139",
        "--json",
    ]);
    // §7.3 by hand: μ_EQ = 0.682 · 0.647; σ_EQ² = (0.682² + 0.139²)(0.647² + 0.175²) − μ_EQ².
    let mu = 0.682 * 0.647;
    let sigma = ((0.682f64.powi(2) + 0.139f64.powi(2)) * (0.647f64.powi(2) + 0.175f64.powi(2)) - mu * mu).sqrt();
    assert!((v["mu_EQ"].as_f64().unwrap() - mu).abs() < 1e-12);
    assert!((v["sigma_EQ"].as_f64().unwrap() - sigma).abs() < 1e-12);
    // Redrawing outside [0.1, 1] lowers the mean flatness below its nominal value (§7.1).
    assert!(v["truncated"]["mean_FL"].as_f64().unwrap() < 0.647);
}

#[test]
fn sample_forms_matches_the_expected_truncated_moments() {
    let args = [
        "sample",
        "forms",
        "--mu-fl",
        "0.5",
        "--sigma-fl",
        "0.2",
        "--mu-el",
        "0.7",
        "--sigma-el",
        "0.15",
        "--count",
        "50000",
        "--seed",
        "4",
        "--json",
    ];
    let v = json(&args);
    for key in ["FL", "EL", "EQ"] {
        let got = v[format!("mean_{key}")].as_f64().unwrap();
        let want = v["expected"][format!("mean_{key}")].as_f64().unwrap();
        let sd = v["expected"][format!("std_{key}")].as_f64().unwrap();
        // 5 standard errors of the mean of 50,000 draws.
        assert!((got - want).abs() < 5.0 * sd / 50_000f64.sqrt(), "{key}: {got} vs {want}");
    }
    assert_eq!(v, json(&args), "same seed, same sample");
}

#[test]
fn sample_sizes_reproduces_mass_fractions_of_a_case_and_of_a_file() {
    let v = json(&["sample", "sizes", "--case", "B50", "--count", "200000", "--seed", "9", "--json"]);
    let sampled = v["mass_fractions"].as_array().unwrap();
    let prescribed = [0.13, 0.21, 0.13, 0.06, 0.13, 0.21, 0.13];
    assert_eq!(sampled.len(), 7);
    for (s, p) in sampled.iter().zip(prescribed) {
        assert!((s.as_f64().unwrap() - p).abs() < 0.012, "{s} vs {p}");
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("curve.yaml");
    std::fs::write(&path, "sieves: [0.001, 0.002, 0.004]\nfractions: [0.3, 0.7]\n").unwrap();
    let v = json(&["sample", "sizes", "--sieves", path.to_str().unwrap(), "--count", "100000", "--json"]);
    let f = v["mass_fractions"].as_array().unwrap();
    assert!((f[0].as_f64().unwrap() - 0.3).abs() < 0.01 && (f[1].as_f64().unwrap() - 0.7).abs() < 0.01);

    std::fs::write(&path, "sieves: [0.001, 0.002, 0.004]\nfractions: [0.3, 0.6]\n").unwrap();
    fails(
        &["sample", "sizes", "--sieves", path.to_str().unwrap(), "--count", "10"],
        &["curve.yaml", "fractions", "sum to 0.899"],
    );
    std::fs::write(&path, "sieves: [0.001, 0.004, 0.002]\nfractions: [0.3, 0.7]\n").unwrap();
    fails(
        &["sample", "sizes", "--sieves", path.to_str().unwrap(), "--count", "10"],
        &["curve.yaml", "strictly increasing"],
    );
    std::fs::write(&path, "sieves: [0.001, 0.002]\nfraction: [1.0]\n").unwrap();
    fails(&["sample", "sizes", "--sieves", path.to_str().unwrap(), "--count", "10"], &["curve.yaml", "fraction"]);
}

#[test]
fn predict_reproduces_table_11() {
    let rhine = ["--mu-fl", "0.647", "--sigma-fl", "0.175", "--mu-el", "0.682", "--sigma-el", "0.139", "--json"];
    // Eqs. 23 and 24 applied by hand to the Rhine distribution give 0.35584 and 0.28370.
    let u1 = json(&[&["predict", "--model", "paper-U1"][..], &rhine].concat());
    assert!((u1["porosity"].as_f64().unwrap() - 0.3558).abs() < 5e-5);
    let u7 = json(&[&["predict", "--model", "paper-U7"][..], &rhine].concat());
    assert!((u7["porosity"].as_f64().unwrap() - 0.2837).abs() < 5e-5);
    assert!(u1["warnings"].as_array().unwrap().is_empty());
    // Eq. 17 by hand for FL = 0.5, EL = 0.8: 0.019/(0.4) + 0.014/0.8 + 0.278 = 0.343.
    let sf = json(&["predict", "--model", "paper-sf-U1", "--fl", "0.5", "--el", "0.8", "--json"]);
    assert!((sf["porosity"].as_f64().unwrap() - 0.343).abs() < 1e-12);
    let outside = json(&[
        "predict",
        "--model",
        "paper-U1",
        "--mu-fl",
        "0.95",
        "--sigma-fl",
        "0.1",
        "--mu-el",
        "0.7",
        "--sigma-el",
        "0.1",
        "--json",
    ]);
    assert!(outside["warnings"][0].as_str().unwrap().contains("mu_fl"));
}

#[test]
fn bad_input_gives_one_clear_line_and_a_failure_code() {
    fails(&["forms", "--lis", "1", "2", "0.5"], &["L ≥ I ≥ S"]);
    fails(&["forms", "--mesh", "/no/such/grain.stl"], &["/no/such/grain.stl", "No such file"]);
    fails(
        &["forms", "--mu-fl", "0.6", "--sigma-fl", "-0.1", "--mu-el", "0.7", "--sigma-el", "0.1"],
        &["sigma_fl", "-0.1"],
    );
    fails(&["forms", "--mu-fl", "1.3", "--sigma-fl", "0.1", "--mu-el", "0.7", "--sigma-el", "0.1"], &["mu_fl", "1.3"]);
    fails(&["predict", "--model", "paper-sf-U7", "--fl", "1.2", "--el", "0.5"], &["--fl", "1.2"]);
    fails(&["predict", "--model", "nonsense", "--fl", "0.5", "--el", "0.5"], &["nonsense", "paper-U1"]);
    fails(&["sample", "sizes", "--case", "U2", "--count", "5"], &["U2"]);
    let dir = tempfile::tempdir().unwrap();
    let open = dir.path().join("open.obj");
    std::fs::write(&open, "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\n").unwrap();
    fails(&["forms", "--mesh", open.to_str().unwrap()], &["open.obj", "not closed"]);
}
