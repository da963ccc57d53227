//! The job queue on one database: submission, claims, ownership, requeues, status, export, checkpoints.

mod common;

use std::time::Duration;

use common::*;
use serde_json::json;
use store::{JobResult, JobState, Stage, Store, StoreError};

#[tokio::test]
async fn campaigns_are_upserted_by_name() {
    let dir = tempfile::tempdir().unwrap();
    let store = Store::open(db_path(&dir)).await.unwrap();
    store.upsert_campaign(CAMPAIGN, "first").await.unwrap();
    let first = store.campaign(CAMPAIGN).await.unwrap();
    tokio::time::sleep(Duration::from_millis(20)).await;
    store.upsert_campaign(CAMPAIGN, CAMPAIGN_SPEC).await.unwrap();
    store.upsert_campaign("b-campaign", "other").await.unwrap();

    let campaigns = store.campaigns().await.unwrap();
    assert_eq!(campaigns.iter().map(|c| c.name.as_str()).collect::<Vec<_>>(), [CAMPAIGN, "b-campaign"]);
    assert_eq!(campaigns[0].spec, CAMPAIGN_SPEC);
    assert_eq!(campaigns[0].created_at, first.created_at);
    assert!(campaigns[0].updated_at > first.updated_at);

    let missing = store.campaign("nope").await.unwrap_err();
    assert!(matches!(missing, StoreError::NoCampaign { .. }));
    assert!(missing.to_string().contains("sedpack.db") && missing.to_string().contains("nope"), "{missing}");
    assert!(matches!(store.add_jobs("nope", &jobs(0..1)).await, Err(StoreError::NoCampaign { .. })));
    store.close().await;
}

#[tokio::test]
async fn resubmitting_adds_nothing_and_a_superset_adds_only_the_new_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 4).await;
    assert_eq!(store.add_jobs(CAMPAIGN, &jobs(0..4)).await.unwrap(), 0);
    assert_eq!(store.add_jobs(CAMPAIGN, &jobs(0..7)).await.unwrap(), 3);
    assert_eq!(store.status(CAMPAIGN).await.unwrap().jobs, 7);

    // A finished job stays finished when the campaign is submitted again.
    let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.complete(&claimed.id, "w1", &result(0.4), &[]).await.unwrap();
    assert_eq!(store.add_jobs(CAMPAIGN, &jobs(0..7)).await.unwrap(), 0);
    assert_eq!(store.status(CAMPAIGN).await.unwrap().done, 1);

    // An id already used by another campaign is refused, and the whole batch with it.
    store.upsert_campaign("other", "").await.unwrap();
    let error = store.add_jobs("other", &[job(100), job(1)]).await.unwrap_err();
    assert!(matches!(error, StoreError::Invalid { .. }));
    assert!(error.to_string().contains("job-0001") && error.to_string().contains(CAMPAIGN), "{error}");
    assert_eq!(store.status("other").await.unwrap().jobs, 0);
    store.close().await;
}

/// A job keeps its id when its campaign's grid gains an axis, and takes the new grid values: done
/// or not, with its result untouched; another campaign's job with the same id is not changed.
#[tokio::test]
async fn stored_jobs_take_the_grid_values_of_the_campaign_file_submitted_again() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 3).await;
    let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.complete(&claimed.id, "w1", &result(0.4), &[]).await.unwrap();
    let wider = |k: usize| {
        let mut p = job(k).parameters;
        p.insert("material.friction".into(), json!(0.5));
        (job(k).id, p)
    };
    let labels: Vec<_> = (0..3).map(wider).collect();
    assert_eq!(store.set_parameters(CAMPAIGN, &labels).await.unwrap(), 3);
    let rows = store.export(CAMPAIGN).await.unwrap();
    for (row, (id, parameters)) in rows.iter().zip(&labels) {
        assert_eq!((&row.job_id, &row.parameters), (id, parameters));
    }
    assert_eq!(rows[0].result.as_ref().map(|r| r.porosity), Some(0.4), "the done job keeps its result");
    assert_eq!(rows[0].state, JobState::Done);
    // Unchanged values change nothing; another campaign's ids are not touched.
    assert_eq!(store.set_parameters(CAMPAIGN, &labels).await.unwrap(), 0);
    store.upsert_campaign("other", "").await.unwrap();
    assert_eq!(store.set_parameters("other", &[(job(1).id, job(1).parameters)]).await.unwrap(), 0);
    assert_eq!(store.export(CAMPAIGN).await.unwrap()[1].parameters, labels[1].1);
    store.close().await;
}

