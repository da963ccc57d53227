//! End-to-end tests of `sedpack export --format jsonl` and `sedpack import`: seeds packed in
//! two databases reported from a third, and bad results files refused whole.

mod common;

use std::path::Path;

use common::{fails, fixture_db, json, ok, path_in, sphere_campaign, write};

/// The CSV export's rows (header left out) of the done jobs, sorted.
fn done_rows(db: &str, name: &str) -> Vec<String> {
    let csv = ok(&["export", name, "--db", db, "--format", "csv"]);
    let mut rows: Vec<String> =
        csv.lines().skip(1).filter(|l| l.split(',').nth(1) == Some("done")).map(String::from).collect();
    rows.sort();
    rows
}

#[test]
fn seeds_packed_in_two_databases_report_together_from_a_third() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "two.yaml", &sphere_campaign("two", 0.05, "seeds: [1, 2]\n"));
    let (a, b, c) = (&path_in(dir.path(), "a.db"), &path_in(dir.path(), "b.db"), &path_in(dir.path(), "c.db"));
    ok(&["run", &file, "--db", a, "--quiet", "--only", "seed=1"]);
    ok(&["run", &file, "--db", b, "--quiet", "--only", "seed=2"]);
    let (from_a, from_b) = (path_in(dir.path(), "a.jsonl"), path_in(dir.path(), "b.jsonl"));
    ok(&["export", "two", "--db", a, "--format", "jsonl", "--out", &from_a]);
    ok(&["export", "two", "--db", b, "--format", "jsonl", "--out", &from_b]);
    assert_eq!(std::fs::read_to_string(&from_a).unwrap().lines().count(), 2, "the header and the one done job");

    let imported = ok(&["import", &from_a, &from_b, "--db", c]);
    assert!(imported.contains("a.jsonl: campaign two, 1 done job(s): 1 added, 0 completed"), "{imported}");
    assert!(imported.contains("b.jsonl: campaign two, 1 done job(s): 1 added, 0 completed"), "{imported}");
    let mut both = [done_rows(a, "two"), done_rows(b, "two")].concat();
    both.sort();
    assert_eq!(both.len(), 2);
    assert_eq!(done_rows(c, "two"), both, "each job's row is the row of the database that packed it");
    let status = json(&["status", "two", "--db", c, "--json"]);
    assert_eq!((status["done"].as_u64(), status["pending"].as_u64()), (Some(2), Some(0)));
    // The campaign file finds its jobs in the imported ones: the ids agree, nothing is packed again.
    let again = ok(&["run", &file, "--db", c, "--quiet"]);
    assert!(again.contains("2 job(s), 0 new") && again.contains("0 job(s) finished now"), "{again}");
    let out = dir.path().join("report");
    ok(&["report", "two", "--db", c, "--out", out.to_str().unwrap()]);
    let dataset = std::fs::read_to_string(out.join("dataset.csv")).unwrap();
    assert_eq!(dataset.lines().count(), 3, "header and both seeds");

    // Database a has seed 2 pending (left by --only): the import completes it.
    let into_a = ok(&["import", &from_b, "--db", a]);
    assert!(
        into_a.contains("1 done job(s): 0 added, 1 completed (pending or failed here), 0 already done"),
        "{into_a}"
    );
    assert_eq!(done_rows(a, "two"), both);
}

#[test]
fn bad_results_files_are_refused_whole_naming_the_file_the_line_and_the_job() {
    let dir = tempfile::tempdir().unwrap();
    // sedpack 0.1.0's database: format-1 jobs, three done and one pending.
    let fixture = &fixture_db(dir.path());
    let good = path_in(dir.path(), "fixture.jsonl");
    ok(&["export", "fixture", "--db", fixture, "--format", "jsonl", "--out", &good]);
    let text = std::fs::read_to_string(&good).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4, "the header and the three done jobs");
    let fresh = &path_in(dir.path(), "fresh.db");
    let bad = |name: &str, text: String| write(dir.path(), name, &text);

    let id = serde_json::from_str::<serde_json::Value>(lines[2]).unwrap()["id"].as_str().unwrap().to_string();
    let edited = bad("edited.jsonl", text.replacen(&format!("\"id\":\"{id}\""), "\"id\":\"0123456789abcdef\"", 1));
    fails(
        &["import", &good, &edited, "--db", fresh],
        &["edited.jsonl: line 3, job 0123456789abcdef", "hashes to the id"],
    );
    let other = bad("other.jsonl", text.replacen("\"campaign\":\"fixture\"", "\"campaign\":\"renamed\"", 1));
    fails(
        &["import", &other, "--db", fresh],
        &["other.jsonl: line 2", "of campaign \"fixture\"", "header of \"renamed\""],
    );
    let cut = bad("cut.jsonl", format!("{}\n{}\n", lines[0], &lines[1][..lines[1].len() / 2]));
    fails(&["import", &cut, "--db", fresh], &["cut.jsonl: line 2"]);
    let csv = bad("rows.jsonl", ok(&["export", "fixture", "--db", fixture, "--format", "csv"]));
    fails(&["import", &csv, "--db", fresh], &["rows.jsonl: not a results file of sedpack", "sedpack_results"]);
    let newer = bad(
        "newer.jsonl",
        text.replacen("{\"sedpack_results\":1,\"sedpack\":\"", "{\"sedpack_results\":2,\"sedpack\":\"9.9.9-", 1),
    );
    fails(
        &["import", &newer, "--db", fresh],
        &["newer.jsonl: results layout 2 (written by sedpack 9.9.9-", "cannot read"],
    );
    assert!(!Path::new(fresh).exists(), "no file was taken in part: the database was never opened");

    let taken = ok(&["import", &good, "--db", fresh]);
    assert!(taken.contains("campaign fixture, 3 done job(s): 3 added"), "{taken}");
    assert_eq!(done_rows(fresh, "fixture"), done_rows(fixture, "fixture"));
}

#[test]
fn the_results_kept_in_the_repository_import_whole() {
    let dir = tempfile::tempdir().unwrap();
    let db = &path_in(dir.path(), "kept.db");
    let folder = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/results");
    let mut files: Vec<_> = std::fs::read_dir(&folder).unwrap().map(|e| e.unwrap().path()).collect();
    files.sort();
    assert!(!files.is_empty(), "{}", folder.display());
    for file in &files {
        // Each job's spec still decodes and hashes to its id with this version of sedpack.
        let jobs = std::fs::read_to_string(file).unwrap().lines().count() - 1;
        let out = ok(&["import", file.to_str().unwrap(), "--db", db]);
        assert!(out.contains(&format!("{jobs} done job(s): {jobs} added")), "{out}");
    }
}
