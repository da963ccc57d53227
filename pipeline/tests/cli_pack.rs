//! End-to-end tests of `sedpack pack` and `sedpack porosity`, running the built binary.

mod common;

use common::{fails, sedpack, write};
use serde_json::Value;

const SMALL_BED: &str = "name: small
domain: {kind: periodic, width: 0.04, height: 0.15}
grains:
  shape: sphere
  size: {sieves: [0.0056, 0.008], fractions: [1.0]}
  mass: 0.1
process:
  generation: {spacing: 0.009}
  shaking: {duration: 0.2}
experiment: {porosity: 0.4, std: 0.01}
";

#[test]
fn pack_writes_consistent_outputs_that_the_porosity_command_confirms() {
    let dir = tempfile::tempdir().unwrap();
    let job = write(dir.path(), "small.yaml", SMALL_BED);
    let out = dir.path().join("out");
    let run = sedpack(&["pack", &job, "--out", out.to_str().unwrap(), "--json"]);
    assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
    // 0.1 kg over 0.04 m × 0.04 m is a bed of ~39 mm at porosity 0.4, above the 2 × 8 mm trims.
    assert!(!String::from_utf8_lossy(&run.stderr).contains("warning"), "{}", String::from_utf8_lossy(&run.stderr));
    let printed: Value = serde_json::from_slice(&run.stdout).unwrap();
    let file: Value = serde_json::from_str(&std::fs::read_to_string(out.join("result.json")).unwrap()).unwrap();
    assert_eq!(printed, file);
    let n = file["porosity"].as_f64().unwrap();
    assert!((0.3..0.5).contains(&n), "porosity {n}");
    assert_eq!(file["experiment"]["porosity"], 0.4);
    assert!(file["statistics"]["mean_FL"] == 1.0 && file["statistics"]["std_EL"] == 0.0, "spheres: FL = EL = 1");
    // One sieve class, holding every grain and all the mass created: the 0.1 kg asked, passed by
    // less than the last grain drawn (at most an 8 mm sphere, 0.71 g).
    let classes = file["size_classes"].as_array().unwrap();
    assert_eq!(classes.len(), 1);
    assert_eq!((classes[0]["lower"].as_f64(), classes[0]["asked"].as_f64()), (Some(0.0056), Some(1.0)));
    assert_eq!(classes[0]["grains"], file["particles"]);
    assert!((0.1..0.1 + 7.2e-4).contains(&classes[0]["mass"].as_f64().unwrap()), "{classes:?}");

    // particles.csv → x,y,z,r → `sedpack porosity` with the pack's trim (the largest sieve,
    // 8 mm) must give the same bulk porosity: the evaluation is one rule (§4.4) from two inputs.
    let particles = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    let mut lines = particles.lines();
    assert_eq!(lines.next().unwrap(), "id,shape,x,y,z,qw,qx,qy,qz,a,b,c,D,volume");
    let mut xyzr = String::from("x,y,z,r\n");
    let mut count = 0;
    for line in lines {
        let f: Vec<&str> = line.split(',').collect();
        xyzr.push_str(&format!("{},{},{},{}\n", f[2], f[3], f[4], f[9]));
        count += 1;
    }
    assert_eq!(count, file["particles"].as_u64().unwrap());
    let csv = write(dir.path(), "xyzr.csv", &xyzr);
    let check = sedpack(&["porosity", &csv, "--width", "0.04", "--slice", "0.001", "--trim", "0.008", "--json"]);
    assert!(check.status.success(), "{}", String::from_utf8_lossy(&check.stderr));
    let check: Value = serde_json::from_slice(&check.stdout).unwrap();
    assert!((check["bulk_porosity"].as_f64().unwrap() - n).abs() < 1e-12);
    assert_eq!(check["z_plus"], file["z_plus"]);

    let profile = std::fs::read_to_string(out.join("profile.csv")).unwrap();
    assert_eq!(profile.lines().next(), Some("z,n"));
    assert_eq!(profile.lines().count() - 1, file["profile"].as_array().unwrap().len());
    let vtk = std::fs::read(out.join("packing.vtk")).unwrap();
    assert!(vtk.starts_with(b"# vtk DataFile Version 3.0\n"));
}

#[test]
fn a_bed_too_thin_for_its_trims_is_announced_before_it_is_packed() {
    // 20 g of 5.6–8 mm spheres over 0.04 m × 0.04 m: a bed of 0.02 / (2650 × 0.0016 × 0.6) =
    // 7.9 mm at porosity 0.4, under the two trims of 8 mm (the largest sieve). The warning
    // comes first, and the packing still ends with the evaluation's error.
    let dir = tempfile::tempdir().unwrap();
    let job = write(dir.path(), "thin.yaml", &SMALL_BED.replace("mass: 0.1", "mass: 0.02"));
    let run = sedpack(&["pack", &job, "--out", dir.path().join("out").to_str().unwrap()]);
    assert!(!run.status.success());
    let stderr = String::from_utf8_lossy(&run.stderr);
    let warning = stderr.find("sedpack: warning: ").expect("a warning");
    let error = stderr.find("too thin for the trim of 0.008 m").expect("the evaluation's error");
    assert!(warning < error, "{stderr}");
    for part in ["thin.yaml", "about 0.0079 m high", "evaluation.trim = 0.008 m (the largest sieve"] {
        assert!(stderr[warning..error].contains(part), "{part}: {stderr}");
    }
}