#[tokio::test]
async fn claims_follow_submission_order_and_carry_the_job() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 3).await;
    for index in 0..3 {
        let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
        let expected = job(index);
        assert_eq!(claimed.id, expected.id);
        assert_eq!((claimed.format, &claimed.spec), (expected.format, &expected.spec));
        assert_eq!(claimed.seed, expected.seed);
        assert_eq!(claimed.parameters, expected.parameters);
        assert_eq!(claimed.attempts, 1);
    }
    assert_eq!(store.claim(CAMPAIGN, "w1", None).await.unwrap(), None);
    let running = store.running_jobs(CAMPAIGN).await.unwrap();
    assert_eq!(running.len(), 3);
    assert!(running.iter().all(|job| job.worker_id == "w1" && job.heartbeat_at >= job.started_at));
    store.close().await;
}

#[tokio::test]
async fn a_claim_limited_to_some_jobs_takes_only_those_in_submission_order() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 5).await;
    let only = [job(3).id, job(1).id];
    let first = store.claim(CAMPAIGN, "w1", Some(&only)).await.unwrap().unwrap();
    let second = store.claim(CAMPAIGN, "w1", Some(&only)).await.unwrap().unwrap();
    assert_eq!((first.id, second.id), (job(1).id, job(3).id), "submission order, not the order asked");
    assert_eq!(store.claim(CAMPAIGN, "w1", Some(&only)).await.unwrap(), None, "the others stay pending");
    assert_eq!(store.status(CAMPAIGN).await.unwrap().pending, 3);
    assert_eq!(store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap().id, job(0).id);
    store.close().await;
}

#[tokio::test]
async fn a_worker_that_lost_its_job_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 1).await;
    let first = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.save_checkpoint(&first.id, "w1", b"w1 state", 1.0, None).await.unwrap();

    // The caller decided w1 is gone; w2 takes the job over from w1's checkpoint.
    assert!(store.release(&first.id, "w1").await.unwrap());
    let second = store.claim(CAMPAIGN, "w2", None).await.unwrap().unwrap();
    assert_eq!((second.id.as_str(), second.attempts), (first.id.as_str(), 2));

    for outcome in [
        store.complete(&first.id, "w1", &result(0.99), &statistics(0.9)).await,
        store.fail(&first.id, "w1", "w1 failed").await,
        store.heartbeat(&first.id, "w1").await,
        store.save_checkpoint(&first.id, "w1", b"stale", 2.0, None).await,
    ] {
        let error = outcome.unwrap_err();
        assert!(matches!(error, StoreError::NotOwner { .. }), "{error:?}");
        assert!(error.to_string().contains(&first.id) && error.to_string().contains("w1"), "{error}");
    }
    assert!(!store.release(&first.id, "w1").await.unwrap());
    assert_eq!(store.load_checkpoint(&first.id).await.unwrap().unwrap().data, b"w1 state");
    let row = &store.export(CAMPAIGN).await.unwrap()[0];
    assert_eq!((row.state, &row.result, &row.error), (JobState::Running, &None, &None));
    assert!(row.grain_statistics.is_empty());

    store.heartbeat(&second.id, "w2").await.unwrap();
    store.complete(&second.id, "w2", &result(0.38), &statistics(0.6)).await.unwrap();
    // Once done, nobody writes again, the owner included: one result per job.
    assert!(matches!(
        store.complete(&second.id, "w2", &result(0.5), &statistics(0.5)).await,
        Err(StoreError::NotOwner { .. })
    ));
    let row = &store.export(CAMPAIGN).await.unwrap()[0];
    assert_eq!(row.state, JobState::Done);
    assert_eq!(row.result, Some(result(0.38)));
    assert_eq!(row.grain_statistics, statistics(0.6));
    assert_eq!(store.load_checkpoint(&first.id).await.unwrap(), None, "done jobs keep no checkpoint");
    store.close().await;
}

