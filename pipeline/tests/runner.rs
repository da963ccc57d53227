//! The runner as a library: when one worker fails, the others stop and every job goes back to
//! pending before the error is returned.

mod common;

use std::time::Duration;

use common::sphere_campaign;
use sedpack::campaign::read_campaign;
use sedpack::records::new_job;
use sedpack::runner::{RunOptions, run};
use sqlx::{ConnectOptions, Connection};
use store::Store;

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_failing_worker_stops_the_others_and_every_job_returns_to_pending() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("broken.yaml");
    // Two sphere packings: one done in a fraction of a second, one shaken for 5 s.
    let grid = "grid:\n  process.shaking.duration: [0.02, 5.0]\n";
    std::fs::write(&file, sphere_campaign("broken", 0.02, grid)).unwrap();
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
