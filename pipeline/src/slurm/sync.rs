//! Bringing a Slurm campaign's store up to date with the cluster, whenever a command touches
//! the campaign: results found in the run directory are ingested, one transaction per job, each
//! once (the job is then done and no longer looked for); tasks that ended without a result are
//! judged from Slurm's word (squeue, and sacct where accounting exists) and from the task's own
//! files, which remain when Slurm has forgotten the task; submissions interrupted before their
//! jobs were handed to their tasks are found again.

use std::collections::HashMap;
use std::path::Path;
use std::time::Duration;

use store::{Store, StoreError};
use tracing::{info, warn};

use super::files::{Event, EventKind, RunDir, TaskResult, file_name, tail};
use super::handle::Handle;
use super::scheduler::{self, TaskState};
use super::submit::comment;

/// A submission of another host whose job is still held this long after its claim is taken
/// for interrupted (the process cannot be checked from here).
const LOST_AFTER: Duration = Duration::from_secs(3600);

/// What a sync found and did.
#[derive(Debug, Default)]
pub struct Synced {
    /// Slurm's word on the campaign's tasks it knows, by `ARRAY_INDEX`.
    pub tasks: HashMap<String, TaskState>,
    /// Results ingested now.
    pub done: usize,
    /// Jobs failed now.
    pub failed: usize,
    /// Jobs that stopped before their time limit and are pending again, to be submitted again.
    pub stopped: Vec<String>,
}

/// A running job of the campaign and who holds it.
struct Held {
    job: String,
    handle: Handle,
    heartbeat_at: f64,
}

async fn held(store: &Store, campaign: &str) -> anyhow::Result<Vec<Held>> {
    Ok(store
        .running_jobs(campaign)
        .await?
        .into_iter()
        .filter_map(|r| {
            Some(Held { handle: Handle::parse(&r.worker_id)?, job: r.job_id, heartbeat_at: r.heartbeat_at })
        })
        .collect())
}

/// Ingests every result in the run directory of a job the campaign still runs: needs no Slurm.
/// Gives how many, and the result files that cannot be used, by job.
pub async fn ingest(store: &Store, run: &RunDir, campaign: &str) -> anyhow::Result<(usize, HashMap<String, String>)> {
    let mut done = 0;
    let mut rejected = HashMap::new();
    for held in held(store, campaign).await? {
        match run.job(&held.job).read_result() {
            Ok(Some(result)) => done += usize::from(record(store, &held, &result).await?),
            Ok(None) => {}
            Err(e) => {
                rejected.insert(held.job, format!("{e:#}"));
            }
        }
    }
    Ok((done, rejected))
}

/// Records a result in one transaction; false if another process recorded it first.
async fn record(store: &Store, held: &Held, r: &TaskResult) -> anyhow::Result<bool> {
    let ran = (r.started_at, r.finished_at);
    match store.complete_ran(&held.job, &held.handle.to_string(), ran, &r.result, &r.grain_statistics).await {
        Ok(()) => {
            info!(job = %held.job, task = %r.task, porosity = r.result.porosity, "result ingested");
            Ok(true)
        }
        Err(StoreError::NotOwner { .. }) => Ok(false),
        Err(e) => Err(e.into()),
    }
}

