//! The runner as a library: when one worker fails, the others stop and every job goes back to
//! pending before the error is returned.

use std::time::Duration;

use sedpack::campaign::read_campaign;
use sedpack::records::new_job;
use sedpack::runner::{RunOptions, run};
use sqlx::{ConnectOptions, Connection};
use store::Store;

/// Two sphere packings: one done in a fraction of a second, one shaken for 5 s of simulated time.
const CAMPAIGN: &str = "name: broken
domain: {kind: periodic, width: 0.03, height: 0.1}
grains:
  shape: sphere
  size: {sieves: [0.0056, 0.008], fractions: [1.0]}
  mass: 0.03
process:
  generation: {spacing: 0.009}
evaluation: {trim: 0.004}
grid:
  process.shaking.duration: [0.02, 5.0]
";

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_failing_worker_stops_the_others_and_every_job_returns_to_pending() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("broken.yaml");
    std::fs::write(&file, CAMPAIGN).unwrap();
    let campaign = read_campaign(&file).unwrap();
    let db = dir.path().join("broken.db");
    let store = Store::open(&db).await.unwrap();
    store.upsert_campaign(&campaign.name, &campaign.text).await.unwrap();
    let jobs: Vec<_> = campaign.jobs.iter().map(new_job).collect();
    assert_eq!(store.add_jobs(&campaign.name, &jobs).await.unwrap(), 2);

    // Without its grain statistics table the store cannot record the short job's result: the
    // worker that finishes it fails while the other is in the middle of the long one.
    let mut raw = sqlx::sqlite::SqliteConnectOptions::new().filename(&db).connect().await.unwrap();
    sqlx::query("DROP TABLE grain_statistics").execute(&mut raw).await.unwrap();
    raw.close().await.unwrap();

    let options = RunOptions { workers: 2, checkpoint_interval: Duration::from_secs(300) };
    let error = run(&store, &campaign.name, &options, false).await.unwrap_err();
    let error = format!("{error:#}");
    assert!(error.contains("grain_statistics"), "{error}");
    let status = store.status(&campaign.name).await.unwrap();
    assert_eq!((status.running, status.pending, status.done), (0, 2, 0), "{status:?}");
    assert!(store.running_jobs(&campaign.name).await.unwrap().is_empty());
}