#[test]
fn bad_job_files_name_the_file_line_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let unknown = write(dir.path(), "unknown.yaml", "domain:\n  kind: periodic\n  widht: 0.05\n");
    fails(&["pack", &unknown], &["unknown.yaml:3", "domain", "widht"]);
    let range = write(
        dir.path(),
        "range.yaml",
        "grains:\n  shape: ellipsoid\n  form: {mu_fl: 0.6, sigma_fl: -0.2, mu_el: 0.7, sigma_el: 0.1}\n",
    );
    fails(&["pack", &range], &["range.yaml:3", "grains.form", "sigma_fl"]);
    let mass = write(dir.path(), "mass.yaml", "grains:\n  mass: -2\n");
    fails(&["pack", &mass], &["mass.yaml:2", "grains.mass", "-2"]);
    let wrong = write(dir.path(), "wrong.yaml", "seed: many\n");
    fails(&["pack", &wrong], &["wrong.yaml:1", "seed"]);
    let point = write(dir.path(), "point.yaml", "solver:\n  contact_point: epa\n");
    fails(&["pack", &point], &["point.yaml:2", "contact_point", "centre-of-pressure", "witness"]);
    let lying = write(dir.path(), "lying.yaml", "process:\n  generation:\n    orientation: flat\n");
    fails(&["pack", &lying], &["lying.yaml:3", "orientation", "random", "upright"]);
    let grid = write(dir.path(), "grid.yaml", "process:\n  generation:\n    grid: hexagonal\n");
    fails(&["pack", &grid], &["grid.yaml:3", "grid", "cubic", "hcp"]);
    let step = write(dir.path(), "step.yaml", "solver: {time_step: 1.0e-4}\n");
    fails(&["pack", &step], &["step.yaml:1", "solver.time_step", "collision_time / 10"]);
    let case = write(dir.path(), "case.yaml", "grains: {size: U4}\n");
    fails(&["pack", &case], &["case.yaml:1", "grains.size", "U4"]);
    let grid = write(dir.path(), "grid.yaml", "grid:\n  seed: [1, 2]\n");
    fails(&["pack", &grid], &["grid.yaml:1", "sedpack run"]);
    let spheres = write(dir.path(), "spheres.yaml", "grains: {shape: sphere, form: {fl: 0.5, el: 0.5}}\n");
    fails(&["pack", &spheres], &["grains.form", "spheres"]);
    // A grid slot narrower than the smallest grain, or a negative spread of a measurement.
    let spacing = write(dir.path(), "spacing.yaml", "process:\n  generation: {spacing: 1.0e-9}\n");
    fails(&["pack", &spacing], &["spacing.yaml:2", "process.generation.spacing", "smallest sieve"]);
    let std = write(dir.path(), "std.yaml", "experiment: {porosity: 0.35, std: -0.01}\n");
    fails(&["pack", &std], &["std.yaml:1", "experiment.std"]);
    // Fluid keys: only with drag on; a coupling shorter than the time step; a flow's keys.
    let dry = write(dir.path(), "dry.yaml", "fluid:\n  coupling: 1.0e-4\n");
    fails(&["pack", &dry], &["dry.yaml:2", "fluid.coupling", "process.fluid: drag"]);
    let coupling = write(dir.path(), "coupling.yaml", "process: {fluid: drag}\nfluid:\n  coupling: 1.0e-7\n");
    fails(&["pack", &coupling], &["coupling.yaml", "fluid.coupling", "solver.time_step"]);
    let flow = write(
        dir.path(),
        "flow.yaml",
        "process: {fluid: drag}\nfluid:\n  flow: {kind: logarithmic, roughness: 1.0e-4}\n",
    );
    fails(&["pack", &flow], &["flow.yaml:3", "fluid.flow.shear_velocity", "required"]);
    fails(&["pack", "/no/such/job.yaml"], &["/no/such/job.yaml"]);
    fails(&["run", "/no/such/campaign.yaml", "--checkpoint-interval=-1"], &["--checkpoint-interval"]);
}

