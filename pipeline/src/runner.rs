//! The campaign runner: workers claim pending jobs from the store and run each packing in a
//! blocking task with its own rayon pool, sending heartbeats and checkpoints while it runs. A
//! Ctrl-C returns running jobs to pending, and so does a worker that fails (a store error): it
//! stops the others, which return their jobs too. Jobs of a killed runner are found by their
//! dead process or their stale heartbeat and run again from their last checkpoint. A checkpoint
//! another version of sedpack wrote holds work this version cannot continue: such a job stops
//! the run, job and checkpoint untouched, unless the user asks to start it over.

use std::path::Path;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use anyhow::anyhow;
use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};
use solver::packing::{Packing, PackingResult, Phase, Progress};
use store::{ClaimedJob, JobState, Stage, Store};
use tokio::sync::mpsc;
use tracing::{info, warn};

use crate::meshes;
use crate::output::phase_words;
use crate::records::result_rows;
use crate::spec::JobSpec;
use crate::stored;

/// A running job proves it is alive this often.
const HEARTBEAT: Duration = Duration::from_secs(10);
/// A job whose heartbeat is older than this belongs to a dead runner.
pub const STALE_AFTER: Duration = Duration::from_secs(60);
/// Time steps between progress reports and stop checks (0.01 s simulated at the default Δt), few
/// enough that a large packing stops within seconds when Slurm's time limit nears.
const STEPS_PER_REPORT: u64 = 2_000;
/// A checkpoint is this number followed by the packing; a checkpoint with another number was
/// written by another version of sedpack and is not used. Raise it whenever `Packing`'s
/// serialised form changes.
pub const CHECKPOINT_FORMAT: u32 = 13;

#[derive(Debug, Clone)]
pub struct RunOptions {
    pub workers: usize,
    /// Threads of each worker's packing.
    pub threads: usize,
    /// Wall time between checkpoints of a running packing.
    pub checkpoint_interval: Duration,
    /// Start over the jobs whose checkpoints another version of sedpack wrote; without it such
    /// a job stops the run before its packing starts, job and checkpoint left as they were.
    pub discard_old_checkpoints: bool,
    /// Run only these jobs (`--only`); the others stay pending.
    pub only: Option<Vec<String>>,
}

/// A pending job's checkpoint that this version cannot continue.
#[derive(Debug, Clone, PartialEq)]
pub struct OldCheckpoint {
    pub job: String,
    /// The format number it starts with.
    pub format: u32,
    /// Where the packing was, when the store knows.
    pub simulated_time: Option<f64>,
}

/// The format of a checkpoint another version of sedpack wrote; `None` for this version's and
/// for bytes that do not start with a format number (unreadable: nothing in them to keep).
pub fn old_format(data: &[u8]) -> Option<u32> {
    postcard::take_from_bytes::<u32>(data).ok().map(|(format, _)| format).filter(|&f| f != CHECKPOINT_FORMAT)
}

/// An error naming the jobs whose checkpoints hold packing work this version would throw away,
/// and what to do; `Ok` when there are none.
pub fn refuse_old_checkpoints(campaign: &str, old: &[OldCheckpoint]) -> anyhow::Result<()> {
    if old.is_empty() {
        return Ok(());
    }
    const SHOWN: usize = 5;
    let mut named: Vec<String> = old
        .iter()
        .take(SHOWN)
        .map(|c| match c.simulated_time {
            Some(t) => format!("{} (format {}, at t = {t:.2} s)", c.job, c.format),
            None => format!("{} (format {})", c.job, c.format),
        })
        .collect();
    if old.len() > SHOWN {
        named.push(format!("and {} more", old.len() - SHOWN));
    }
    Err(anyhow!(
        "{campaign}: {} pending job(s) have a checkpoint written by another version of sedpack, which this \
         version (checkpoint format {CHECKPOINT_FORMAT}) cannot continue: {}. These jobs and their checkpoints \
         are left as they were. To keep that packing work, resume with the sedpack that wrote the checkpoints; to start \
         these jobs over, pass --discard-old-checkpoints",
        old.len(),
        named.join(", ")
    ))
}

