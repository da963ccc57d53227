//! `--wait`: following a Slurm campaign until its submitted jobs end, with a progress bar for
//! the campaign, a line of Slurm's states and one line per running task; jobs that stopped
//! before their time limit are submitted again on the way.

use std::collections::{BTreeMap, HashMap};
use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use store::Store;

use super::handle::Handle;
use super::scheduler::TaskState;
use super::submit::Submission;
use super::sync::{Synced, sync};
use crate::output::phase_words;

/// How often the run directory and Slurm are looked at.
const POLL: Duration = Duration::from_secs(3);
/// Running tasks shown, one line each.
const TASK_LINES: usize = 8;

/// Whether following ended because every submitted job did, or because of Ctrl-C.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Followed {
    Ended,
    Interrupted,
}

pub async fn follow(submission: &Submission<'_>, interactive: bool) -> anyhow::Result<Followed> {
    let (store, campaign) = (submission.store, submission.campaign);
    let bars = MultiProgress::with_draw_target(if interactive {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    let total = bars.add(ProgressBar::new(0));
    total.set_style(
        ProgressStyle::with_template("{prefix} [{elapsed_precise}] {bar:30} {pos}/{len} jobs done, ETA {eta}")
            .expect("valid template"),
    );
    total.set_prefix(campaign.to_string());
    let line = |bar: ProgressBar| {
        bar.set_style(ProgressStyle::with_template("  {msg}").expect("valid template"));
        bars.add(bar)
    };
    let queue = line(ProgressBar::new_spinner());
    let tasks: Vec<ProgressBar> = (0..TASK_LINES).map(|_| line(ProgressBar::new_spinner())).collect();
    let ctrl_c = tokio::signal::ctrl_c();
    tokio::pin!(ctrl_c);
    let followed = loop {
        let mut running = HashMap::new();
        match sync(store, submission.run, campaign).await {
            Ok(synced) => {
                if !synced.stopped.is_empty() {
                    let again = submission.pending(Some(&synced.stopped)).await?;
                    for s in again {
                        bars.println(format!(
                            "{campaign}: array {} submitted again: {} job(s) that stopped before their time limit",
                            s.array, s.jobs
                        ))?;
                    }
                }
                queue.set_message(slurm_line(&synced));
                running = synced.tasks;
            }
            // The controller may come back (a restart): say so and keep following.
            Err(e) => queue.set_message(format!("slurm: {e:#} (trying again)")),
        }
        let status = store.status(campaign).await?;
        total.set_length(status.jobs);
        total.set_position(status.done + status.failed);
        show_tasks(store, submission, &running, &tasks).await?;
        if status.running == 0 {
            break Followed::Ended;
        }
        tokio::select! {
            _ = tokio::time::sleep(POLL) => {}
            _ = &mut ctrl_c => break Followed::Interrupted,
        }
    };
    for bar in tasks.iter().chain([&queue, &total]) {
        bar.finish_and_clear();
    }
    Ok(followed)
}

/// Slurm's states of the campaign's tasks, counted: "slurm: 2 RUNNING, 6 PENDING (JobArrayTaskLimit)".
fn slurm_line(synced: &Synced) -> String {
    let mut counts: BTreeMap<String, usize> = BTreeMap::new();
    for t in synced.tasks.values().filter(|t| t.is_active()) {
        let reason = t.reason.as_ref().map(|r| format!(" ({r})")).unwrap_or_default();
        *counts.entry(format!("{}{reason}", t.state)).or_default() += 1;
    }
    let counts: Vec<String> = counts.iter().map(|(state, n)| format!("{n} {state}")).collect();
    format!("slurm: {}", if counts.is_empty() { "no task queued or running".into() } else { counts.join(", ") })
}

/// One line per task Slurm runs, from the progress file it writes.
async fn show_tasks(
    store: &Store,
    submission: &Submission<'_>,
    slurm: &HashMap<String, TaskState>,
    lines: &[ProgressBar],
) -> anyhow::Result<()> {
    let held = store.running_jobs(submission.campaign).await?;
    let mut shown = held.iter().filter_map(|r| {
        let task = Handle::parse(&r.worker_id)?.task()?;
        slurm.get(&task).filter(|t| t.state == "RUNNING")?;
        let p = submission.run.job(&r.job_id).progress()?;
        let id = r.job_id.get(..8).unwrap_or(&r.job_id);
        let mass = p.mass_created.map(|m| format!(" ({:.0} % of the mass)", 100.0 * m)).unwrap_or_default();
        Some(format!(
            "task {task}, job {id}: {} t = {:.3} s, {} grains{mass}, {} contacts",
            phase_words(&p.phase, p.shaking_until),
            p.time,
            p.grains,
            p.contacts
        ))
    });
    for line in lines {
        line.set_message(shown.next().unwrap_or_default());
    }
    Ok(())
}
