//! `sedpack task JOB_DIR`: what each Slurm array task runs. It reads the job from its folder,
//! continues from the folder's checkpoint if there is one, and leaves the result there, written
//! atomically; it never opens the database. SIGUSR1 (asked for before the time limit) and SIGTERM
//! (scancel, time limit, requeue, preemption) make it write a checkpoint and exit.

use std::sync::Arc;
use std::sync::atomic::{AtomicU8, Ordering};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{Context, anyhow};
use solver::packing::Progress;
use tokio::signal::unix::{SignalKind, signal};

use super::files::{Event, EventKind, JobDir, RESULT_FORMAT, TaskJob, TaskProgress, TaskResult, write_atomically};
use crate::cli::TaskArgs;
use crate::records::result_rows;
use crate::runner::{Observer, Outcome, checkpoint_data, simulate};
use crate::spec::JobSpec;
use crate::{meshes, stored};

/// How often a running task rewrites its progress file.
const PROGRESS_EVERY: Duration = Duration::from_secs(10);
/// The exit status of a process ended by SIGTERM, kept when it ends itself on SIGTERM.
const TERMINATED: i32 = 128 + 15;

const RUNNING: u8 = 0;
const TIME_LIMIT_NEAR: u8 = 1;
const TERMINATING: u8 = 2;

/// The Slurm task this process is, as its environment says.
struct Me {
    task: String,
    submission: String,
    host: String,
    restarts: u32,
}

impl Me {
    fn event(&self, kind: EventKind, detail: Option<String>) -> Event {
        Event {
            task: self.task.clone(),
            submission: self.submission.clone(),
            kind,
            at: now(),
            host: self.host.clone(),
            restarts: self.restarts,
            detail,
        }
    }
}

pub fn run(args: &TaskArgs) -> anyhow::Result<()> {
    let env = |name: &str| std::env::var(name).ok();
    let me = Me {
        task: match (env("SLURM_ARRAY_JOB_ID"), env("SLURM_ARRAY_TASK_ID")) {
            (Some(array), Some(index)) => format!("{array}_{index}"),
            _ => "outside-slurm".into(),
        },
        submission: args.submission.clone().unwrap_or_default(),
        host: hostname::get().map(|h| h.to_string_lossy().into_owned()).unwrap_or_default(),
        restarts: env("SLURM_RESTART_COUNT").and_then(|n| n.parse().ok()).unwrap_or(0),
    };
    let dir = JobDir { path: std::path::absolute(&args.job_dir)? };
    let interval = Duration::try_from_secs_f64(args.checkpoint_interval)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| anyhow!("--checkpoint-interval: expected a positive number of seconds"))?;
    let threads = args.threads.max(1);
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build()?;
    let stop = Arc::new(AtomicU8::new(RUNNING));
    let code = runtime.block_on(async {
        // Before any work: a signal that came earlier would end the task without a checkpoint.
        let mut usr1 = signal(SignalKind::user_defined1())?;
        let mut term = signal(SignalKind::terminate())?;
        let job = dir.read_job()?;
        if dir.read_result().ok().flatten().is_some() {
            println!("sedpack task {}: job {} is already done ({})", me.task, job.id, dir.result().display());
            return Ok(0);
        }
        println!(
            "sedpack task {} on {} (restart {}): job {} of campaign {}",
            me.task, me.host, me.restarts, job.id, job.campaign
        );
        dir.append_event(&me.event(EventKind::Started, None)).with_context(|| format!("{}", dir.path.display()))?;
        let started_at = now();
        let mut work = {
            let (dir, stop) = (dir.clone(), stop.clone());
            tokio::task::spawn_blocking(move || {
                let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build()?;
                pool.install(|| run_job(&job, &dir, stop, interval))
            })
        };
        let outcome = loop {
            tokio::select! {
                _ = usr1.recv() => stop.store(TIME_LIMIT_NEAR, Ordering::SeqCst),
                _ = term.recv() => stop.store(TERMINATING, Ordering::SeqCst),
                outcome = &mut work => break outcome.map_err(|panic| anyhow!("the task panicked: {panic}"))?,
            }
        };
        finish(&dir, &me, outcome?, started_at, stop.load(Ordering::SeqCst))
    })?;
    if code != 0 {
        std::process::exit(code);
    }
    Ok(())
}

/// The job of the folder, checked against its id, with its meshes read through the shared
/// file system; then the packing loop.
fn run_job(job: &TaskJob, dir: &JobDir, stop: Arc<AtomicU8>, interval: Duration) -> anyhow::Result<Outcome> {
    let spec = match job_spec(job) {
        Ok(spec) => spec,
        Err(e) => return Ok(Outcome::Failed(format!("{e:#}"))),
    };
    let checkpoint = std::fs::read(dir.checkpoint()).ok();
    let mut observer = TaskObserver { dir, stop, last_progress: None };
    Ok(simulate(&job.id, spec, checkpoint.as_deref(), &mut observer, interval))
}

