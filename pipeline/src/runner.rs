//! The campaign runner: workers claim pending jobs from the store and run each packing in a
//! blocking task with its own rayon pool, sending heartbeats and checkpoints while it runs. A
//! Ctrl-C returns running jobs to pending; jobs of a killed runner are found by their dead
//! process or their stale heartbeat and run again, from their last checkpoint.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::Context;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use solver::packing::{Packing, PackingResult, Phase};
use store::Store;
use tokio::sync::mpsc;
use tracing::{info, warn};

use crate::meshes;
use crate::records::result_rows;
use crate::spec::JobSpec;
use crate::stored;

/// A running job proves it is alive this often.
const HEARTBEAT: Duration = Duration::from_secs(10);
/// A job whose heartbeat is older than this belongs to a dead runner.
const STALE_AFTER: Duration = Duration::from_secs(60);
/// Time steps between progress reports and cancellation checks (0.05 s simulated at the default Δt).
const STEPS_PER_REPORT: u64 = 10_000;

#[derive(Debug, Clone)]
pub struct RunOptions {
    pub workers: usize,
    /// Wall time between checkpoints of a running packing.
    pub checkpoint_interval: Duration,
}

/// What the runner did.
#[derive(Debug, Default, Clone, Copy)]
pub struct Summary {
    pub completed: usize,
    pub failed: usize,
    pub interrupted: bool,
}

enum Message {
    Progress(solver::packing::Progress),
    Checkpoint(Vec<u8>, f64),
}

enum Outcome {
    Done(Box<PackingResult>),
    Cancelled,
    Failed(String),
}

/// "host:pid:worker" of this process's worker k.
fn worker_id(k: usize) -> String {
    format!("{}:{}:{k}", host(), std::process::id())
}

fn host() -> String {
    hostname::get().map(|h| h.to_string_lossy().into_owned()).unwrap_or_else(|_| "localhost".into())
}

/// Whether the worker that owns a running job is certainly gone: a process of this host whose
/// pid no longer exists.
fn is_dead_local_worker(worker: &str) -> bool {
    let mut parts = worker.rsplitn(3, ':');
    let (_, pid, owner_host) = (parts.next(), parts.next(), parts.next());
    match (owner_host, pid.and_then(|p| p.parse::<u32>().ok())) {
        (Some(h), Some(pid)) => {
            h == host() && pid != std::process::id() && !Path::new(&format!("/proc/{pid}")).exists()
        }
        _ => false,
    }
}

/// Returns the jobs of dead workers to pending; returns how many.
pub async fn recover(store: &Store, campaign: &str) -> anyhow::Result<usize> {
    let mut recovered = 0;
    for job in store.running_jobs(campaign).await? {
        if is_dead_local_worker(&job.worker_id) && store.release(&job.job_id, &job.worker_id).await? {
            info!(job = %job.job_id, worker = %job.worker_id, "requeued the job of a dead worker");
            recovered += 1;
        }
    }
    let stale = store.requeue_stale(campaign, STALE_AFTER).await?;
    for job in &stale {
        info!(job = %job, "requeued a job with a stale heartbeat");
    }
    Ok(recovered + stale.len())
}