#[tokio::test]
async fn stale_heartbeats_are_requeued_and_live_ones_kept() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 3).await;
    let dead = store.claim(CAMPAIGN, "dead", None).await.unwrap().unwrap();
    let alive = store.claim(CAMPAIGN, "alive", None).await.unwrap().unwrap();
    tokio::time::sleep(Duration::from_millis(1200)).await;
    store.heartbeat(&alive.id, "alive").await.unwrap();

    assert_eq!(store.requeue_stale(CAMPAIGN, Duration::from_secs(1)).await.unwrap(), [dead.id.as_str()]);
    let running = store.running_jobs(CAMPAIGN).await.unwrap();
    assert_eq!(running.len(), 1);
    assert_eq!((running[0].job_id.as_str(), running[0].worker_id.as_str()), (alive.id.as_str(), "alive"));
    assert!(running[0].heartbeat_at - running[0].started_at >= 1.0);

    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.pending, status.running), (2, 1));
    // The requeued job is first in line again, on its second attempt.
    let again = store.claim(CAMPAIGN, "new", None).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempts), (dead.id, 2));
    assert!(store.requeue_stale(CAMPAIGN, Duration::from_secs(60)).await.unwrap().is_empty());
    store.close().await;
}

#[tokio::test]
async fn released_jobs_return_to_pending_with_their_checkpoint() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 2).await;
    let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.save_checkpoint(&claimed.id, "w1", b"half way", 3.0, None).await.unwrap();
    assert!(!store.release(&claimed.id, "someone else").await.unwrap());
    assert!(store.release(&claimed.id, "w1").await.unwrap());
    assert!(!store.release(&claimed.id, "w1").await.unwrap());

    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.pending, status.running), (2, 0));
    assert!(store.running_jobs(CAMPAIGN).await.unwrap().is_empty());
    let checkpoint = store.load_checkpoint(&claimed.id).await.unwrap().unwrap();
    assert_eq!((checkpoint.data.as_slice(), checkpoint.simulated_time), (&b"half way"[..], 3.0));
    let again = store.claim(CAMPAIGN, "w2", None).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempts), (claimed.id, 2));
    store.close().await;
}

#[tokio::test]
async fn status_says_how_far_running_and_interrupted_jobs_are() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 4).await;
    let a = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    let b = store.claim(CAMPAIGN, "w2", None).await.unwrap().unwrap();
    let c = store.claim(CAMPAIGN, "w3", None).await.unwrap().unwrap();
    let stage = Stage { phase: "generation".into(), grains: 1972, mass_created: 0.382, shaking_until: None };
    let shaking = Stage { phase: "shaking".into(), grains: 5100, mass_created: 1.0, shaking_until: Some(6.25) };
    store.save_checkpoint(&a.id, "w1", b"a", 1.5, Some(&stage)).await.unwrap();
    store.save_checkpoint(&b.id, "w2", b"b", 5.5, Some(&shaking)).await.unwrap();
    store.save_checkpoint(&c.id, "w3", b"c", 0.5, Some(&stage)).await.unwrap();
    // A checkpoint that does not say where it stood replaces the last one's stage too.
    store.save_checkpoint(&c.id, "w3", b"c", 0.75, None).await.unwrap();
    let in_progress = store.status(CAMPAIGN).await.unwrap().in_progress;
    let seen: Vec<_> = in_progress
        .iter()
        .map(|p| (p.job_id.as_str(), p.state, p.worker_id.as_deref(), p.checkpoint.map(|c| c.0)))
        .collect();
    assert_eq!(
        seen,
        [
            (a.id.as_str(), JobState::Running, Some("w1"), Some(1.5)),
            (b.id.as_str(), JobState::Running, Some("w2"), Some(5.5)),
            (c.id.as_str(), JobState::Running, Some("w3"), Some(0.75)),
        ],
        "the fourth job, pending without a checkpoint, is not in progress"
    );
    let stages: Vec<_> = in_progress.iter().map(|p| p.stage.clone()).collect();
    assert_eq!(stages, [Some(stage.clone()), Some(shaking), None]);
    assert!(in_progress.iter().all(|p| p.started_at.is_some() && p.attempts == 1));

    // Stopped with its checkpoint, a job stays in progress as pending; a failed one leaves.
    store.release(&a.id, "w1").await.unwrap();
    store.fail(&b.id, "w2", "diverged").await.unwrap();
    let in_progress = store.status(CAMPAIGN).await.unwrap().in_progress;
    let seen: Vec<_> = in_progress.iter().map(|p| (p.job_id.as_str(), p.state, p.worker_id.as_deref())).collect();
    assert_eq!(seen, [(a.id.as_str(), JobState::Pending, None), (c.id.as_str(), JobState::Running, Some("w3"))]);
    assert_eq!((in_progress[0].started_at, in_progress[0].checkpoint.map(|c| c.0)), (None, Some(1.5)));
    assert_eq!(in_progress[0].stage, Some(stage), "a stopped job keeps its checkpoint's stage");
    store.close().await;
}

