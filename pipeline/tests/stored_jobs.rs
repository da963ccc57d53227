//! The stored job across places and versions: a job with a mesh folder keeps its id wherever the
//! campaign and the folder lie; a job that sedpack 0.1.0 stored with the folder's absolute path
//! is found again when its campaign is submitted again (kept under its id, not added twice) and
//! follows the folder when it moves; a job stored in this version's format (the fixture
//! tests/fixtures/stored/format-2.json) reads back byte for byte and runs, as later versions
//! must keep it.

mod common;

use std::path::{Path, PathBuf};

use common::{fixture, ok, repo};
use serde_json::{Value, json};
use sha2::{Digest, Sha256};
use solver::packing::{Packing, Phase};
use store::{JobState, NewJob, Store};

/// A campaign of two tiny mesh packings from the folder `scans` beside it (copies of the Rhine
/// scans), each allowed too little simulated time to settle: it fails fast, after reading its
/// meshes.
fn mesh_campaign(dir: &Path) -> PathBuf {
    std::fs::create_dir_all(dir.join("scans")).unwrap();
    for f in ["rhine_scan_0.obj", "rhine_scan_1.obj"] {
        std::fs::copy(Path::new(&repo("solver/meshes")).join(f), dir.join("scans").join(f)).unwrap();
    }
    let file = dir.join("scans.yaml");
    std::fs::write(
        &file,
        "name: scans\ndomain: {width: 0.05, height: 0.1}\n\
         grains: {shape: mesh, meshes: scans, faces: 40, mass: 0.01, size: {sieves: [0.008, 0.0112], fractions: [1.0]}}\n\
         process: {generation: {spacing: 0.013}, shaking: {duration: 0.05}}\nsolver: {max_time: 0.06}\nseeds: [1, 2]\n",
    )
    .unwrap();
    file
}

#[test]
fn a_mesh_folder_job_has_the_same_id_wherever_it_lies() {
    let dir = tempfile::tempdir().unwrap();
    let here = mesh_campaign(&dir.path().join("here"));
    let there = mesh_campaign(&dir.path().join("elsewhere/deeper"));
    let (a, b) = (sedpack::campaign::read_campaign(&here).unwrap(), sedpack::campaign::read_campaign(&there).unwrap());
    let ids = |c: &sedpack::campaign::Campaign| c.jobs.iter().map(|j| j.id.clone()).collect::<Vec<_>>();
    assert_eq!(ids(&a), ids(&b));
    let stored = sedpack::stored::encode(&b.jobs[0].spec);
    let folder = dir.path().join("elsewhere/deeper/scans").canonicalize().unwrap();
    assert_eq!(stored["mesh_folder"], folder.display().to_string(), "where the job finds its meshes");
}

#[test]
fn a_mesh_folder_job_of_0_1_0_is_kept_under_its_id_and_follows_the_folder() {
    let dir = tempfile::tempdir().unwrap();
    let file = mesh_campaign(&dir.path().join("old"));
    let campaign = sedpack::campaign::read_campaign(&file).unwrap();
    // What sedpack 0.1.0 stored: format 1, the folder's absolute path in the job and its id.
    let planned = &campaign.jobs[0];
    let mut v1 = sedpack::stored::encode(&planned.spec)["job"].clone();
    let old_folder = dir.path().join("old/scans").canonicalize().unwrap().display().to_string();
    v1["packing"]["grains"]["meshes"]["source"] = json!(old_folder);
    let digest = Sha256::digest(serde_json::to_string(&v1).unwrap().as_bytes());
    let old_id: String = digest.iter().take(8).map(|b| format!("{b:02x}")).collect();
    assert_ne!(old_id, planned.id);
    let db = dir.path().join("sedpack.db");
    let rt = tokio::runtime::Runtime::new().unwrap();
    rt.block_on(async {
        let store = Store::open(&db).await.unwrap();
        store.upsert_campaign("scans", &campaign.text).await.unwrap();
        let job = NewJob {
            id: old_id.clone(),
            format: 1,
            spec: v1,
            seed: 1,
            parameters: planned.parameters.clone(),
            experiment_porosity: None,
            experiment_std: None,
            fluid: None,
        };
        store.add_jobs("scans", &[job]).await.unwrap();
    });

    // The campaign and its meshes move; the campaign is submitted from its new place.
    std::fs::rename(dir.path().join("old"), dir.path().join("new")).unwrap();
    let moved = dir.path().join("new/scans.yaml");
    let out = ok(&["run", moved.to_str().unwrap(), "--db", db.to_str().unwrap(), "--workers", "1", "--quiet"]);
    assert!(out.contains("2 job(s), 1 new"), "the 0.1.0 job is the first one: {out}");
    assert!(out.contains("1 job(s) not done now find their mesh folder where this campaign file does"), "{out}");
    let jobs = rt.block_on(async { Store::open(&db).await.unwrap().jobs("scans").await.unwrap() });
    assert_eq!(jobs.len(), 2);
    let new_folder = dir.path().join("new/scans").canonicalize().unwrap().display().to_string();
    assert_eq!((jobs[0].id.as_str(), jobs[0].format), (old_id.as_str(), 2), "its id kept, its spec stored anew");
    assert_eq!(jobs[0].spec["mesh_folder"], new_folder);
    // Both read their meshes from the new place: they ran until the time they were allowed.
    for job in &jobs {
        assert_eq!(job.state, JobState::Failed);
        assert!(job.error.as_deref().unwrap().contains("not converged after solver.max_time = 0.06 s"), "{job:?}");
    }
    let again = ok(&["run", moved.to_str().unwrap(), "--db", db.to_str().unwrap(), "--quiet"]);
    assert!(again.contains("2 job(s), 0 new") && !again.contains("mesh folder"), "{again}");
}

#[test]
fn a_stored_job_of_format_2_reads_back_byte_for_byte_and_runs() {
    let text = std::fs::read_to_string(fixture("stored/format-2.json")).unwrap();
    let meshes = Path::new(&repo("solver/meshes")).canonicalize().unwrap().display().to_string();
    let jobs: Vec<Value> = serde_json::from_str(&text.replace("\"MESHES\"", &format!("{meshes:?}"))).unwrap();
    assert_eq!(jobs.len(), 2);
    for job in &jobs {
        assert_eq!(job["format"], 2);
        let spec = sedpack::stored::decode(2, &job["spec"]).unwrap();
        assert_eq!(sedpack::stored::job_id(&spec), job["id"].as_str().unwrap(), "the same id");
        assert_eq!(sedpack::stored::encode(&spec), job["spec"], "the same stored job");
    }
    // The sphere packing runs to a porosity.
    let spheres = sedpack::stored::decode(2, &jobs[0]["spec"]).unwrap();
    assert_eq!(spheres.experiment.map(|e| e.porosity), Some(0.38));
    let mut packing = Packing::new(spheres.packing).unwrap();
    while packing.advance(10_000).unwrap() != Phase::Converged {}
    let porosity = packing.result().unwrap().porosity.bulk;
    assert!((0.25..0.6).contains(&porosity), "{porosity}");
    let meshes_job = sedpack::stored::decode(2, &jobs[1]["spec"]).unwrap();
    assert_eq!(meshes_job.packing.grains.meshes.unwrap().source, meshes);
}
