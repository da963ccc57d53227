//! What every printing command does with its standard output: `status --json` lists every
//! campaign, and a reader that closed the pipe (`sedpack … | head`) ends the command quietly.

mod common;

use std::process::{Command, Output, Stdio};

use common::{fixture_db, json, sphere_campaign, write};

/// Runs sedpack with a standard output whose reader is already gone.
fn with_closed_stdout(args: &[&str]) -> Output {
    let (reader, writer) = std::io::pipe().unwrap();
    drop(reader);
    Command::new(env!("CARGO_BIN_EXE_sedpack"))
        .args(args)
        .stdout(writer)
        .stderr(Stdio::piped())
        .output()
        .expect("sedpack runs")
}

#[test]
fn status_as_json_lists_every_campaign_of_the_database() {
    let dir = tempfile::tempdir().unwrap();
    let db = &fixture_db(dir.path());
    let all = json(&["status", "--db", db, "--json"]);
    let names: Vec<&str> = all.as_array().unwrap().iter().map(|c| c["campaign"].as_str().unwrap()).collect();
    assert_eq!(names, ["fixture-spheres", "fixture"]);
    assert_eq!(all[1]["pending"], 1);
    // A named campaign is one object, the same as its entry in the list.
    assert_eq!(json(&["status", "fixture", "--db", db, "--json"]), all[1]);
}

#[test]
fn every_printing_command_ends_quietly_when_the_reader_is_gone() {
    let dir = tempfile::tempdir().unwrap();
    let db = &fixture_db(dir.path());
    // A simple cubic lattice of 2 mm spheres, 5 × 5 per layer in a 10 mm box, 10 layers.
    let mut lattice = String::from("x,y,z,r\n");
    for k in 0..250 {
        let at = |i: usize| 0.001 + 0.002 * i as f64;
        lattice.push_str(&format!("{},{},{},0.001\n", at(k % 5), at(k / 5 % 5), at(k / 25)));
    }
    let spheres = write(dir.path(), "spheres.csv", &lattice);
    let sizes = write(dir.path(), "sizes.yaml", "sieves: [0.001, 0.002]\nfractions: [1.0]\n");
    let job = write(dir.path(), "job.yaml", &sphere_campaign("job", 0.01, ""));
    let out = dir.path().join("out");
    let report = dir.path().join("report");
    let distribution = ["--mu-fl", "0.6", "--sigma-fl", "0.1", "--mu-el", "0.7", "--sigma-el", "0.1"];
    let commands: Vec<Vec<&str>> = vec![
        vec!["forms", "--lis", "4", "2", "1"],
        vec!["forms", "--lis", "4", "2", "1", "--json"],
        [&["forms"][..], &distribution].concat(),
        vec!["forms", "--bonded", "3", "1", "1"],
        [&["sample", "forms", "--count", "100"][..], &distribution].concat(),
        vec!["sample", "sizes", "--case", "U7", "--count", "100"],
        vec!["sample", "sizes", "--sieves", &sizes, "--count", "100", "--json"],
        [&["predict", "--model", "paper-U1"][..], &distribution].concat(),
        vec!["porosity", &spheres, "--width", "0.01", "--trim", "0"],
        vec!["pack", &job, "--out", out.to_str().unwrap(), "--json"],
        vec!["status", "--db", db],
        vec!["status", "--db", db, "--json"],
        vec!["export", "fixture", "--db", db, "--format", "csv"],
        vec!["report", "fixture", "--db", db, "--out", report.to_str().unwrap()],
        vec!["--help"],
    ];
    // The fixture's results are 0.1.0's, of which `report` warns: that line is expected.
    let warning = "sedpack: warning: fixture: 3 finished job(s) were packed by sedpack 0.1.0";
    for args in &commands {
        let output = with_closed_stdout(args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        let unexpected: Vec<&str> = stderr.lines().filter(|l| !l.starts_with(warning)).collect();
        assert!(output.status.success() && unexpected.is_empty(), "{args:?}: {:?}, {stderr}", output.status);
    }
}
