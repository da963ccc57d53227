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
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path.to_str().unwrap().to_string()
}

/// A path inside the repository.
pub fn repo(path: &str) -> String {
    format!("{}/../{path}", env!("CARGO_MANIFEST_DIR"))
}

/// A path inside the tests' fixtures.
pub fn fixture(path: &str) -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(path)
}
