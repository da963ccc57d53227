//! The runner as a library: when one worker fails, the others stop and every job goes back to
//! pending before the error is returned; a checkpoint another version wrote stops the run
//! rather than being thrown away.

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

    let options = RunOptions {
        workers: 2,
        threads: 1,
        checkpoint_interval: Duration::from_secs(300),
        discard_old_checkpoints: false,
        only: None,
    };
    let error = run(&store, &campaign.name, &options, false).await.unwrap_err();
    let error = format!("{error:#}");
    assert!(error.contains("grain_statistics"), "{error}");
    let status = store.status(&campaign.name).await.unwrap();
    assert_eq!((status.running, status.pending, status.done), (0, 2, 0), "{status:?}");
    assert!(store.running_jobs(&campaign.name).await.unwrap().is_empty());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_checkpoint_of_another_version_stops_the_run_untouched_unless_discarding_is_asked() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("upgraded.yaml");
    std::fs::write(&file, sphere_campaign("upgraded", 0.02, "")).unwrap();
    let campaign = read_campaign(&file).unwrap();
    let store = Store::open(dir.path().join("upgraded.db")).await.unwrap();
    store.upsert_campaign(&campaign.name, &campaign.text).await.unwrap();
    let jobs: Vec<_> = campaign.jobs.iter().map(new_job).collect();
    assert_eq!(store.add_jobs(&campaign.name, &jobs).await.unwrap(), 1);

    // An older sedpack ran the job to t = 2.5 s and was stopped: its checkpoint starts with
    // format number 3 (one varint byte), followed by a packing this version cannot decode.
    let claimed = store.claim(&campaign.name, "old-sedpack", None).await.unwrap().unwrap();
    let old = [3u8, 0x2a, 0x07, 0x00, 0x13];
    store.save_checkpoint(&claimed.id, "old-sedpack", &old, 2.5, None).await.unwrap();
    assert!(store.release(&claimed.id, "old-sedpack").await.unwrap());

    // The worker that claims it stops the run instead of starting the packing over.
    let options = RunOptions {
        workers: 1,
        threads: 1,
        checkpoint_interval: Duration::from_secs(300),
        discard_old_checkpoints: false,
        only: None,
    };
    let error = format!("{:#}", run(&store, &campaign.name, &options, false).await.unwrap_err());
    let named = format!("{} (format 3, at t = 2.50 s)", claimed.id);
    assert!(error.contains(&named) && error.contains("--discard-old-checkpoints"), "{error}");
    let status = store.status(&campaign.name).await.unwrap();
    assert_eq!((status.pending, status.running, status.done), (1, 0, 0), "{status:?}");
    let kept = store.load_checkpoint(&claimed.id).await.unwrap().unwrap();
    assert_eq!((&kept.data[..], kept.simulated_time), (&old[..], 2.5));

    // Asked to, it starts the job over and finishes it.
    let options = RunOptions { discard_old_checkpoints: true, ..options };
    let summary = run(&store, &campaign.name, &options, false).await.unwrap();
    assert_eq!((summary.completed, summary.failed), (1, 0));
    assert_eq!(store.status(&campaign.name).await.unwrap().done, 1);
}
