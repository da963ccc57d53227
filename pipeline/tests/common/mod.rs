//! Running the built `sedpack` binary from the end-to-end tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

use serde_json::Value;

pub fn sedpack(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_sedpack")).args(args).output().expect("sedpack runs")
}

/// Standard output of a command that must succeed.
pub fn ok(args: &[&str]) -> String {
    let out = sedpack(args);
    assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).expect("UTF-8 output")
}

/// The one JSON value a `--json` command prints.
pub fn json(args: &[&str]) -> Value {
    serde_json::from_str(&ok(args)).expect("one JSON value")
}

/// The command fails with status 1 and one line on stderr containing every needle.
pub fn fails(args: &[&str], needles: &[&str]) {
    let out = sedpack(args);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{args:?}: {stderr}");
    assert_eq!(stderr.trim_end().lines().count(), 1, "one line: {stderr}");
    for n in needles {
        assert!(stderr.contains(n), "{args:?}: '{stderr}' lacks '{n}'");
    }
}

/// Writes a file into `dir` and returns its path.
pub fn write(dir: &Path, name: &str, text: &str) -> String {
    std::fs::write(dir.join(name), text).unwrap();
    path_in(dir, name)
}

/// The path of `name` in `dir`, as a command-line argument.
pub fn path_in(dir: &Path, name: &str) -> String {
    dir.join(name).to_str().unwrap().to_string()
}

/// A path inside the repository.
pub fn repo(path: &str) -> String {
    format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"))
}

/// A path inside the tests' fixtures.
pub fn fixture(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(path)
}

/// A copy of sedpack 0.1.0's fixture database (two campaigns, one job pending) in `dir`.
pub fn fixture_db(dir: &Path) -> String {
    std::fs::copy(fixture("v0.1.0/fixture.db"), dir.join("fixture.db")).unwrap();
    path_in(dir, "fixture.db")
}

/// A campaign (or, with an empty `grid`, a job) of small sphere packings, ~60 grains of
/// 5.6–8 mm in a 3 cm periodic square, shaken for `shaking` s; `grid` gives the `grid:` and
/// `seeds:` lines.
pub fn sphere_campaign(name: &str, shaking: f64, grid: &str) -> String {
    format!(
        "name: {name}
domain: {{kind: periodic, width: 0.03, height: 0.1}}
grains:
  shape: sphere
  size: {{sieves: [0.0056, 0.008], fractions: [1.0]}}
  mass: 0.03
process:
  generation: {{spacing: 0.009}}
  shaking: {{duration: {shaking}}}
evaluation: {{trim: 0.004}}
{grid}"
    )
}
