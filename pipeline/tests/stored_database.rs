//! A database written by sedpack 0.1.0 (tests/fixtures/v0.1.0: four small ellipsoid packings,
//! three done and one interrupted with a checkpoint, beside a one-job campaign of spheres) opens,
//! resumes and reports with this version, with the results the old version gave.

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
    let resumed = ok(&["resume", "fixture", "--db", db, "--workers", "1", "--quiet"]);
    assert!(resumed.contains("1 job(s) finished now") && resumed.contains("4 done"), "{resumed}");
    // The interrupted job's checkpoint is 0.1.0's: the log says it cannot be used, and why.
    let log = read(&dir.path().join("fixture.log"));
    let warning = log.lines().find(|l| l.contains("its checkpoint cannot be used")).unwrap_or_else(|| panic!("{log}"));
    assert!(warning.contains("another version of sedpack wrote it (checkpoint format 0; this version reads 2)"));
    assert!(warning.contains("starting over") && warning.contains("e4f0b397d28c4f59"), "{warning}");
    assert!(!log.contains("resuming from a checkpoint"), "{log}");

    // Every job, the resumed one included, has the result 0.1.0 computed (wall times aside).
    let export = ok(&["export", "fixture", "--db", db, "--format", "csv"]);
    let expected = read(&fixture("v0.1.0/expected-export.csv"));
    assert_eq!(fields_without(&export, "wall_time"), fields_without(&expected, "wall_time"));
    assert_eq!(ok(&["export", "fixture-spheres", "--db", db, "--format", "csv"]), spheres_before);

    // The report's numbers are those of 0.1.0's report of the same jobs.
    let out = dir.path().join("report");
    ok(&["report", "fixture", "--db", db, "--out", out.to_str().unwrap()]);
    let expected = fixture("v0.1.0/expected-report");
    assert_eq!(read(&out.join("dataset.csv")), read(&expected.join("dataset.csv")));
    let mut models: Vec<String> = std::fs::read_dir(expected.join("models"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    models.sort();
    assert_eq!(models.len(), 3);
    for model in &models {
        assert_eq!(read(&out.join("models").join(model)), read(&expected.join("models").join(model)), "{model}");
    }
    // The campaign's measurement (porosity 0.4, no spread) comes from the stored jobs of 0.1.0.
    let md = read(&out.join("report.md"));
    assert!(md.contains("| grains.form.mu_fl = 0.8 | 0.400 | 0.400 | 0.400 (spread not given) | -0.000 |"), "{md}");
    assert!(!md.contains("± 0.000"), "an unknown spread is not shown as 0: {md}");

    // Submitting the campaign file again finds every job by its id: ids did not change.
    let again = ok(&["run", fixture("v0.1.0/fixture.yaml").to_str().unwrap(), "--db", db, "--quiet"]);
    assert!(again.contains("4 job(s), 0 new"), "{again}");
}
