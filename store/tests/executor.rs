//! Jobs handed to an executor elsewhere (a batch scheduler): a campaign's executor, claims of
//! many jobs at once, handing a job to another worker, stored specs replaced, times of a job
//! that ran elsewhere.

mod common;

use common::*;
use serde_json::json;
use sqlx::Connection;
use store::{JobState, StoreError};

#[tokio::test]
async fn a_campaign_keeps_its_executor() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 1).await;
    assert_eq!(store.campaign(CAMPAIGN).await.unwrap().executor, None);
    let slurm = json!({"kind": "slurm", "cpus_per_task": 2});
    store.set_executor(CAMPAIGN, Some(&slurm)).await.unwrap();
    assert_eq!(store.campaign(CAMPAIGN).await.unwrap().executor, Some(slurm.clone()));
    // Submitting the campaign again keeps it.
    store.upsert_campaign(CAMPAIGN, CAMPAIGN_SPEC).await.unwrap();
    assert_eq!(store.campaigns().await.unwrap()[0].executor, Some(slurm));
    store.set_executor(CAMPAIGN, None).await.unwrap();
    assert_eq!(store.campaign(CAMPAIGN).await.unwrap().executor, None);
    assert!(matches!(store.set_executor("nope", None).await, Err(StoreError::NoCampaign { .. })));
    store.close().await;
}

#[tokio::test]
async fn many_jobs_are_claimed_at_once_each_by_its_own_worker() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 5).await;
    let first = store.claim(CAMPAIGN, "local", None).await.unwrap().unwrap();
    // Only the jobs asked for, if they are pending.
    let only = ["job-0000".to_string(), "job-0002".to_string()];
    let picked = store.claim_many(CAMPAIGN, Some(&only), 5, |k| format!("only_{k}")).await.unwrap();
    assert_eq!(picked.iter().map(|c| c.id.as_str()).collect::<Vec<_>>(), ["job-0002"]);
    store.release("job-0002", "only_0").await.unwrap();
    let claimed = store.claim_many(CAMPAIGN, None, 3, |k| format!("array_{k}")).await.unwrap();
    let ids: Vec<&str> = claimed.iter().map(|c| c.id.as_str()).collect();
    assert_eq!(ids, ["job-0001", "job-0002", "job-0003"], "in submission order, the claimed one skipped");
    assert_eq!(claimed.iter().map(|c| c.attempts).collect::<Vec<_>>(), [1, 2, 1], "job-0002 was claimed before");
    let running = store.running_jobs(CAMPAIGN).await.unwrap();
    let workers: Vec<(&str, &str)> = running.iter().map(|r| (r.job_id.as_str(), r.worker_id.as_str())).collect();
    assert_eq!(
        workers,
        [("job-0000", "local"), ("job-0001", "array_0"), ("job-0002", "array_1"), ("job-0003", "array_2")]
    );
    let rest = store.claim_many(CAMPAIGN, None, 10, |k| format!("b_{k}")).await.unwrap();
    assert_eq!(rest.iter().map(|c| c.id.as_str()).collect::<Vec<_>>(), ["job-0004"]);
    assert!(store.claim_many(CAMPAIGN, None, 10, |k| format!("c_{k}")).await.unwrap().is_empty());
    assert_ne!(first.id, rest[0].id);
    store.close().await;
}

#[tokio::test]
async fn a_running_job_is_handed_over_only_by_its_worker() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 1).await;
    let job = &store.claim_many(CAMPAIGN, None, 1, |_| "submitting:1".into()).await.unwrap()[0];
    assert!(!store.reassign(&job.id, "someone", "slurm:7_0").await.unwrap());
    assert!(store.reassign(&job.id, "submitting:1", "slurm:7_0").await.unwrap());
    assert!(!store.reassign(&job.id, "submitting:1", "slurm:8_0").await.unwrap(), "handed over once");
    assert_eq!(store.running_jobs(CAMPAIGN).await.unwrap()[0].worker_id, "slurm:7_0");
    // The job ran from t = 100 to t = 130 elsewhere: that is its wall time, not claim to now.
    store.complete_ran(&job.id, "slurm:7_0", (100.0, 130.0), &result(0.4), &statistics(0.6)).await.unwrap();
    let again = store.complete_ran(&job.id, "slurm:7_0", (100.0, 130.0), &result(0.4), &[]).await;
    assert!(matches!(again, Err(StoreError::NotOwner { .. })), "a result is recorded once");
    let mut raw = sqlx::SqliteConnection::connect(&format!("sqlite://{}", db_path(&dir).display())).await.unwrap();
    let times: (f64, f64, f64) =
        sqlx::query_as("SELECT started_at, finished_at, wall_time FROM jobs").fetch_one(&mut raw).await.unwrap();
    assert_eq!(times, (100.0, 130.0, 30.0));
    raw.close().await.unwrap();
    // The status counts the packing's own time, which its result carries (42 s of packing).
    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.done, status.mean_wall_time_done), (1, Some(42.0)));
    let jobs = store.jobs(CAMPAIGN).await.unwrap();
    assert_eq!((jobs[0].state, jobs[0].worker_id.as_deref(), jobs[0].attempts), (JobState::Done, Some("slurm:7_0"), 1));
    store.close().await;
}

#[tokio::test]
async fn the_spec_of_a_job_not_done_can_be_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 2).await;
    let moved = json!({"job": {"name": CAMPAIGN}, "mesh_folder": "/new/place"});
    assert!(store.replace_spec("job-0000", 2, &moved).await.unwrap());
    let jobs = store.jobs(CAMPAIGN).await.unwrap();
    assert_eq!((jobs[0].format, &jobs[0].spec), (2, &moved));
    assert_eq!((jobs[1].format, &jobs[1].spec), (1, &job(1).spec), "the other job is untouched");
    let claimed = store.claim(CAMPAIGN, "w", None).await.unwrap().unwrap();
    assert_eq!((claimed.format, claimed.spec), (2, moved.clone()));
    store.complete(&claimed.id, "w", &result(0.4), &[]).await.unwrap();
    assert!(!store.replace_spec("job-0000", 2, &json!({})).await.unwrap(), "a done job keeps its spec");
    assert_eq!(store.jobs(CAMPAIGN).await.unwrap()[0].spec, moved);
    store.close().await;
}