#[test]
fn porosity_command_evaluates_a_lattice_and_rejects_bad_rows() {
    // Simple cubic lattice of 2 mm spheres, 5 × 5 per layer in a 10 mm box, 20 layers:
    // the bulk porosity is 1 − π/6 (hand-checked in the solver's tests).
    let dir = tempfile::tempdir().unwrap();
    let mut csv = String::from("x,y,z,r\n");
    for k in 0..20 {
        for j in 0..5 {
            for i in 0..5 {
                csv.push_str(&format!(
                    "{},{},{},0.001\n",
                    0.001 + 0.002 * i as f64,
                    0.001 + 0.002 * j as f64,
                    0.001 + 0.002 * k as f64
                ));
            }
        }
    }
    let path = write(dir.path(), "lattice.csv", &csv);
    let out = sedpack(&["porosity", &path, "--width", "0.01", "--slice", "0.001", "--trim", "0.002", "--json"]);
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!((v["bulk_porosity"].as_f64().unwrap() - (1.0 - std::f64::consts::PI / 6.0)).abs() < 1e-9);
    assert_eq!(v["particles"], 500);
    let bad = write(dir.path(), "bad.csv", "x,y,z,r\n0,0,0.001,0.001\n0,0,abc,0.001\n");
    fails(&["porosity", &bad, "--width", "0.01", "--trim", "0"], &["bad.csv", "line 3", "abc"]);
    let missing = write(dir.path(), "missing.csv", "x,y,z\n0,0,0\n");
    fails(&["porosity", &missing, "--width", "0.01", "--trim", "0"], &["missing.csv", "'r'"]);
    fails(&["porosity", &path, "--width", "-1", "--trim", "0"], &["--width"]);
    fails(&["porosity", &path, "--width", "0.01", "--slice", "1e-12", "--trim", "0"], &["slices of 1e-12 m"]);
}

/// An OBJ of a 10 mm box with one face pushed in: closed and valid, but not convex.
fn dented_box() -> String {
    let mut obj = String::new();
    for k in 0..8 {
        let s = |bit: u32| if k & (1 << bit) != 0 { 0.005 } else { -0.005 };
        obj.push_str(&format!("v {} {} {}\n", s(0), s(1), s(2)));
    }
    obj.push_str("v 0 0 0.002\n"); // the dent, below the top face's centre
    obj.push_str("f 1 3 4 2\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n");
    obj.push_str("f 5 6 9\nf 6 8 9\nf 8 7 9\nf 7 5 9\n");
    obj
}

#[test]
fn mesh_grains_from_a_folder_use_the_convex_hull_of_a_dented_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let meshes = dir.path().join("grains");
    std::fs::create_dir(&meshes).unwrap();
    write(&meshes, "dented.obj", &dented_box());
    let job = write(
        dir.path(),
        "mesh.yaml",
        "domain: {kind: periodic, width: 0.04, height: 0.1}\ngrains:\n  shape: mesh\n  meshes: grains\n  faces: 50\n  size: {sieves: [0.0056, 0.008], fractions: [1.0]}\n  mass: 0.03\nprocess:\n  generation: {spacing: 0.012}\n  shaking: {duration: 0.02}\nevaluation: {trim: 0.0}\n",
    );
    let out = dir.path().join("out");
    let run = sedpack(&["pack", &job, "--out", out.to_str().unwrap(), "--json"]);
    let stderr = String::from_utf8_lossy(&run.stderr);
    assert!(run.status.success(), "{stderr}");
    assert!(stderr.contains("dented.obj") && stderr.contains("convex hull"), "warned: {stderr}");
    let particles = std::fs::read_to_string(out.join("particles.csv")).unwrap();
    assert!(particles.lines().skip(1).all(|l| l.split(',').nth(1) == Some("mesh")));
    // The hull of the dented box is the box: its own form, rescaled to each grain's size D, has
    // L = I = S (a cube), so the stored statistics give FL = EL = 1.
    let result: Value = serde_json::from_slice(&run.stdout).unwrap();
    assert!((result["statistics"]["mean_FL"].as_f64().unwrap() - 1.0).abs() < 1e-9);
}

#[test]
fn bad_mesh_keys_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("empty")).unwrap();
    let empty = write(dir.path(), "empty.yaml", "grains:\n  shape: mesh\n  meshes: empty\n");
    fails(&["pack", &empty], &["empty.yaml:3", "grains.meshes", "no STL or OBJ"]);
    let faces = write(dir.path(), "faces.yaml", "grains:\n  shape: mesh\n  faces: 2\n");
    fails(&["pack", &faces], &["faces.yaml:3", "grains.faces", "at least 4"]);
    let own = write(dir.path(), "own.yaml", "grains:\n  shape: ellipsoid\n  form: mesh\n");
    fails(&["pack", &own], &["own.yaml:3", "grains.form", "grains.shape: mesh"]);
    let stray = write(dir.path(), "stray.yaml", "grains:\n  shape: sphere\n  meshes: builtin:rhine\n");
    fails(&["pack", &stray], &["grains.meshes", "mesh only"]);
}

#[test]
fn forms_simplifies_a_mesh_and_reports_the_volume_change() {
    let rhine = format!("{}/../solver/meshes/rhine_scan_0.obj", env!("CARGO_MANIFEST_DIR"));
    let out = sedpack(&["forms", "--mesh", &rhine, "--faces", "50", "--json"]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(v["triangles"].as_u64().unwrap() <= 50);
    // Table 4: simplification to 50 faces removes a few percent of the volume.
    let change = v["volume_change"].as_f64().unwrap();
    assert!(change < 0.0 && change > -0.06, "volume change {change}");
    let full = sedpack(&["forms", "--mesh", &rhine, "--json"]);
    let full: Value = serde_json::from_slice(&full.stdout).unwrap();
    assert!((v["volume"].as_f64().unwrap() / full["volume"].as_f64().unwrap() - 1.0 - change).abs() < 1e-12);
}