/// Ingests results, finds interrupted submissions again, and judges tasks that ended without a
/// result. Results are ingested before Slurm is asked, so they are in even when Slurm's
/// commands fail.
pub async fn sync(store: &Store, run: &RunDir, campaign: &str) -> anyhow::Result<Synced> {
    let (done, rejected) = ingest(store, run, campaign).await?;
    let mut synced = Synced { done, ..Synced::default() };
    recover_submissions(store, run, campaign).await?;

    let held: Vec<Held> = held(store, campaign).await?;
    let tasks: Vec<String> = held.iter().filter_map(|h| h.handle.task()).collect();
    synced.tasks = scheduler::states(&tasks)?;
    let ended: Vec<(&Held, String)> = held
        .iter()
        .filter_map(|h| Some((h, h.handle.task()?)))
        .filter(|(_, task)| synced.tasks.get(task).is_none_or(|t| !t.is_active()))
        .collect();
    for (held, task) in ended {
        let worker = held.handle.to_string();
        let dir = run.job(&held.job);
        // A result that came in since the ingestion above.
        if let Ok(Some(result)) = dir.read_result() {
            synced.done += usize::from(record(store, held, &result).await?);
            continue;
        }
        let verdict = match rejected.get(&held.job) {
            Some(why) => {
                let aside = dir.set_aside_result().map_or_else(
                    |e| format!("could not be set aside: {e}"),
                    |p| format!("set aside as {}", p.display()),
                );
                Verdict::Failed(format!("task {task} left a result that cannot be used ({aside}): {why}"))
            }
            None => verdict(&task, synced.tasks.get(&task), &dir.events(), &run.log(&task)),
        };
        match verdict {
            Verdict::Pending(why) => {
                if store.release(&held.job, &worker).await? {
                    info!(job = %held.job, %task, "pending again: {why}");
                    synced.stopped.push(held.job.clone());
                }
            }
            Verdict::Failed(why) => match store.fail(&held.job, &worker, &why).await {
                Ok(()) => {
                    warn!(job = %held.job, %task, "failed: {why}");
                    synced.failed += 1;
                }
                Err(StoreError::NotOwner { .. }) => {}
                Err(e) => return Err(e.into()),
            },
        }
    }
    Ok(synced)
}

/// Jobs held by submissions whose process is gone: handed to their array task if sbatch had
/// taken the array, returned to pending if it had not.
async fn recover_submissions(store: &Store, run: &RunDir, campaign: &str) -> anyhow::Result<()> {
    let now = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default().as_secs_f64();
    let mut lost: HashMap<String, Vec<(Held, usize)>> = HashMap::new();
    for held in held(store, campaign).await? {
        let Handle::Submitting { host, pid, token, index } = &held.handle else { continue };
        let gone = if *host == super::host() {
            *pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists()
        } else {
            now - held.heartbeat_at > LOST_AFTER.as_secs_f64()
        };
        if gone {
            let (token, index) = (token.clone(), *index);
            lost.entry(token).or_default().push((held, index));
        }
    }
    for (token, jobs) in lost {
        let array = scheduler::find_submission(&file_name(campaign), &comment(&token))?;
        for (held, index) in jobs {
            // The task's own events name its array when the controller has forgotten it.
            let task = match &array {
                Some(array) => Some(Handle::Task { array: array.clone(), index }),
                None => run
                    .job(&held.job)
                    .events()
                    .iter()
                    .rev()
                    .find(|e| e.submission == token)
                    .and_then(|e| Handle::parse(&format!("slurm:{}", e.task))),
            };
            let worker = held.handle.to_string();
            match task {
                Some(task) => {
                    if store.reassign(&held.job, &worker, &task.to_string()).await? {
                        info!(job = %held.job, %task, "found the task of an interrupted submission");
                    }
                }
                None => {
                    if store.release(&held.job, &worker).await? {
                        info!(job = %held.job, "an interrupted submission never reached Slurm: pending again");
                    }
                }
            }
        }
    }
    Ok(())
}

/// What becomes of a job whose task ended without a result.
#[derive(Debug, PartialEq)]
pub(crate) enum Verdict {
    /// Stopped before its time limit, its checkpoint written: to be submitted again.
    Pending(String),
    Failed(String),
}

