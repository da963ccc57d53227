//! The standard settled beds of `solver::bed` for the benchmarks, built once and cached in
//! target/sedpack-bench/.

use std::path::PathBuf;

use solver::bed::{BedSpec, build};
use solver::dem::Simulation;

/// Where a standard bed is cached: beside the build, one file per bed and solver version.
fn cache(spec: &BedSpec) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!(
        "../target/sedpack-bench/{}-v{}.json",
        spec.name(),
        solver::VERSION
    ))
}

/// The settled bed of `spec`, built once and read back from its cache file afterwards.
pub fn bed(spec: &BedSpec) -> Simulation {
    let path = cache(spec);
    if let Some(sim) = std::fs::read_to_string(&path).ok().and_then(|s| serde_json::from_str(&s).ok()) {
        return sim;
    }
    eprintln!("building {} for the benchmark, cached in {}", spec.name(), path.display());
    let sim = build(spec, &mut |_| {}).expect("the standard beds build");
    std::fs::create_dir_all(path.parent().expect("a folder")).expect("the cache folder");
    std::fs::write(&path, serde_json::to_string(&sim).expect("serialisable")).expect("the cache file");
    sim
}