fn job_spec(job: &TaskJob) -> anyhow::Result<JobSpec> {
    let mut spec = stored::decode(job.format, &job.spec).context("job.json")?;
    let id = stored::job_id(&spec);
    // A format 1 job with a mesh folder keeps the id sedpack 0.1.0 gave it.
    if id != job.id && !(job.format == 1 && spec.packing.grains.meshes.is_some()) {
        return Err(anyhow!("job.json: its spec is job {id}'s, not job {}'s", job.id));
    }
    if let Some(library) = &mut spec.packing.grains.meshes {
        meshes::reload(library)
            .context("the mesh folder must be readable from the compute nodes (a shared file system)")?;
    }
    Ok(spec)
}

/// Records how the packing ended and gives the exit status.
fn finish(dir: &JobDir, me: &Me, outcome: Outcome, started_at: f64, stop: u8) -> anyhow::Result<i32> {
    let job = dir.id();
    match outcome {
        Outcome::Done(result) => {
            let (row, grain_statistics) = result_rows(&result);
            let porosity = row.porosity;
            let result = TaskResult {
                result_format: RESULT_FORMAT,
                job: job.clone(),
                task: me.task.clone(),
                started_at,
                finished_at: now(),
                result: row,
                grain_statistics,
            };
            dir.write_result(&result)?;
            dir.append_event(&me.event(EventKind::Done, None))?;
            // The result holds everything now.
            let _ = std::fs::remove_file(dir.checkpoint());
            let _ = std::fs::remove_file(dir.progress_file());
            println!("sedpack task {}: job {job} done, porosity {porosity}", me.task);
            Ok(0)
        }
        Outcome::Failed(error) => {
            dir.append_event(&me.event(EventKind::Failed, Some(error.clone())))?;
            // As on the local workers: a retry starts afresh rather than from the state that failed.
            let _ = std::fs::remove_file(dir.checkpoint());
            let _ = std::fs::remove_file(dir.progress_file());
            Err(anyhow!("job {job}: {error}"))
        }
        Outcome::Stopped(packing) => {
            let time = packing.simulation.time;
            write_atomically(&dir.checkpoint(), &checkpoint_data(&packing)?)?;
            let (kind, why, code) = if stop == TIME_LIMIT_NEAR {
                (EventKind::Stopped, "the time limit is near (SIGUSR1)", 0)
            } else {
                (EventKind::Terminated, "SIGTERM (cancelled, time limit, requeue or preemption)", TERMINATED)
            };
            let detail = format!("{why}: checkpoint written at t = {time:.4} s of simulated time");
            dir.append_event(&me.event(kind, Some(detail.clone())))?;
            println!("sedpack task {}: job {job} stopped: {detail}", me.task);
            Ok(code)
        }
    }
}

/// A task's packing writes its checkpoints and progress into the job's folder and stops when a
/// signal came.
struct TaskObserver<'a> {
    dir: &'a JobDir,
    stop: Arc<AtomicU8>,
    last_progress: Option<Instant>,
}

impl Observer for TaskObserver<'_> {
    fn progress(&mut self, p: Progress) {
        if self.last_progress.is_some_and(|t| t.elapsed() < PROGRESS_EVERY) {
            return;
        }
        self.last_progress = Some(Instant::now());
        let progress = TaskProgress {
            phase: p.phase.name().into(),
            time: p.time,
            grains: p.grains,
            contacts: p.contacts,
            mass_created: Some(p.created),
            shaking_until: p.shaking_until,
        };
        // Progress is for display only: a failed write is retried next time.
        let _ = self.dir.write_progress(&progress);
    }

    fn checkpoint(&mut self, data: Vec<u8>, _progress: Progress) -> bool {
        // Going on without this checkpoint still ends in a result; the next one may succeed.
        if let Err(e) = write_atomically(&self.dir.checkpoint(), &data) {
            eprintln!("sedpack: warning: {e:#}");
        }
        true
    }

    fn warning(&mut self, text: String) {
        eprintln!("sedpack: warning: job {}: {text}", self.dir.id());
    }

    fn stop_requested(&self) -> bool {
        self.stop.load(Ordering::SeqCst) != RUNNING
    }
}

fn now() -> f64 {
    SystemTime::now().duration_since(UNIX_EPOCH).unwrap_or_default().as_secs_f64()
}