/// Judges a task that ended without a result from Slurm's word (None: Slurm no longer knows
/// it), the job's events and the task's output file.
pub(crate) fn verdict(task: &str, slurm: Option<&TaskState>, events: &[Event], log: &Path) -> Verdict {
    let last = events.iter().rev().find(|e| e.task == task);
    let detail = |e: &Event| e.detail.clone().unwrap_or_default();
    match last {
        Some(e) if e.kind == EventKind::Stopped => return Verdict::Pending(detail(e)),
        Some(e) if e.kind == EventKind::Failed => return Verdict::Failed(format!("task {task} failed: {}", detail(e))),
        _ => {}
    }
    let said = match slurm {
        Some(s) => {
            let reason = s.reason.as_ref().map(|r| format!(" ({r})")).unwrap_or_default();
            let exit = s.exit_code.as_ref().map(|x| format!(", exit code {x}")).unwrap_or_default();
            format!("Slurm says {}{reason}{exit}", s.state)
        }
        None => "Slurm no longer lists it (no accounting, and it ended more than MinJobAge ago)".into(),
    };
    let own = match last {
        Some(e) if e.kind == EventKind::Terminated => {
            format!("the task was stopped: {}; `--retry-failed` continues from the checkpoint", detail(e))
        }
        Some(e) if e.kind == EventKind::Done => "the task said it was done but left no result".into(),
        Some(e) => format!("the task started on {} and ended without a word (killed?)", e.host),
        None => "the task never started".into(),
    };
    let output = match tail(log, 3) {
        Some(lines) => format!("output {}: {lines}", log.display()),
        None if last.is_none() => format!(
            "no output file {}: is the run directory on a file system that the compute nodes share?",
            log.display()
        ),
        None => format!("no output file {}", log.display()),
    };
    Verdict::Failed(format!("task {task} ended without a result: {said}; {own}; {output}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn event(kind: EventKind, detail: Option<&str>) -> Event {
        Event {
            task: "7_1".into(),
            submission: "s".into(),
            kind,
            at: 1.0,
            host: "node3".into(),
            restarts: 0,
            detail: detail.map(String::from),
        }
    }

    fn slurm(state: &str, reason: Option<&str>, exit: Option<&str>) -> TaskState {
        TaskState {
            task: "7_1".into(),
            state: state.into(),
            reason: reason.map(String::from),
            exit_code: exit.map(String::from),
        }
    }

    #[test]
    fn a_task_stopped_before_its_time_limit_goes_back_to_pending() {
        let events = [event(EventKind::Started, None), event(EventKind::Stopped, Some("the time limit is near"))];
        let log = Path::new("/nowhere/7_1.out");
        assert_eq!(
            verdict("7_1", Some(&slurm("COMPLETED", None, Some("0:0"))), &events, log),
            Verdict::Pending("the time limit is near".into())
        );
        // Only this task's events count: an earlier task's stop says nothing of this one.
        let Verdict::Failed(why) = verdict("7_2", None, &events, log) else { panic!("failed") };
        assert!(why.contains("task 7_2") && why.contains("never started"), "{why}");
    }

    #[test]
    fn failures_give_slurms_word_the_tasks_and_its_output() {
        let dir = tempfile::tempdir().unwrap();
        let log = dir.path().join("7_1.out");
        std::fs::write(
            &log,
            "sedpack task 7_1 on node3\n\nslurmstepd: *** JOB 9 ON node3 CANCELLED AT 2026 DUE TO TIME LIMIT ***\n",
        )
        .unwrap();
        let started = event(EventKind::Started, None);
        let terminated = event(EventKind::Terminated, Some("SIGTERM: checkpoint written at t = 0.2 s"));
        let Verdict::Failed(why) =
            verdict("7_1", Some(&slurm("TIMEOUT", Some("TimeLimit"), None)), &[started.clone(), terminated], &log)
        else {
            panic!("failed")
        };
        assert!(why.starts_with("task 7_1 ended without a result: Slurm says TIMEOUT (TimeLimit);"), "{why}");
        assert!(why.contains("checkpoint written at t = 0.2 s; `--retry-failed` continues"), "{why}");
        assert!(why.contains("DUE TO TIME LIMIT ***") && why.contains("sedpack task 7_1 on node3 |"), "{why}");

        let Verdict::Failed(why) = verdict("7_1", None, std::slice::from_ref(&started), &log) else { panic!() };
        assert!(why.contains("Slurm no longer lists it") && why.contains("started on node3 and ended without a word"));
        let failed = event(EventKind::Failed, Some("not converged after solver.max_time = 0.02 s"));
        assert_eq!(
            verdict("7_1", Some(&slurm("FAILED", Some("NonZeroExitCode"), Some("1:0"))), &[started, failed], &log),
            Verdict::Failed("task 7_1 failed: not converged after solver.max_time = 0.02 s".into())
        );
        let Verdict::Failed(why) =
            verdict("7_1", Some(&slurm("FAILED", None, Some("0:53"))), &[], &dir.path().join("x.out"))
        else {
            panic!()
        };
        assert!(why.contains("never started") && why.contains("x.out: is the run directory on a file system"), "{why}");
    }
}