#[tokio::test]
async fn failed_jobs_keep_their_error_until_retried() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 2).await;
    let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.save_checkpoint(&claimed.id, "w1", b"before the crash", 1.0, None).await.unwrap();
    store.fail(&claimed.id, "w1", "no packing surface found").await.unwrap();
    assert!(matches!(store.fail(&claimed.id, "w1", "again").await, Err(StoreError::NotOwner { .. })));
    assert_eq!(store.load_checkpoint(&claimed.id).await.unwrap(), None, "a retry starts afresh");

    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.pending, status.failed), (1, 1));
    assert_eq!(status.failures.len(), 1);
    assert_eq!(status.failures[0].job_id, claimed.id);
    assert_eq!(status.failures[0].error, "no packing surface found");
    assert_eq!(status.failures[0].attempts, 1);
    let row = &store.export(CAMPAIGN).await.unwrap()[0];
    assert_eq!((row.state, row.error.as_deref()), (JobState::Failed, Some("no packing surface found")));

    assert_eq!(store.requeue_failed(CAMPAIGN).await.unwrap(), 1);
    assert_eq!(store.requeue_failed(CAMPAIGN).await.unwrap(), 0);
    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.pending, status.failed, status.failures.len()), (2, 0, 0));
    let row = &store.export(CAMPAIGN).await.unwrap()[0];
    assert_eq!((row.state, &row.error), (JobState::Pending, &None));
    let again = store.claim(CAMPAIGN, "w2", None).await.unwrap().unwrap();
    assert_eq!((again.id, again.attempts), (claimed.id, 2));
    store.close().await;
}

#[tokio::test]
async fn status_counts_states_and_times_finished_jobs() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 5).await;
    let empty = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((empty.jobs, empty.pending, empty.wall_time_finished, empty.mean_wall_time_done), (5, 5, 0.0, None));

    let done_a = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    let done_b = store.claim(CAMPAIGN, "w2", None).await.unwrap().unwrap();
    let failed = store.claim(CAMPAIGN, "w3", None).await.unwrap().unwrap();
    let _running = store.claim(CAMPAIGN, "w4", None).await.unwrap().unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;
    store.complete(&done_a.id, "w1", &result(0.37), &[]).await.unwrap();
    store.complete(&done_b.id, "w2", &JobResult { simulated_time: 8.5, ..result(0.39) }, &[]).await.unwrap();
    store.fail(&failed.id, "w3", "bad mesh").await.unwrap();

    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!(status.campaign, CAMPAIGN);
    assert_eq!((status.jobs, status.pending, status.running, status.done, status.failed), (5, 1, 1, 2, 1));
    // Done jobs count their packing's own time (the results say 42 s each, however long the
    // last attempt took); the failed job its last attempt (0.3 s or a little more).
    assert_eq!(status.mean_wall_time_done, Some(42.0));
    // Their simulated times, 7.5 s and 8.5 s, average to 8 s; the failed job has none.
    assert_eq!((empty.mean_simulated_time_done, status.mean_simulated_time_done), (None, Some(8.0)));
    assert!((84.3..94.0).contains(&status.wall_time_finished), "{status:?}");
    let json = serde_json::to_value(&status).unwrap();
    for key in ["campaign", "jobs", "pending", "running", "done", "failed"] {
        assert!(json.get(key).is_some(), "{key} missing from {json}");
    }
    assert!(matches!(store.status("nope").await, Err(StoreError::NoCampaign { .. })));
    store.close().await;
}