/// Runs the campaign's pending jobs on `options.workers` workers until none is left.
pub async fn run(store: &Store, campaign: &str, options: &RunOptions, interactive: bool) -> anyhow::Result<Summary> {
    recover(store, campaign).await?;
    let status = store.status(campaign).await?;
    let cancel = Arc::new(AtomicBool::new(false));
    {
        let cancel = cancel.clone();
        tokio::spawn(async move {
            if tokio::signal::ctrl_c().await.is_ok() {
                eprintln!("sedpack: stopping; running jobs return to pending (Ctrl-C again to quit at once)");
                cancel.store(true, Ordering::SeqCst);
                if tokio::signal::ctrl_c().await.is_ok() {
                    std::process::exit(130);
                }
            }
        });
    }
    let bars = MultiProgress::with_draw_target(if interactive {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    });
    let total = bars.add(ProgressBar::new(status.jobs));
    total.set_style(
        ProgressStyle::with_template("{prefix} [{elapsed_precise}] {bar:30} {pos}/{len} jobs done, ETA {eta}")
            .expect("valid template"),
    );
    total.set_prefix(campaign.to_string());
    total.set_position(status.done + status.failed);

    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let per_worker = (threads / options.workers).max(1);
    let mut handles = Vec::new();
    for k in 0..options.workers {
        let bar = bars.add(ProgressBar::new_spinner());
        bar.set_style(ProgressStyle::with_template("  {prefix} {msg}").expect("valid template"));
        bar.set_prefix(format!("worker {}", k + 1));
        let context = Worker {
            store: store.clone(),
            campaign: campaign.to_string(),
            id: worker_id(k),
            threads: per_worker,
            checkpoint_interval: options.checkpoint_interval,
            cancel: cancel.clone(),
            bar,
            total: total.clone(),
        };
        handles.push(tokio::spawn(context.run()));
    }
    let mut summary = Summary::default();
    for handle in handles {
        let s = handle.await.context("a worker panicked")??;
        summary.completed += s.completed;
        summary.failed += s.failed;
    }
    summary.interrupted = cancel.load(Ordering::SeqCst);
    total.finish_and_clear();
    Ok(summary)
}

struct Worker {
    store: Store,
    campaign: String,
    id: String,
    threads: usize,
    checkpoint_interval: Duration,
    cancel: Arc<AtomicBool>,
    bar: ProgressBar,
    total: ProgressBar,
}

impl Worker {
    async fn run(self) -> anyhow::Result<Summary> {
        let mut summary = Summary::default();
        let pool = Arc::new(rayon::ThreadPoolBuilder::new().num_threads(self.threads).build()?);
        loop {
            if self.cancel.load(Ordering::SeqCst) {
                break;
            }
            let claimed = match self.store.claim(&self.campaign, &self.id).await? {
                Some(job) => job,
                // Nothing pending: jobs of runners that died meanwhile may be waiting.
                None if recover(&self.store, &self.campaign).await? > 0 => continue,
                None => break,
            };
            let label: Vec<String> = claimed.parameters.iter().map(|(k, v)| format!("{k}={v}")).collect();
            let label = format!("{} ({})", claimed.id.get(..8).unwrap_or(&claimed.id), label.join(", "));
            info!(job = %claimed.id, worker = %self.id, attempt = claimed.attempts, "started");
            let outcome = match read_spec(claimed.format, &claimed.spec) {
                Ok(spec) => self.execute(&claimed.id, spec, &label, pool.clone()).await?,
                Err(e) => Outcome::Failed(format!("{e:#}")),
            };
            match outcome {
                Outcome::Done(result) => {
                    let (row, statistics) = result_rows(&result);
                    self.store.complete(&claimed.id, &self.id, &row, &statistics).await?;
                    info!(job = %claimed.id, porosity = result.porosity.bulk, "done");
                    summary.completed += 1;
                    self.total.inc(1);
                }
                Outcome::Cancelled => {
                    if self.store.release(&claimed.id, &self.id).await? {
                        info!(job = %claimed.id, "returned to pending");
                    }
                    if self.cancel.load(Ordering::SeqCst) {
                        break;
                    }
                }
                Outcome::Failed(error) => {
                    warn!(job = %claimed.id, %error, "failed");
                    self.store.fail(&claimed.id, &self.id, &error).await?;
                    summary.failed += 1;
                    self.total.inc(1);
                }
            }
        }
        self.bar.finish_and_clear();
        Ok(summary)
    }

