//! Separate processes on one file, as two `sedpack run` would be: they split the work without
//! duplicates, and a process killed mid-job loses nothing it finished. The children are this test
//! binary run again on an ignored test, told what to do through environment variables.

mod common;

use std::process::{Command, Stdio};
use std::time::Duration;

use common::*;
use store::{JobState, Store};

const CHILD_DB: &str = "STORE_TEST_CHILD_DB";
const CHILD_WORKER: &str = "STORE_TEST_CHILD_WORKER";
const CHILD_REPORT: &str = "STORE_TEST_CHILD_REPORT";
const PROCESS_JOBS: usize = 60;

/// The database, worker id and report file a parent test gave this child process; None when the
/// ignored child test runs on its own.
fn child_task() -> Option<(String, String, String)> {
    Some((std::env::var(CHILD_DB).ok()?, std::env::var(CHILD_WORKER).ok()?, std::env::var(CHILD_REPORT).ok()?))
}

/// Run by `separate_processes_split_the_work` in child processes, as `sedpack run` would:
/// open (maybe a new file), submit the campaign, then work. Reports how many jobs it added, then
/// the ids it completed, one a line.
#[tokio::test]
#[ignore = "a child process of separate_processes_split_the_work"]
async fn child_process_runner() {
    let Some((path, worker_id, report)) = child_task() else { return };
    let store = Store::open(&path).await.unwrap();
    store.upsert_campaign(CAMPAIGN, CAMPAIGN_SPEC).await.unwrap();
    let added = store.add_jobs(CAMPAIGN, &jobs(0..PROCESS_JOBS)).await.unwrap();
    let completed = work(store.clone(), worker_id).await;
    store.close().await;
    std::fs::write(report, format!("{added}\n{}", completed.join("\n"))).unwrap();
}

#[test]
fn separate_processes_split_the_work() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    let reports: Vec<_> = (0..3).map(|index| dir.path().join(format!("process{index}.txt"))).collect();
    let children: Vec<_> = reports
        .iter()
        .enumerate()
        .map(|(index, report)| {
            Command::new(std::env::current_exe().unwrap())
                .args(["child_process_runner", "--exact", "--ignored", "--test-threads=1"])
                .env(CHILD_DB, &path)
                .env(CHILD_WORKER, format!("process{index}"))
                .env(CHILD_REPORT, report)
                .stdout(Stdio::null())
                .spawn()
                .unwrap()
        })
        .collect();
    for mut child in children {
        assert!(child.wait().unwrap().success(), "a child process failed");
    }
    let mut added = 0;
    let mut completed = Vec::new();
    for report in reports {
        let report = std::fs::read_to_string(report).unwrap();
        let mut lines = report.lines();
        added += lines.next().unwrap().parse::<usize>().unwrap();
        completed.extend(lines.map(String::from));
    }
    assert_eq!(added, PROCESS_JOBS, "the campaign's jobs were added more than once in total");
    tokio::runtime::Runtime::new().unwrap().block_on(assert_each_job_done_once(&path, PROCESS_JOBS, &completed));
}

/// Run by `a_killed_process_loses_no_finished_job`: completes three jobs, saves a checkpoint of
/// the fourth, says so, and waits to be killed.
#[tokio::test]
#[ignore = "a child process of a_killed_process_loses_no_finished_job"]
async fn child_process_killed() {
    let Some((path, worker_id, report)) = child_task() else { return };
    let store = Store::open(&path).await.unwrap();
    for _ in 0..3 {
        let job = store.claim(CAMPAIGN, &worker_id, None).await.unwrap().unwrap();
        store.complete(&job.id, &worker_id, &result(0.36), &statistics(0.5)).await.unwrap();
    }
    let job = store.claim(CAMPAIGN, &worker_id, None).await.unwrap().unwrap();
    store.save_checkpoint(&job.id, &worker_id, b"mid-packing", 4.0, None).await.unwrap();
    std::fs::write(report, "ready").unwrap();
    tokio::time::sleep(Duration::from_secs(600)).await;
}

#[test]
fn a_killed_process_loses_no_finished_job() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    let runtime = tokio::runtime::Runtime::new().unwrap();
    runtime.block_on(async { store_with_jobs(&path, 5).await.close().await });
    let ready = dir.path().join("ready");
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["child_process_killed", "--exact", "--ignored", "--test-threads=1"])
        .env(CHILD_DB, &path)
        .env(CHILD_WORKER, "doomed")
        .env(CHILD_REPORT, &ready)
        .stdout(Stdio::null())
        .spawn()
        .unwrap();
    while !ready.exists() {
        assert!(child.try_wait().unwrap().is_none(), "the child ended before it was killed");
        std::thread::sleep(Duration::from_millis(20));
    }
    // SIGKILL on Unix: no destructor runs, the pool is never closed.
    child.kill().unwrap();
    child.wait().unwrap();

    runtime.block_on(async {
        let store = Store::open(&path).await.unwrap();
        let status = store.status(CAMPAIGN).await.unwrap();
        assert_eq!((status.done, status.running, status.pending), (3, 1, 1));
        let running = store.running_jobs(CAMPAIGN).await.unwrap();
        assert_eq!((running[0].job_id.as_str(), running[0].worker_id.as_str()), ("job-0003", "doomed"));

        // Resume: the dead worker's job goes back to the queue and continues from its checkpoint.
        assert_eq!(store.requeue_stale(CAMPAIGN, Duration::ZERO).await.unwrap(), ["job-0003"]);
        let job = store.claim(CAMPAIGN, "heir", None).await.unwrap().unwrap();
        assert_eq!((job.id.as_str(), job.attempts), ("job-0003", 2));
        assert_eq!(store.load_checkpoint(&job.id).await.unwrap().unwrap().data, b"mid-packing");
        store.complete(&job.id, "heir", &result(0.37), &statistics(0.5)).await.unwrap();
        let last = store.claim(CAMPAIGN, "heir", None).await.unwrap().unwrap();
        store.complete(&last.id, "heir", &result(0.38), &statistics(0.5)).await.unwrap();

        let rows = store.export(CAMPAIGN).await.unwrap();
        assert!(rows.iter().all(|row| row.state == JobState::Done && row.result.is_some()));
        let porosities: Vec<f64> = rows.iter().map(|row| row.result.as_ref().unwrap().porosity).collect();
        assert_eq!(porosities, [0.36, 0.36, 0.36, 0.37, 0.38]);
        store.close().await;
    });
}