#[tokio::test]
async fn export_gives_every_job_with_its_result_and_statistics() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 3).await;
    store.upsert_campaign("other", "").await.unwrap();
    store.add_jobs("other", &[job(50)]).await.unwrap();
    let first = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    let second = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    let imbricated = JobResult {
        imbrication: Some(json!({"mean_dip": 21.5, "upstream": 0.6})),
        size_classes: Some(json!([{"lower": 0.0056, "upper": 0.008, "asked": 1.0, "grains": 40, "mass": 0.02}])),
        ..result(0.371)
    };
    store.complete(&first.id, "w1", &imbricated, &statistics(0.647)).await.unwrap();
    store.fail(&second.id, "w1", "solver diverged").await.unwrap();

    let rows = store.export(CAMPAIGN).await.unwrap();
    assert_eq!(rows.iter().map(|row| row.job_id.clone()).collect::<Vec<_>>(), ["job-0000", "job-0001", "job-0002"]);
    for (index, row) in rows.iter().enumerate() {
        let submitted = job(index);
        assert_eq!((&row.parameters, row.seed), (&submitted.parameters, submitted.seed));
        assert_eq!(
            (row.experiment_porosity, row.experiment_std),
            (submitted.experiment_porosity, submitted.experiment_std)
        );
        assert_eq!(row.fluid, submitted.fluid);
    }
    assert!(rows[0].fluid.is_some() && rows[1].fluid.is_none());
    assert_eq!(rows[0].state, JobState::Done);
    assert_eq!(rows[0].result, Some(imbricated));
    assert_eq!(rows[0].grain_statistics, statistics(0.647));
    assert_eq!(
        (rows[1].state, rows[1].error.as_deref(), &rows[1].result),
        (JobState::Failed, Some("solver diverged"), &None)
    );
    assert_eq!((rows[2].state, rows[2].attempts, &rows[2].result), (JobState::Pending, 0, &None));
    assert!(rows[2].grain_statistics.is_empty());

    // Rows serialize for the pipeline's CSV and JSON: parameters by dotted key, lowercase states.
    let json = serde_json::to_value(&rows[0]).unwrap();
    assert_eq!(json["state"], "done");
    assert_eq!(json["parameters"]["grains.form.mu_fl"], 0.4);
    assert_eq!(json["result"]["profile"][1]["n"], 0.371);
    assert_eq!(store.export("other").await.unwrap().len(), 1);
    store.close().await;
}

#[tokio::test]
async fn checkpoints_round_trip_and_are_overwritten() {
    let dir = tempfile::tempdir().unwrap();
    let store = store_with_jobs(&db_path(&dir), 1).await;
    let claimed = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    assert_eq!(store.load_checkpoint(&claimed.id).await.unwrap(), None);

    let first: Vec<u8> = (0..=255).cycle().take(100_000).collect();
    store.save_checkpoint(&claimed.id, "w1", &first, 1.25, None).await.unwrap();
    let loaded = store.load_checkpoint(&claimed.id).await.unwrap().unwrap();
    assert_eq!((loaded.data, loaded.simulated_time), (first, 1.25));

    store.save_checkpoint(&claimed.id, "w1", b"later", 2.5, None).await.unwrap();
    let loaded_again = store.load_checkpoint(&claimed.id).await.unwrap().unwrap();
    assert_eq!((loaded_again.data.as_slice(), loaded_again.simulated_time), (&b"later"[..], 2.5));
    assert!(loaded_again.written_at >= loaded.written_at);
    // Saving a checkpoint is a heartbeat too.
    let running = &store.running_jobs(CAMPAIGN).await.unwrap()[0];
    assert_eq!(running.heartbeat_at, loaded_again.written_at);

    assert!(store.delete_checkpoint(&claimed.id).await.unwrap());
    assert!(!store.delete_checkpoint(&claimed.id).await.unwrap());
    assert_eq!(store.load_checkpoint(&claimed.id).await.unwrap(), None);
    store.close().await;
}
