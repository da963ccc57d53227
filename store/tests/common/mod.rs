//! Helpers shared by the store's test files; each file uses a subset of them.
#![allow(dead_code)]

use std::collections::HashSet;
use std::path::{Path, PathBuf};

use serde_json::{Map, json};
use store::{GrainStatistic, JobResult, JobState, NewJob, Store};

pub const CAMPAIGN: &str = "rhine-u1";
pub const CAMPAIGN_SPEC: &str = "name: rhine-u1\ngrid:\n  grains.form.mu_fl: [0.4, 0.6]\n";

pub fn db_path(dir: &tempfile::TempDir) -> PathBuf {
    dir.path().join("sedpack.db")
}

/// Job `index` of a grid over mu_fl, as the pipeline would describe it; every other job is
/// compared with a measurement, every fourth with its spread, every third has fluid forces.
pub fn job(index: usize) -> NewJob {
    let mu_fl = 0.4 + 0.01 * index as f64;
    let seed = index as u64 % 3 + 1;
    let mut parameters = Map::new();
    parameters.insert("grains.form.mu_fl".into(), json!(mu_fl));
    parameters.insert("grains.size".into(), json!("U1"));
    NewJob {
        id: format!("job-{index:04}"),
        format: 1,
        spec: json!({"name": CAMPAIGN, "grains": {"size": "U1", "form": {"mu_fl": mu_fl}}, "seed": seed}),
        seed,
        parameters,
        experiment_porosity: index.is_multiple_of(2).then_some(0.371),
        experiment_std: index.is_multiple_of(4).then_some(0.001),
        fluid: index.is_multiple_of(3).then(|| json!({"flow": "logarithmic", "shear_velocity": 0.05})),
    }
}

pub fn jobs(range: std::ops::Range<usize>) -> Vec<NewJob> {
    range.map(job).collect()
}

pub fn result(porosity: f64) -> JobResult {
    JobResult {
        porosity,
        z_minus: 0.002,
        z_plus: 0.041,
        profile: json!([{"z": 0.0005, "n": 0.52}, {"z": 0.0015, "n": porosity}]),
        particles: 1234,
        simulated_time: 7.5,
        steps: 1_500_000,
        wall_time: 42.0,
        solver_version: "sedpack 0.1.0".into(),
        imbrication: None,
        size_classes: None,
    }
}

pub fn statistics(mean_fl: f64) -> Vec<GrainStatistic> {
    vec![
        GrainStatistic { name: "FL".into(), mean: mean_fl, std: 0.1 },
        GrainStatistic { name: "inv_FL".into(), mean: 1.0 / mean_fl, std: 0.3 },
        GrainStatistic { name: "EL".into(), mean: 0.7, std: 0.12 },
    ]
}

/// A fresh database holding the campaign and jobs 0..count.
pub async fn store_with_jobs(path: &Path, count: usize) -> Store {
    let store = Store::open(path).await.unwrap();
    store.upsert_campaign(CAMPAIGN, CAMPAIGN_SPEC).await.unwrap();
    assert_eq!(store.add_jobs(CAMPAIGN, &jobs(0..count)).await.unwrap(), count as u64);
    store
}

/// Claims and completes jobs until none is pending; returns the ids it completed.
pub async fn work(store: Store, worker_id: String) -> Vec<String> {
    let mut completed = Vec::new();
    while let Some(job) = store.claim(CAMPAIGN, &worker_id, None).await.unwrap() {
        assert_eq!(job.attempts, 1, "{} was claimed before", job.id);
        store.complete(&job.id, &worker_id, &result(0.4), &statistics(0.6)).await.unwrap();
        completed.push(job.id);
    }
    completed
}

/// Every job done exactly once, with one result, and `completed` names each job once.
pub async fn assert_each_job_done_once(path: &Path, count: usize, completed: &[String]) {
    let unique: HashSet<&String> = completed.iter().collect();
    assert_eq!((completed.len(), unique.len()), (count, count), "a job was run twice or never");
    let store = Store::open(path).await.unwrap();
    let rows = store.export(CAMPAIGN).await.unwrap();
    assert_eq!(rows.len(), count);
    assert!(rows.iter().all(|row| row.state == JobState::Done && row.attempts == 1 && row.result.is_some()));
    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.done, status.pending, status.running), (count as u64, 0, 0));
    store.close().await;
}