/// The campaign's pending jobs whose stored checkpoints this version cannot continue.
pub async fn old_checkpoints(store: &Store, campaign: &str) -> anyhow::Result<Vec<OldCheckpoint>> {
    let mut old = Vec::new();
    for job in store.jobs(campaign).await?.into_iter().filter(|j| j.state == JobState::Pending) {
        if let Some(checkpoint) = store.load_checkpoint(&job.id).await?
            && let Some(format) = old_format(&checkpoint.data)
        {
            old.push(OldCheckpoint { job: job.id, format, simulated_time: Some(checkpoint.simulated_time) });
        }
    }
    Ok(old)
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
    /// A checkpoint and where the packing stood when it was taken.
    Checkpoint(Vec<u8>, Progress),
    /// Something the user should know, such as a checkpoint that cannot be used.
    Warning(String),
}

/// How a packing loop ended.
pub(crate) enum Outcome {
    Done(Box<PackingResult>),
    /// Asked to stop, or its checkpoint could not be kept: the packing as it stands.
    Stopped(Box<Packing>),
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
                eprintln!(
                    "sedpack: stopping; running jobs write a checkpoint and return to pending (Ctrl-C again to quit at once)"
                );
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

    let mut handles = Vec::new();
    for k in 0..options.workers {
        let bar = bars.add(ProgressBar::new_spinner());
        bar.set_style(ProgressStyle::with_template("  {prefix} {msg}").expect("valid template"));
        bar.set_prefix(format!("worker {}", k + 1));
        let context = Worker {
            store: store.clone(),
            campaign: campaign.to_string(),
            id: worker_id(k),
            threads: options.threads,
            checkpoint_interval: options.checkpoint_interval,
            discard_old_checkpoints: options.discard_old_checkpoints,
            only: options.only.clone(),
            cancel: cancel.clone(),
            bar,
            total: total.clone(),
        };
        handles.push(tokio::spawn(context.run()));
    }
    // A worker that fails has already told the others to stop; wait for all of them, so that
    // every job is back to pending before the error is reported.
    let mut summary = Summary::default();
    let mut failure = None;
    for handle in handles {
        match handle.await.map_err(|panic| anyhow!("a worker panicked: {panic}")).and_then(|r| r) {
            Ok(s) => {
                summary.completed += s.completed;
                summary.failed += s.failed;
            }
            Err(e) => {
                cancel.store(true, Ordering::SeqCst);
                failure.get_or_insert(e);
            }
        }
    }
    total.finish_and_clear();
    if let Some(e) = failure {
        return Err(e);
    }
    summary.interrupted = cancel.load(Ordering::SeqCst);
    Ok(summary)
}

struct Worker {
    store: Store,
    campaign: String,
    id: String,
    threads: usize,
    checkpoint_interval: Duration,
    discard_old_checkpoints: bool,
    only: Option<Vec<String>>,
    cancel: Arc<AtomicBool>,
    bar: ProgressBar,
    total: ProgressBar,
}

impl Worker {
    /// Works until no job is left or the run is stopped; on an error, tells the other workers
    /// to stop before returning it.
    async fn run(self) -> anyhow::Result<Summary> {
        let result = self.work().await;
        if result.is_err() {
            self.cancel.store(true, Ordering::SeqCst);
        }
        self.bar.finish_and_clear();
        result
    }

    async fn work(&self) -> anyhow::Result<Summary> {
        let mut summary = Summary::default();
        let pool = Arc::new(rayon::ThreadPoolBuilder::new().num_threads(self.threads).build()?);
        while !self.cancel.load(Ordering::SeqCst) {
            let claimed = match self.store.claim(&self.campaign, &self.id, self.only.as_deref()).await? {
                Some(job) => job,
                // Nothing pending: jobs of runners that died meanwhile may be waiting.
                None if recover(&self.store, &self.campaign).await? > 0 => continue,
                None => break,
            };
            if let Err(e) = self.handle(&claimed, pool.clone(), &mut summary).await {
                // The job goes back to pending now rather than after a stale-heartbeat recovery.
                if let Ok(true) = self.store.release(&claimed.id, &self.id).await {
                    info!(job = %claimed.id, "returned to pending after the worker's error");
                }
                return Err(e.context(format!("worker {} on job {}", self.id, claimed.id)));
            }
        }
        Ok(summary)
    }