    /// Runs one packing in a blocking task, relaying its progress, heartbeats and checkpoints.
    async fn execute(
        &self,
        job: &str,
        spec: JobSpec,
        label: &str,
        pool: Arc<rayon::ThreadPool>,
    ) -> anyhow::Result<Outcome> {
        let checkpoint = self.store.load_checkpoint(job).await?;
        if let Some(c) = &checkpoint {
            info!(job, simulated_time = c.simulated_time, "resuming from a checkpoint");
        }
        let (sender, mut receiver) = mpsc::channel(4);
        let stop = [self.cancel.clone(), Arc::new(AtomicBool::new(false))];
        let lost = stop[1].clone();
        let interval = self.checkpoint_interval;
        let mut task = tokio::task::spawn_blocking(move || {
            pool.install(|| simulate(spec, checkpoint.map(|c| c.data), &sender, &stop, interval))
        });
        let mut heartbeat = tokio::time::interval(HEARTBEAT);
        loop {
            tokio::select! {
                outcome = &mut task => {
                    return Ok(outcome.unwrap_or_else(|panic| Outcome::Failed(format!("the solver panicked: {panic}"))));
                }
                Some(message) = receiver.recv() => match message {
                    Message::Progress(p) => self.bar.set_message(format!(
                        "{label}: {} t = {:.3} s, {} grains, {} contacts", p.phase.name(), p.time, p.grains, p.contacts
                    )),
                    Message::Checkpoint(data, time) => {
                        if let Err(e) = self.store.save_checkpoint(job, &self.id, &data, time).await {
                            warn!(job, error = %e, "checkpoint not saved; stopping the job");
                            lost.store(true, Ordering::SeqCst);
                        } else {
                            info!(job, simulated_time = time, bytes = data.len(), "checkpoint");
                        }
                    }
                },
                _ = heartbeat.tick() => {
                    // A job taken away (e.g. requeued as stale) must not be finished twice.
                    if let Err(e) = self.store.heartbeat(job, &self.id).await {
                        warn!(job, error = %e, "heartbeat refused; stopping the job");
                        lost.store(true, Ordering::SeqCst);
                    }
                }
            }
        }
    }
}

/// The packing loop of a worker: from a checkpoint or from scratch, reporting progress and
/// writing checkpoints, until converged, failed or cancelled.
fn simulate(
    spec: JobSpec,
    checkpoint: Option<Vec<u8>>,
    sender: &mpsc::Sender<Message>,
    stop: &[Arc<AtomicBool>; 2],
    interval: Duration,
) -> Outcome {
    let restored = checkpoint.and_then(|data| match postcard::from_bytes::<Packing>(&data) {
        Ok(mut packing) if packing.spec() == &spec.packing => {
            // A checkpoint keeps only the digest of the meshes; the job brought them back.
            match &spec.packing.grains.meshes {
                Some(library) => packing.attach_meshes(library).ok().map(|_| packing),
                None => Some(packing),
            }
        }
        _ => {
            warn!("ignoring a checkpoint that does not match the job");
            None
        }
    });
    let mut packing = match restored {
        Some(p) => p,
        None => match Packing::new(spec.packing) {
            Ok(p) => p,
            Err(e) => return Outcome::Failed(e.to_string()),
        },
    };
    let mut last_checkpoint = Instant::now();
    loop {
        match packing.advance(STEPS_PER_REPORT) {
            Ok(Phase::Converged) => break,
            Ok(_) => {}
            Err(e) => return Outcome::Failed(e.to_string()),
        }
        // A full channel only delays the display; the packing never waits for it.
        let _ = sender.try_send(Message::Progress(packing.progress()));
        if stop.iter().any(|s| s.load(Ordering::SeqCst)) {
            return Outcome::Cancelled;
        }
        if last_checkpoint.elapsed() >= interval {
            match postcard::to_allocvec(&packing) {
                Ok(data) => {
                    if sender.blocking_send(Message::Checkpoint(data, packing.simulation.time)).is_err() {
                        return Outcome::Cancelled;
                    }
                }
                Err(e) => warn!(error = %e, "could not serialise a checkpoint"),
            }
            last_checkpoint = Instant::now();
        }
    }
    match packing.result() {
        Ok(result) => Outcome::Done(Box::new(result)),
        Err(e) => Outcome::Failed(e.to_string()),
    }
}

/// A stored job's spec, with its meshes loaded again and checked against their digest.
fn read_spec(format: u32, json: &serde_json::Value) -> anyhow::Result<JobSpec> {
    let mut spec = stored::decode(format, json)?;
    if let Some(library) = &mut spec.packing.grains.meshes {
        meshes::reload(library)?;
    }
    Ok(spec)
}
