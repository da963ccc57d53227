//! Many claimers in one process, each Store with its own pool, get each job once; simultaneous
//! first opens of a new file all succeed.

mod common;

use common::*;
use store::Store;

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn concurrent_claimers_on_separate_pools_get_each_job_once() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    const JOBS: usize = 200;
    store_with_jobs(&path, JOBS).await.close().await;

    let mut tasks = Vec::new();
    for pool in 0..4 {
        let store = Store::open(&path).await.unwrap();
        for task in 0..8 {
            tasks.push(tokio::spawn(work(store.clone(), format!("pool{pool}-task{task}"))));
        }
    }
    let mut completed = Vec::new();
    for task in tasks {
        completed.extend(task.await.unwrap());
    }
    assert_each_job_done_once(&path, JOBS, &completed).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 4)]
async fn simultaneous_first_opens_of_a_new_file_all_succeed() {
    for round in 0..10 {
        let dir = tempfile::tempdir().unwrap();
        let path = db_path(&dir);
        let opens: Vec<_> = (0..4)
            .map(|_| {
                let path = path.clone();
                tokio::spawn(async move {
                    let store = Store::open(&path).await?;
                    store.upsert_campaign(CAMPAIGN, CAMPAIGN_SPEC).await?;
                    let added = store.add_jobs(CAMPAIGN, &jobs(0..10)).await?;
                    store.close().await;
                    Ok::<u64, store::StoreError>(added)
                })
            })
            .collect();
        let mut added = 0;
        for open in opens {
            added += open.await.unwrap().unwrap_or_else(|e| panic!("round {round}: {e}"));
        }
        assert_eq!(added, 10, "round {round}: the jobs were added more than once in total");
    }
}
