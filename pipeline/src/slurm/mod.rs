//! The Slurm executor: a campaign's pending jobs become Slurm job arrays, one task per job,
//! each running `sedpack task` in its job's folder of the run directory beside the database.
//! Compute nodes never open the database: the submitting side keeps it, and brings it up to date
//! from the run directory and Slurm's commands whenever a command touches the campaign.

mod files;
mod handle;
mod scheduler;
mod submit;
mod sync;
pub mod task;
mod watch;

use std::time::Duration;

use serde::Serialize;
use store::{JobState, Store};

pub use files::EventKind;
pub use files::RunDir;
pub use submit::{Submission, Submitted};
pub use sync::sync;
pub use watch::{Followed, follow};

use handle::Handle;

fn host() -> String {
    hostname::get().map(|h| h.to_string_lossy().into_owned()).unwrap_or_else(|_| "localhost".into())
}

/// A job of a Slurm campaign beside its task's state in Slurm, for `status`.
#[derive(Debug, Clone, Serialize)]
pub struct TaskRow {
    pub job_id: String,
    /// sedpack's state.
    pub state: JobState,
    /// The Slurm task, `ARRAY_INDEX`, that runs or ran the job last.
    pub task: Option<String>,
    /// Slurm's state of that task, where Slurm still knows it.
    pub slurm_state: Option<String>,
    pub slurm_reason: Option<String>,
    /// The last event the task itself recorded in the job's folder: started, stopped,
    /// terminated, failed or done.
    pub task_record: Option<EventKind>,
}

/// Every job of the campaign with the Slurm task that has it or had it last, Slurm's word on it
/// (None where Slurm cannot be asked) and the task's own record.
pub async fn task_rows(store: &Store, run: &RunDir, campaign: &str) -> anyhow::Result<Vec<TaskRow>> {
    let jobs = store.jobs(campaign).await?;
    let handles: Vec<Option<Handle>> = jobs.iter().map(|j| j.worker_id.as_deref().and_then(Handle::parse)).collect();
    let tasks: Vec<String> = handles.iter().flatten().filter_map(Handle::task).collect();
    // The caller has already warned when Slurm cannot be asked.
    let slurm = scheduler::states(&tasks).unwrap_or_default();
    Ok(jobs
        .into_iter()
        .zip(handles)
        .map(|(job, handle)| {
            let task = handle.as_ref().and_then(Handle::task);
            let said = task.as_ref().and_then(|t| slurm.get(t));
            let submitting = matches!(handle, Some(Handle::Submitting { .. })) && job.state == JobState::Running;
            let record = task.as_ref().and_then(|t| run.job(&job.id).events().into_iter().rev().find(|e| &e.task == t));
            TaskRow {
                state: job.state,
                slurm_state: said.map(|s| s.state.clone()).or(submitting.then(|| "submitting".into())),
                slurm_reason: said.and_then(|s| s.reason.clone()),
                task_record: record.map(|e| e.kind),
                task,
                job_id: job.id,
            }
        })
        .collect())
}

/// What `sedpack cancel` did.
#[derive(Debug, Default)]
pub struct Cancelled {
    /// Jobs returned to pending.
    pub pending: usize,
    /// Jobs whose result came in meanwhile.
    pub done: usize,
    /// Tasks Slurm had not ended when cancel stopped waiting; their jobs stay running.
    pub still_ending: Vec<String>,
}

/// How long `cancel` waits for cancelled tasks to write their checkpoint and end.
const CANCEL_WAIT: Duration = Duration::from_secs(120);

/// Cancels the campaign's Slurm tasks, waits for them to end, ingests results that came in
/// meanwhile and returns the other jobs to pending, checkpoints kept.
pub async fn cancel(store: &Store, run: &RunDir, campaign: &str) -> anyhow::Result<Cancelled> {
    sync(store, run, campaign).await?;
    let held: Vec<(String, Handle)> = store
        .running_jobs(campaign)
        .await?
        .into_iter()
        .filter_map(|r| Some((r.job_id, Handle::parse(&r.worker_id)?)))
        .collect();
    let tasks: Vec<String> = held.iter().filter_map(|(_, h)| h.task()).collect();
    scheduler::scancel(&tasks)?;
    let spinner = indicatif::ProgressBar::new_spinner();
    spinner.set_message(format!("waiting for {} cancelled task(s) to end", tasks.len()));
    let deadline = std::time::Instant::now() + CANCEL_WAIT;
    let still = loop {
        let active: Vec<String> = scheduler::states(&tasks)?
            .into_values()
            .filter(|t| t.is_active() && tasks.contains(&t.task))
            .map(|t| t.task)
            .collect();
        if active.is_empty() || std::time::Instant::now() > deadline {
            break active;
        }
        spinner.tick();
        tokio::time::sleep(Duration::from_secs(1)).await;
    };
    spinner.finish_and_clear();
    let (done, _) = sync::ingest(store, run, campaign).await?;
    let mut cancelled = Cancelled { done, ..Cancelled::default() };
    for (job, handle) in held {
        let Some(task) = handle.task() else { continue };
        if still.contains(&task) {
            cancelled.still_ending.push(task);
        } else if store.release(&job, &handle.to_string()).await? {
            cancelled.pending += 1;
        }
    }
    Ok(cancelled)
}
