//! Done jobs carried from one database to another: `Store::archive` and `Store::import`.

mod common;

use common::*;
use store::{Imported, JobState, Store, StoreError};

/// Jobs 0..4 of which 0, 1 and 2 are done (with distinct results) and 3 is pending.
async fn source(path: &std::path::Path) -> Store {
    let store = store_with_jobs(path, 4).await;
    for porosity in [0.371, 0.383, 0.395] {
        let job = store.claim(CAMPAIGN, "far:1:0", None).await.unwrap().unwrap();
        store.complete(&job.id, "far:1:0", &result(porosity), &statistics(porosity + 0.2)).await.unwrap();
    }
    store
}

#[tokio::test]
async fn an_empty_database_takes_the_done_jobs_as_they_were() {
    let dir = tempfile::tempdir().unwrap();
    let from = source(&dir.path().join("from.db")).await;
    let archived = from.archive(CAMPAIGN).await.unwrap();
    assert_eq!(archived.iter().map(|a| a.job.id.as_str()).collect::<Vec<_>>(), ["job-0000", "job-0001", "job-0002"]);
    assert_eq!(archived[1].job, job(1), "the job as submitted");
    assert_eq!((archived[1].attempts, archived[1].worker_id.as_deref()), (1, Some("far:1:0")));

    let to = Store::open(dir.path().join("to.db")).await.unwrap();
    let imported = to.import(CAMPAIGN, CAMPAIGN_SPEC, &archived).await.unwrap();
    assert_eq!(imported, Imported { added: 3, ..Imported::default() });
    assert_eq!(to.campaign(CAMPAIGN).await.unwrap().spec, CAMPAIGN_SPEC);
    // Every column the export reads is the source's: the done rows are the same rows.
    let done: Vec<_> = from.export(CAMPAIGN).await.unwrap().into_iter().filter(|r| r.state == JobState::Done).collect();
    assert_eq!(to.export(CAMPAIGN).await.unwrap(), done);
    let status = to.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.done, status.pending), (3, 0));
    assert_eq!(status.mean_wall_time_done, Some(42.0), "the packing's own time, not the import's");
    // Importing again changes nothing.
    let again = to.import(CAMPAIGN, "another file", &archived).await.unwrap();
    assert_eq!(again, Imported { kept: 3, ..Imported::default() });
    assert_eq!(to.campaign(CAMPAIGN).await.unwrap().spec, CAMPAIGN_SPEC, "the stored campaign file is kept");
    assert_eq!(to.export(CAMPAIGN).await.unwrap(), done);
    from.close().await;
    to.close().await;
}

#[tokio::test]
async fn pending_and_failed_jobs_are_completed_done_ones_kept_and_running_ones_left() {
    let dir = tempfile::tempdir().unwrap();
    let from = source(&dir.path().join("from.db")).await;
    let archived = from.archive(CAMPAIGN).await.unwrap();

    // Here job 0 stopped with a checkpoint, job 1 failed, job 2 runs; job 3 is done here only.
    let to = store_with_jobs(&dir.path().join("to.db"), 4).await;
    let only = |id: &str| vec![id.to_string()];
    let zero = to.claim(CAMPAIGN, "here:1:0", Some(&only("job-0000"))).await.unwrap().unwrap();
    to.save_checkpoint(&zero.id, "here:1:0", b"state", 1.5, None).await.unwrap();
    assert!(to.release(&zero.id, "here:1:0").await.unwrap());
    let one = to.claim(CAMPAIGN, "here:1:0", Some(&only("job-0001"))).await.unwrap().unwrap();
    to.fail(&one.id, "here:1:0", "solver diverged").await.unwrap();
    let two = to.claim(CAMPAIGN, "here:1:0", Some(&only("job-0002"))).await.unwrap().unwrap();
    let three = to.claim(CAMPAIGN, "here:1:1", Some(&only("job-0003"))).await.unwrap().unwrap();
    to.complete(&three.id, "here:1:1", &result(0.5), &statistics(0.5)).await.unwrap();
    let mut with_three = archived.clone();
    with_three.push(from.archive(CAMPAIGN).await.unwrap()[0].clone());
    with_three[3].job = job(3);
    with_three[3].result = result(0.301);

    let imported = to.import(CAMPAIGN, CAMPAIGN_SPEC, &with_three).await.unwrap();
    assert_eq!(imported, Imported { added: 0, completed: 2, kept: 1, running: vec![two.id.clone()] });
    let rows = to.export(CAMPAIGN).await.unwrap();
    let porosity = |i: usize| rows[i].result.as_ref().map(|r| r.porosity);
    assert_eq!((rows[0].state, porosity(0)), (JobState::Done, Some(0.371)));
    assert_eq!((rows[1].state, porosity(1), rows[1].error.as_deref()), (JobState::Done, Some(0.383), None));
    assert_eq!(rows[1].attempts, 2, "the failed attempt here and the one elsewhere");
    assert_eq!((rows[2].state, porosity(2)), (JobState::Running, None), "left to its worker");
    assert_eq!((rows[3].state, porosity(3)), (JobState::Done, Some(0.5)), "the stored result is kept");
    assert_eq!(to.load_checkpoint(&zero.id).await.unwrap(), None, "a completed job's checkpoint is dropped");
    // The worker of job 2 still finishes it.
    to.complete(&two.id, "here:1:0", &result(0.41), &statistics(0.6)).await.unwrap();
    from.close().await;
    to.close().await;
}

#[tokio::test]
async fn an_id_of_another_campaign_imports_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let from = source(&dir.path().join("from.db")).await;
    let archived = from.archive(CAMPAIGN).await.unwrap();
    let to = Store::open(dir.path().join("to.db")).await.unwrap();
    to.upsert_campaign("other", "").await.unwrap();
    to.add_jobs("other", &[job(2)]).await.unwrap();

    let error = to.import(CAMPAIGN, CAMPAIGN_SPEC, &archived).await.unwrap_err();
    assert!(matches!(error, StoreError::Invalid { .. }), "{error}");
    assert!(error.to_string().contains("job job-0002 already belongs to campaign \"other\""), "{error}");
    assert!(
        matches!(to.campaign(CAMPAIGN).await, Err(StoreError::NoCampaign { .. })),
        "neither the campaign nor jobs 0 and 1 were stored"
    );
    assert_eq!(to.export("other").await.unwrap()[0].state, JobState::Pending);
    from.close().await;
    to.close().await;
}
