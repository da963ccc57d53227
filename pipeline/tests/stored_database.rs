//! A database written by sedpack 0.1.0 (tests/fixtures/v0.1.0: four small ellipsoid packings,
//! three done and one interrupted with a checkpoint, beside a one-job campaign of spheres) opens,
//! resumes and reports with this version: stored results are kept bit for bit, and the job run
//! again from the start gets grains and a porosity within the sampling and run-to-run spread of
//! such small beds (0.2.0 draws a set's grains before placing them, so its grains are a new
//! sample of the same distributions, and its narrow phase rounds differently).

mod common;

use std::path::Path;

use common::{fixture, fixture_db, json, ok};

/// CSV lines as fields, without the column named `skip`.
fn fields_without(csv: &str, skip: &str) -> Vec<Vec<String>> {
    let header: Vec<&str> = csv.lines().next().unwrap().split(',').collect();
    let at = header.iter().position(|h| *h == skip).unwrap();
    csv.lines()
        .map(|l| l.split(',').enumerate().filter(|(k, _)| *k != at).map(|(_, f)| f.to_string()).collect())
        .collect()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

#[test]
fn a_database_of_version_0_1_0_resumes_and_reports_the_same_results() {
    let dir = tempfile::tempdir().unwrap();
    let db = &fixture_db(dir.path());
    let spheres_before = ok(&["export", "fixture-spheres", "--db", db, "--format", "csv"]);

    let status = json(&["status", "fixture", "--db", db, "--json"]);
    assert_eq!((status["done"].as_u64(), status["pending"].as_u64()), (Some(3), Some(1)), "{status}");
    // The interrupted job's checkpoint is 0.1.0's, which this version cannot continue: resume
    // says so and changes nothing until asked to start that job over.
    let notice = ["e4f0b397d28c4f59 (format 0, at t = ", "left as they were", "--discard-old-checkpoints"];
    common::fails(&["resume", "fixture", "--db", db, "--workers", "1", "--quiet"], &notice);
    assert_eq!(json(&["status", "fixture", "--db", db, "--json"]), status);
    let log = read(&dir.path().join("fixture.log"));
    assert!(!log.contains("started") && !log.contains("its checkpoint cannot be used"), "{log}");
    let resumed = ok(&["resume", "fixture", "--db", db, "--workers", "1", "--quiet", "--discard-old-checkpoints"]);
    assert!(resumed.contains("1 job(s) finished now") && resumed.contains("4 done"), "{resumed}");
    // The log says why that checkpoint was not used.
    let log = read(&dir.path().join("fixture.log"));
    let warning = log.lines().find(|l| l.contains("its checkpoint cannot be used")).unwrap_or_else(|| panic!("{log}"));
    let reads = sedpack::runner::CHECKPOINT_FORMAT;
    let why = format!("another version of sedpack wrote it (checkpoint format 0; this version reads {reads})");
    assert!(warning.contains(&why), "{warning}");
    assert!(warning.contains("starting over") && warning.contains("e4f0b397d28c4f59"), "{warning}");
    assert!(!log.contains("resuming from a checkpoint"), "{log}");

    // The jobs 0.1.0 finished keep their results (wall times aside); the one run again has a
    // porosity within 0.03 of 0.1.0's and a new sample of ~73 grains from the same distributions:
    // a count within 20 % (the mass target fixes it up to the spread of the grain mass, a CV of
    // ~0.4 over √73), each form factor's mean within 4 standard errors of the difference of two
    // such means, and the spread of the drawn factors FL and EL and of EQ = FL·EL within 35 %
    // (4 × the 1/√(2N) relative error of a normal spread; the other factors' tails are too heavy).
    let export = ok(&["export", "fixture", "--db", db, "--format", "csv"]);
    let expected = read(&fixture("v0.1.0/expected-export.csv"));
    let (got, want) = (fields_without(&export, "wall_time"), fields_without(&expected, "wall_time"));
    assert_eq!(got.len(), want.len());
    let rerun = got.iter().position(|row| row[0] == "e4f0b397d28c4f59").unwrap();
    let porosity = want[0].iter().position(|h| h == "porosity").unwrap();
    for (k, (g, w)) in got.iter().zip(&want).enumerate() {
        if k != rerun {
            assert_eq!(g, w);
            continue;
        }
        let value = |row: &[String], column: &str| -> f64 {
            row[want[0].iter().position(|h| h == column).unwrap()].parse().unwrap()
        };
        let (n_got, n_want) = (value(g, "particles"), value(w, "particles"));
        assert!((n_got / n_want - 1.0).abs() < 0.2, "{n_got} grains vs 0.1.0's {n_want}");
        for (column, (a, b)) in want[0].iter().zip(g.iter().zip(w)) {
            let (x, y) = (a.parse::<f64>(), b.parse::<f64>());
            match column.as_str() {
                "porosity" => {
                    let (a, b) = (x.unwrap(), y.unwrap());
                    assert!((a - b).abs() < 0.03, "porosity {a} vs 0.1.0's {b}");
                }
                "z_minus" | "z_plus" | "simulated_time" | "particles" => {}
                mean if mean.starts_with("mean_") => {
                    let spread = value(w, &mean.replacen("mean_", "std_", 1));
                    let error = spread * (1.0 / n_got + 1.0 / n_want).sqrt();
                    assert!((x.unwrap() - y.unwrap()).abs() <= 4.0 * error, "{column}: {a} vs 0.1.0's {b}");
                }
                "std_FL" | "std_EL" | "std_EQ" => {
                    assert!((x.unwrap() / y.unwrap() - 1.0).abs() < 0.35, "{column}: {a} vs 0.1.0's {b}");
                }
                spread if spread.starts_with("std_") => {}
                _ => assert_eq!(a, b, "{column}"),
            }
        }
    }
    assert!(porosity > 0);
    assert_eq!(ok(&["export", "fixture-spheres", "--db", db, "--format", "csv"]), spheres_before);

    // The report's dataset holds the stored jobs' numbers; the kept jobs' rows are 0.1.0's.
    let out = dir.path().join("report");
    let report = common::sedpack(&["report", "fixture", "--db", db, "--out", out.to_str().unwrap()]);
    let stderr = String::from_utf8_lossy(&report.stderr);
    assert!(report.status.success(), "{stderr}");
    assert!(stderr.contains("fixture: 3 finished job(s) were packed by sedpack 0.1.0"), "{stderr}");
    let expected = fixture("v0.1.0/expected-report");
    let dataset = read(&out.join("dataset.csv"));
    let want = read(&expected.join("dataset.csv"));
    assert_eq!(dataset.lines().count(), want.lines().count());
    for line in want.lines().filter(|l| !l.starts_with("e4f0b397d28c4f59")) {
        assert!(dataset.lines().any(|l| l == line), "{line}");
    }
    // The campaign's measurement (porosity 0.4, no spread) comes from the stored jobs of 0.1.0.
    let md = read(&out.join("report.md"));
    // The three packings 0.1.0 made are flagged: its generation dropped grains.
    assert!(md.contains("**Warning:** 3 of the finished jobs were packed by sedpack 0.1.0"), "{md}");
    assert!(md.contains("| grains.form.mu_fl = 0.7 | 0.386 | 0.386 | 0.400 (spread not given) | -0.014 |"), "{md}");
    assert!(!md.contains("± 0.000"), "an unknown spread is not shown as 0: {md}");

    // Submitting the campaign file again finds every job by its id: ids did not change.
    let again = ok(&["run", fixture("v0.1.0/fixture.yaml").to_str().unwrap(), "--db", db, "--quiet"]);
    assert!(again.contains("4 job(s), 0 new"), "{again}");
}