    /// Checkpoints a packing stopped by Ctrl-C (or by another worker's failure), so that `resume`
    /// loses none of the work done since its last checkpoint.
    async fn keep(&self, job: &str, packing: &Packing) {
        let p = packing.progress();
        let saved = match checkpoint_data(packing) {
            Ok(data) => self
                .store
                .save_checkpoint(job, &self.id, &data, p.time, Some(&stage(&p)))
                .await
                .map_err(anyhow::Error::from),
            Err(e) => Err(e.into()),
        };
        match saved {
            Ok(()) => info!(job, simulated_time = p.time, "checkpoint on stopping"),
            Err(e) => warn!(job, error = %e, "checkpoint on stopping not saved; resume continues from the last one"),
        }
    }

    /// Runs a claimed job and records how it ended.
    async fn handle(
        &self,
        claimed: &ClaimedJob,
        pool: Arc<rayon::ThreadPool>,
        summary: &mut Summary,
    ) -> anyhow::Result<()> {
        let label: Vec<String> = claimed.parameters.iter().map(|(k, v)| format!("{k}={v}")).collect();
        let label = format!("{} ({})", claimed.id.get(..8).unwrap_or(&claimed.id), label.join(", "));
        info!(job = %claimed.id, worker = %self.id, attempt = claimed.attempts, threads = self.threads, "started");
        let outcome = match read_spec(claimed.format, &claimed.spec) {
            Ok(spec) => self.execute(&claimed.id, spec, &label, pool).await?,
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
            Outcome::Stopped(packing) => {
                if self.cancel.load(Ordering::SeqCst) {
                    self.keep(&claimed.id, &packing).await;
                }
                if self.store.release(&claimed.id, &self.id).await? {
                    info!(job = %claimed.id, "returned to pending");
                }
            }
            Outcome::Failed(error) => {
                warn!(job = %claimed.id, %error, "failed");
                self.store.fail(&claimed.id, &self.id, &error).await?;
                summary.failed += 1;
                self.total.inc(1);
            }
        }
        Ok(())
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
        // `run`/`resume` checked the pending jobs before starting; this catches those taken over
        // since (their runner died). The error returns the job to pending and stops the run.
        if let Some(c) = checkpoint.as_ref().filter(|_| !self.discard_old_checkpoints)
            && let Some(format) = old_format(&c.data)
        {
            let old = OldCheckpoint { job: job.to_string(), format, simulated_time: Some(c.simulated_time) };
            refuse_old_checkpoints(&self.campaign, &[old])?;
        }
        let (sender, mut receiver) = mpsc::channel(4);
        let stop = [self.cancel.clone(), Arc::new(AtomicBool::new(false))];
        let lost = stop[1].clone();
        let interval = self.checkpoint_interval;
        let id = job.to_string();
        let mut task = tokio::task::spawn_blocking(move || {
            let mut relay = Relay { sender: &sender, stop: &stop };
            pool.install(|| simulate(&id, spec, checkpoint.as_ref().map(|c| &c.data[..]), &mut relay, interval))
        });
        let mut heartbeat = tokio::time::interval(HEARTBEAT);
        loop {
            tokio::select! {
                // Messages first, so that none sent before the packing ended is lost.
                biased;
                Some(message) = receiver.recv() => match message {
                    Message::Progress(p) => {
                        self.bar.set_message(format!(
                            "{label}: {} t = {:.3} s, {} grains, {} contacts",
                            phase_words(p.phase.name(), p.shaking_until),
                            p.time,
                            p.grains,
                            p.contacts
                        ));
                    }
                    Message::Warning(text) => {
                        warn!(job, "{text}");
                        self.bar.println(format!("sedpack: warning: job {job}: {text}"));
                    }
                    Message::Checkpoint(data, p) => {
                        if let Err(e) = self.store.save_checkpoint(job, &self.id, &data, p.time, Some(&stage(&p))).await {
                            warn!(job, error = %e, "checkpoint not saved; stopping the job");
                            lost.store(true, Ordering::SeqCst);
                        } else {
                            info!(
                                job,
                                simulated_time = p.time,
                                phase = p.phase.name(),
                                grains = p.grains,
                                mass_created = format!("{:.1} %", 100.0 * p.created),
                                shaking_until = p.shaking_until,
                                contacts = p.contacts,
                                bytes = data.len(),
                                "checkpoint"
                            );
                        }
                    }
                },
                outcome = &mut task => {
                    return Ok(outcome.unwrap_or_else(|panic| Outcome::Failed(format!("the solver panicked: {panic}"))));
                }
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

/// Where a packing loop reports to, and learns whether to stop.
pub(crate) trait Observer {
    fn progress(&mut self, progress: Progress);
    /// Keeps a checkpoint taken at `progress`; false when it cannot, and the packing stops.
    fn checkpoint(&mut self, data: Vec<u8>, progress: Progress) -> bool;
    /// Something the user should know, such as a checkpoint that cannot be used.
    fn warning(&mut self, text: String);
    fn stop_requested(&self) -> bool;
}

/// A local worker's packing reports through a channel and stops on Ctrl-C or a lost job.
struct Relay<'a> {
    sender: &'a mpsc::Sender<Message>,
    stop: &'a [Arc<AtomicBool>; 2],
}

impl Observer for Relay<'_> {
    fn progress(&mut self, progress: Progress) {
        // A full channel only delays the display; the packing never waits for it.
        let _ = self.sender.try_send(Message::Progress(progress));
    }

    fn checkpoint(&mut self, data: Vec<u8>, progress: Progress) -> bool {
        self.sender.blocking_send(Message::Checkpoint(data, progress)).is_ok()
    }

    fn warning(&mut self, text: String) {
        let _ = self.sender.blocking_send(Message::Warning(text));
    }

    fn stop_requested(&self) -> bool {
        self.stop.iter().any(|s| s.load(Ordering::SeqCst))
    }
}

/// The packing loop: from a checkpoint or from scratch, reporting progress and writing
/// checkpoints, until converged, failed or stopped.
pub(crate) fn simulate(
    job: &str,
    spec: JobSpec,
    checkpoint: Option<&[u8]>,
    observer: &mut impl Observer,
    interval: Duration,
) -> Outcome {
    let restored = checkpoint.and_then(|data| match restore(data, &spec) {
        Ok(packing) => {
            info!(job, simulated_time = packing.simulation.time, "resuming from a checkpoint");
            Some(packing)
        }
        Err(why) => {
            observer.warning(format!("its checkpoint cannot be used: {why}; starting over"));
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
        observer.progress(packing.progress());
        if observer.stop_requested() {
            return Outcome::Stopped(Box::new(packing));
        }
        if last_checkpoint.elapsed() >= interval {
            match checkpoint_data(&packing) {
                Ok(data) => {
                    if !observer.checkpoint(data, packing.progress()) {
                        return Outcome::Stopped(Box::new(packing));
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

/// What the store keeps of a packing's progress beside its checkpoint.
fn stage(p: &Progress) -> Stage {
    Stage {
        phase: p.phase.name().into(),
        grains: p.grains as u64,
        mass_created: p.created,
        shaking_until: p.shaking_until,
    }
}

/// A checkpoint: this version's checkpoint format number followed by the packing.
pub(crate) fn checkpoint_data(packing: &Packing) -> Result<Vec<u8>, postcard::Error> {
    postcard::to_allocvec(&(CHECKPOINT_FORMAT, packing))
}

/// The packing a checkpoint holds, if this version wrote it for this job; otherwise why not.
fn restore(data: &[u8], spec: &JobSpec) -> Result<Packing, String> {
    let unreadable = |e: postcard::Error| format!("it cannot be read ({e})");
    let (format, rest) = postcard::take_from_bytes::<u32>(data).map_err(unreadable)?;
    if format != CHECKPOINT_FORMAT {
        return Err(format!(
            "another version of sedpack wrote it (checkpoint format {format}; this version reads {CHECKPOINT_FORMAT})"
        ));
    }
    let mut packing: Packing = postcard::from_bytes(rest).map_err(unreadable)?;
    if packing.spec() != &spec.packing {
        return Err("it belongs to another spec than the job's".into());
    }
    // A checkpoint keeps only the digest of the meshes; the job brought them back.
    if let Some(library) = &spec.packing.grains.meshes {
        packing.attach_meshes(library).map_err(|e| format!("its meshes cannot be attached again: {e}"))?;
    }
    Ok(packing)
}

/// A stored job's spec, with its meshes loaded again and checked against their digest.
pub(crate) fn read_spec(format: u32, json: &serde_json::Value) -> anyhow::Result<JobSpec> {
    let mut spec = stored::decode(format, json)?;
    if let Some(library) = &mut spec.packing.grains.meshes {
        meshes::reload(library)?;
    }
    Ok(spec)
}

#[cfg(test)]
mod tests {
    use solver::fluid::flow::Flow;
    use solver::packing::{DomainKind, FluidSpec, PackingSpec};

    use super::*;

    fn job(seed: u64) -> JobSpec {
        JobSpec {
            name: "j".into(),
            packing: PackingSpec { seed, ..PackingSpec::paper(DomainKind::Periodic) },
            experiment: None,
        }
    }

    #[test]
    fn a_checkpoint_is_used_only_by_its_own_job_and_format_and_says_why_not() {
        let packing = Packing::new(job(1).packing).unwrap();
        let data = checkpoint_data(&packing).unwrap();
        assert_eq!(restore(&data, &job(1)).unwrap().spec(), packing.spec());
        let other = restore(&data, &job(2)).unwrap_err();
        assert!(other.contains("another spec"), "{other}");
        // sedpack 0.1.0 wrote the packing alone, which starts with the domain's variant (0).
        let old = postcard::to_allocvec(&packing).unwrap();
        let why = restore(&old, &job(1)).unwrap_err();
        assert!(why.contains("another version of sedpack wrote it (checkpoint format 0"), "{why}");
        assert!(restore(&[], &job(1)).unwrap_err().contains("cannot be read"));
    }

    #[test]
    fn a_packing_under_a_current_restored_between_two_fluid_updates_goes_on_bit_for_bit() {
        // Fluid forces updated every 20 steps; the checkpoint falls 10 steps after an update,
        // so the restored packing must carry the responses of that update to agree.
        let mut spec = job(3);
        spec.packing.grains.mass = 0.005;
        spec.packing.fluid = Some(FluidSpec {
            flow: Flow::Logarithmic { shear_velocity: 0.05, roughness: 2e-4 },
            ..FluidSpec::STILL_WATER
        });
        assert_eq!(spec.packing.fluid_forces().map(|f| f.coupling), Some(20));
        let mut straight = Packing::new(spec.packing.clone()).unwrap();
        straight.advance(1_000).unwrap();
        let mut first = Packing::new(spec.packing.clone()).unwrap();
        first.advance(530).unwrap();
        let mut resumed = restore(&checkpoint_data(&first).unwrap(), &spec).unwrap();
        resumed.advance(470).unwrap();
        let (a, b) = (&straight.simulation.bodies, &resumed.simulation.bodies);
        assert!(a.len() > 5, "{} grains", a.len());
        assert_eq!((&a.position, &a.velocity, &a.angular_velocity), (&b.position, &b.velocity, &b.angular_velocity));
    }
}
