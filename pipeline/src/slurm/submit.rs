//! Submitting pending jobs as Slurm job arrays: at most MaxArraySize tasks per array, each task
//! one job. The jobs are claimed in the store first (held by this submission), their folders
//! and the batch script written, then sbatch is run and each job handed to its array task. A
//! submission interrupted between the claim and the hand-over is found again by the next sync
//! (`super::sync`), through the job name and comment it gave Slurm.

use std::time::{Duration, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use store::{ClaimedJob, Store};
use tracing::info;

use super::files::{RunDir, TaskJob, file_name, write_atomically};
use super::handle::Handle;
use super::scheduler;
use crate::executor::SlurmSettings;

/// One array submitted.
#[derive(Debug, Clone, PartialEq)]
pub struct Submitted {
    pub array: String,
    pub jobs: usize,
}

/// How the jobs of a campaign are submitted.
pub struct Submission<'a> {
    pub store: &'a Store,
    pub run: &'a RunDir,
    pub campaign: &'a str,
    pub settings: &'a SlurmSettings,
    pub checkpoint_interval: Duration,
}

/// The comment a submission gives its array, by which an interrupted submission is found.
pub fn comment(token: &str) -> String {
    format!("sedpack:{token}")
}

impl Submission<'_> {
    /// Submits the campaign's pending jobs (those of `only`, if given); gives the arrays. When
    /// sbatch refuses an array, its jobs return to pending and the error says why.
    pub async fn pending(&self, only: Option<&[String]>) -> anyhow::Result<Vec<Submitted>> {
        // Asked before any job is claimed: no Slurm, nothing claimed.
        let size = scheduler::max_array_size()?;
        let mut submitted = Vec::new();
        let mut previous: Option<String> = None;
        loop {
            let token = token();
            let (host, pid) = (super::host(), std::process::id());
            let handle = |index| Handle::Submitting { host: host.clone(), pid, token: token.clone(), index };
            let jobs = self.store.claim_many(self.campaign, only, size, |k| handle(k).to_string()).await?;
            if jobs.is_empty() {
                break;
            }
            let array = match self.array(&jobs, &token, previous.as_deref()) {
                Ok(array) => array,
                Err(e) => {
                    for (k, job) in jobs.iter().enumerate() {
                        self.store.release(&job.id, &handle(k).to_string()).await?;
                    }
                    let kept = submitted.iter().map(|s: &Submitted| s.array.as_str()).collect::<Vec<_>>().join(", ");
                    let kept = if kept.is_empty() { String::new() } else { format!(" (arrays {kept} were submitted)") };
                    return Err(e.context(format!(
                        "nothing was submitted for {} job(s), which are pending again{kept}",
                        jobs.len()
                    )));
                }
            };
            for (k, job) in jobs.iter().enumerate() {
                let task = Handle::Task { array: array.clone(), index: k };
                self.store.reassign(&job.id, &handle(k).to_string(), &task.to_string()).await?;
            }
            info!(campaign = self.campaign, array = %array, jobs = jobs.len(), "submitted");
            submitted.push(Submitted { array: array.clone(), jobs: jobs.len() });
            // With a throttle, arrays run one after another so that it holds for all of them.
            previous = self.settings.max_parallel.map(|_| array);
            if jobs.len() < size {
                break;
            }
        }
        Ok(submitted)
    }

    /// Writes the jobs' folders and the batch script and submits them as one array.
    fn array(&self, jobs: &[ClaimedJob], token: &str, after: Option<&str>) -> anyhow::Result<String> {
        let run = self.run;
        for job in jobs {
            let task_job = TaskJob {
                id: job.id.clone(),
                campaign: self.campaign.into(),
                format: job.format,
                spec: job.spec.clone(),
            };
            run.job(&job.id).write_job(&task_job)?;
        }
        for folder in [run.logs(), run.submissions()] {
            std::fs::create_dir_all(&folder).with_context(|| format!("{}", folder.display()))?;
        }
        let s = self.settings;
        let mut args = vec![
            format!("--job-name={}", file_name(self.campaign)),
            format!("--comment={}", comment(token)),
            match s.max_parallel {
                Some(n) => format!("--array=0-{}%{n}", jobs.len() - 1),
                None => format!("--array=0-{}", jobs.len() - 1),
            },
            format!("--cpus-per-task={}", s.cpus_per_task),
            // Requeued and preempted tasks run again and continue from their checkpoint.
            "--requeue".into(),
            // A rerun adds to the task's output rather than truncating it.
            "--open-mode=append".into(),
            format!("--output={}", run.logs().join("%A_%a.out").display()),
        ];
        if let Some(time) = s.time {
            args.push(format!("--time={time}"));
            // To the batch shell, which the task replaces (exec): the task itself gets it.
            args.push(format!("--signal=B:USR1@{}", time.signal_lead()));
        }
        if let Some(previous) = after {
            args.push(format!("--dependency=afterany:{previous}"));
        }
        args.extend(s.sbatch_args()?);
        let script = run.submissions().join(format!("{token}.sh"));
        write_atomically(&script, self.script(jobs, token, &args)?.as_bytes())?;
        args.push(script.display().to_string());
        scheduler::sbatch(&args)
    }

    fn script(&self, jobs: &[ClaimedJob], token: &str, args: &[String]) -> anyhow::Result<String> {
        let quote = |text: &str| shlex::try_quote(text).map(|q| q.into_owned()).context("a path with a NUL byte");
        let exe = std::env::current_exe().context("the path of the sedpack binary")?;
        let ids: Vec<&str> = jobs.iter().map(|j| j.id.as_str()).collect();
        Ok(format!(
            "#!/bin/bash\n\
             # sedpack: campaign {campaign:?}, submission {token}, {n} job(s); submitted as\n\
             #   sbatch --parsable {args} {this}\n\
             # Task k runs the job jobs[k] in its folder of the run directory.\n\
             jobs=({ids})\n\
             run={run}\n\
             exec {exe} task \"$run/${{jobs[$SLURM_ARRAY_TASK_ID]}}\" --threads {threads} \
             --checkpoint-interval {interval} --submission {token}\n",
            campaign = self.campaign,
            n = jobs.len(),
            args = args.iter().map(|a| quote(a)).collect::<anyhow::Result<Vec<_>>>()?.join(" "),
            this = quote(&format!("{token}.sh"))?,
            ids = ids.join(" "),
            run = quote(&self.run.path.display().to_string())?,
            exe = quote(&exe.display().to_string())?,
            threads = self.settings.cpus_per_task,
            interval = self.checkpoint_interval.as_secs_f64(),
        ))
    }
}

/// A token no other submission has: the time in nanoseconds and this process's id.
fn token() -> String {
    let nanos = SystemTime::now().duration_since(UNIX_EPOCH).unwrap_or_default().as_nanos();
    format!("{nanos:x}{:x}", std::process::id())
}
