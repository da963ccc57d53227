//! `sedpack run`, `resume`, `cancel`, `status` and `export`: campaigns in the SQLite store, run by
//! this machine's workers or as Slurm job arrays.

use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::time::Duration;

use analysis::csv;
use analysis::report::{duration, mean_std, setup_text};
use anyhow::{Context, bail};
use serde::Serialize;
use serde_json::{Map, Value};
use store::{CampaignStatus, ExportRow, JobState, NewJob, Progress, Store, StoreError, StoredJob};
use tracing::info;

use crate::campaign::{Campaign, read_campaign};
use crate::cli::{CancelArgs, ContinueArgs, ExportArgs, ExportFormat, LocalArgs, ResumeArgs, RunArgs, StatusArgs};
use crate::commands::archive;
use crate::executor::{Executor, Request};
use crate::output::{Table, phase_words, print_json};
use crate::records::new_job;
use crate::runner::{self, OldCheckpoint, RunOptions, Summary, old_format, refuse_old_checkpoints};
use crate::selection::Selection;
use crate::slurm::{self, Followed, RunDir, Submission, TaskRow};
use crate::{outln, stored};

pub(crate) fn runtime() -> anyhow::Result<tokio::runtime::Runtime> {
    Ok(tokio::runtime::Builder::new_multi_thread().worker_threads(2).enable_all().build()?)
}

/// Opens an existing database; status, export and resume never create one.
pub(crate) async fn open_existing(db: &Path) -> anyhow::Result<Store> {
    if !db.exists() {
        bail!("{}: no such database (start a campaign with `sedpack run CAMPAIGN.yaml`)", db.display());
    }
    Ok(Store::open(db).await?)
}

/// Logs go to a file beside the database: DB with the extension `.log`.
fn start_log(db: &Path) -> anyhow::Result<PathBuf> {
    let path = db.with_extension("log");
    let file = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&path)
        .with_context(|| format!("{}", path.display()))?;
    // A second initialisation (tests calling `run` twice in one process) keeps the first log.
    let _ = tracing_subscriber::fmt().with_writer(std::sync::Mutex::new(file)).with_ansi(false).try_init();
    Ok(path)
}

/// Workers and threads per worker of the local executor on `cores` cores: as asked, else one
/// worker per core and the cores divided among the workers.
fn local_threads(local: &LocalArgs, cores: usize) -> anyhow::Result<(usize, usize)> {
    let workers = match local.workers {
        Some(0) => bail!("--workers must be at least 1"),
        Some(n) => n,
        None => cores,
    };
    let threads = match local.threads {
        Some(0) => bail!("--threads must be at least 1"),
        Some(n) => n,
        None => (cores / workers).max(1),
    };
    Ok((workers, threads))
}

/// HEAD followed by the jobs per state ("running" named `running`), then the failures.
fn print_states(head: &str, status: &CampaignStatus, running: &str) -> std::io::Result<()> {
    let s = status;
    outln!("{head}{} done, {} failed, {} pending, {} {running}", s.done, s.failed, s.pending, s.running)?;
    for f in &status.failures {
        outln!("  failed {}: {}", f.job_id, f.error)?;
    }
    Ok(())
}

/// What a local run did; `only` is its `--only` arguments, repeated in the command that
/// continues it.
fn report(name: &str, summary: Summary, status: &CampaignStatus, only: &[String]) -> std::io::Result<()> {
    let head = format!("{name}: {} job(s) finished now, {} failed now; campaign: ", summary.completed, summary.failed);
    print_states(&head, status, "running")?;
    let picked: String = only.iter().map(|a| format!(" --only {}", shell_word(a))).collect();
    if summary.interrupted {
        let what = if only.is_empty() { "the campaign" } else { "the jobs --only picks" };
        outln!("interrupted: run `sedpack resume {name}{picked}` to finish {what}")?;
    } else if !only.is_empty() && status.pending > 0 {
        outln!("{} job(s) that --only left out are pending: `sedpack resume {name}` runs them", status.pending)?;
    }
    Ok(())
}

/// An argument as a POSIX shell reads it back: quoted unless it is plain.
fn shell_word(arg: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "._=-+,/:".contains(c);
    if !arg.is_empty() && arg.chars().all(plain) {
        arg.to_string()
    } else {
        format!("'{}'", arg.replace('\'', "'\\''"))
    }
}

/// `--checkpoint-interval` as a duration: a positive, finite number of seconds.
fn checkpoint_interval(seconds: f64) -> anyhow::Result<Duration> {
    Duration::try_from_secs_f64(seconds)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| anyhow::anyhow!("--checkpoint-interval: expected a positive number of seconds, got {seconds}"))
}

pub fn run(args: &RunArgs) -> anyhow::Result<()> {
    let e = &args.executor;
    let flags = Request {
        kind: e.executor,
        sbatch: e.sbatch.clone(),
        cpus_per_task: e.cpus_per_task,
        time: e.time,
        max_parallel: e.max_parallel,
    }
    .checked_flags()?;
    let interval = checkpoint_interval(args.common.checkpoint_interval)?;
    let campaign = read_campaign(&args.campaign)?;
    if let Some(selection) = Selection::parse(&args.common.only)? {
        // Refused before anything is stored.
        let planned: Vec<(String, Map<String, Value>)> =
            campaign.jobs.iter().map(|j| (j.id.clone(), j.parameters.clone())).collect();
        selection.pick(&campaign.name, &planned)?;
    }
    let thin: Vec<String> = campaign.jobs.iter().filter_map(|j| j.spec.thin_bed()).collect();
    if let Some(first) = thin.first() {
        let more = if thin.len() > 1 { format!(" (and {} more job(s) alike)", thin.len() - 1) } else { String::new() };
        eprintln!("sedpack: warning: {}: {first}{more}", args.campaign.display());
    }
    let log = start_log(&args.db)?;
    runtime()?.block_on(async {
        let store = Store::open(&args.db).await?;
        let previous = match store.campaign(&campaign.name).await {
            Ok(c) => Some(Executor::from_stored(c.executor.as_ref())?),
            Err(StoreError::NoCampaign { .. }) => None,
            Err(e) => return Err(e.into()),
        };
        let executor = flags.over(campaign.executor.clone()).resolve(previous.as_ref());
        check_workers(&args.local, &executor)?;
        store.upsert_campaign(&campaign.name, &campaign.text).await?;
        switch_executor(&store, &campaign.name, previous.as_ref(), &executor).await?;
        let added = add_jobs(&store, &campaign).await?;
        outln!(
            "{}: {} job(s), {} new; database {}, log {}",
            campaign.name,
            campaign.jobs.len(),
            added.new,
            args.db.display(),
            log.display()
        )?;
        if added.relabelled > 0 {
            outln!(
                "{}: {} stored job(s) now carry this campaign file's grid values (its grid changed)",
                campaign.name,
                added.relabelled
            )?;
        }
        if added.moved > 0 {
            outln!(
                "{}: {} job(s) not done now find their mesh folder where this campaign file does",
                campaign.name,
                added.moved
            )?;
        }
        continue_campaign(&store, &args.db, &campaign.name, &executor, &args.local, &args.common, interval).await
    })
}

fn check_workers(local: &LocalArgs, executor: &Executor) -> anyhow::Result<()> {
    if (local.workers.is_some() || local.threads.is_some()) && matches!(executor, Executor::Slurm(_)) {
        bail!(
            "--workers and --threads apply to the local executor; a Slurm task runs one packing on --cpus-per-task threads"
        );
    }
    // Counts of zero are refused here, before anything is stored.
    local_threads(local, 1)?;
    Ok(())
}

/// Records the executor the campaign runs on from now; refuses to change it while jobs run on
/// the other one.
async fn switch_executor(
    store: &Store,
    name: &str,
    previous: Option<&Executor>,
    executor: &Executor,
) -> anyhow::Result<()> {
    let was_slurm = matches!(previous, Some(Executor::Slurm(_)));
    let is_slurm = matches!(executor, Executor::Slurm(_));
    if let Some(previous) = previous.filter(|_| was_slurm != is_slurm) {
        if !was_slurm {
            // Jobs of local runners that died are not running any more.
            runner::recover(store, name).await?;
        }
        let running = store.running_jobs(name).await?.len();
        if running > 0 {
            let how =
                if was_slurm { format!("wait for them or `sedpack cancel {name}`") } else { "let them end".into() };
            bail!(
                "{name}: {running} job(s) are running on {previous}: {how} before running the campaign on {executor}"
            );
        }
    }
    store.set_executor(name, executor.to_stored().as_ref()).await?;
    Ok(())
}

/// What submitting a campaign's jobs did.
struct Added {
    new: u64,
    /// Stored jobs not done whose mesh folder moved, now described with its new place.
    moved: usize,
    /// Stored jobs whose grid values the campaign file changed (the grid gained an axis).
    relabelled: u64,
}

/// Adds the campaign's new jobs. A planned job that is already stored (under its id, or, for a
/// job of sedpack 0.1.0 with a mesh folder, under the id that version gave it) is not added
/// again, but takes the campaign file's grid values; if it is not done, its stored spec takes
/// the mesh folder's place from the campaign file.
async fn add_jobs(store: &Store, campaign: &Campaign) -> anyhow::Result<Added> {
    let mut stored_by_identity: HashMap<String, StoredJob> = HashMap::new();
    for job in store.jobs(&campaign.name).await? {
        // A job this version cannot read is left as it is.
        if let Ok(spec) = stored::decode(job.format, &job.spec) {
            stored_by_identity.insert(stored::job_id(&spec), job);
        }
    }
    let mut new: Vec<NewJob> = Vec::new();
    let mut labels = Vec::new();
    let mut moved = 0;
    for planned in &campaign.jobs {
        let job = new_job(planned);
        let Some(known) = stored_by_identity.get(&planned.id) else {
            new.push(job);
            continue;
        };
        labels.push((known.id.clone(), job.parameters.clone()));
        if (known.format != job.format || known.spec != job.spec)
            && store.replace_spec(&known.id, job.format, &job.spec).await?
        {
            info!(job = %known.id, "stored anew: {}", job.spec["mesh_folder"]);
            moved += 1;
        }
    }
    let relabelled = store.set_parameters(&campaign.name, &labels).await?;
    Ok(Added { new: store.add_jobs(&campaign.name, &new).await?, moved, relabelled })
}

/// Runs or submits the campaign's pending jobs on its executor.
async fn continue_campaign(
    store: &Store,
    db: &Path,
    name: &str,
    executor: &Executor,
    local: &LocalArgs,
    common: &ContinueArgs,
    checkpoint_interval: Duration,
) -> anyhow::Result<()> {
    let settings = match executor {
        Executor::Slurm(settings) => settings,
        Executor::Local => {
            let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
            let (workers, threads) = local_threads(local, cores)?;
            retry_failed(store, name, common.retry_failed).await?;
            // Jobs of dead runners are pending again before `--only` counts the pending ones.
            runner::recover(store, name).await?;
            let only = selected(store, name, &common.only).await?;
            let options = RunOptions {
                workers,
                threads,
                checkpoint_interval,
                discard_old_checkpoints: common.discard_old_checkpoints,
                only: only.clone(),
            };
            if !common.discard_old_checkpoints {
                // All at once before anything starts; the workers check jobs requeued later.
                let mut old = runner::old_checkpoints(store, name).await?;
                old.retain(|c| only.as_ref().is_none_or(|ids| ids.contains(&c.job)));
                refuse_old_checkpoints(name, &old)?;
            }
            let summary = runner::run(store, name, &options, !common.quiet).await?;
            return report(name, summary, &store.status(name).await?, &common.only).map_err(Into::into);
        }
    };
    let run = RunDir::of(db, name)?;
    slurm::sync(store, &run, name).await?;
    retry_failed(store, name, common.retry_failed).await?;
    let only = selected(store, name, &common.only).await?;
    let only = only.as_deref();
    if !common.discard_old_checkpoints {
        // The tasks run this binary and continue from the checkpoints in the run directory.
        let mut old = Vec::new();
        let jobs = store.jobs(name).await?.into_iter().filter(|j| j.state == JobState::Pending);
        for job in jobs.filter(|j| only.is_none_or(|ids| ids.contains(&j.id))) {
            if let Some(format) = std::fs::read(run.job(&job.id).checkpoint()).ok().and_then(|d| old_format(&d)) {
                old.push(OldCheckpoint { job: job.id, format, simulated_time: None });
            }
        }
        refuse_old_checkpoints(name, &old)?;
    }
    let submission = Submission { store, run: &run, campaign: name, settings, checkpoint_interval };
    let arrays = submission.pending(only).await?;
    for a in &arrays {
        outln!("{name}: submitted Slurm array {} ({} job(s))", a.array, a.jobs)?;
    }
    if !arrays.is_empty() {
        outln!("{name}: run directory {}", run.path.display())?;
    }
    let followed = if common.wait { Some(slurm::follow(&submission, !common.quiet).await?) } else { None };
    let status = store.status(name).await?;
    print_states(&format!("{name}: "), &status, "in Slurm")?;
    match followed {
        None if status.running > 0 => {
            outln!("follow it with `sedpack status {name}`; `sedpack resume {name} --wait` waits for it")?
        }
        Some(Followed::Interrupted) => outln!(
            "stopped following; the tasks go on in Slurm: `sedpack status {name}`, `sedpack resume {name} --wait`, `sedpack cancel {name}`"
        )?,
        _ if status.pending > 0 => outln!("{} job(s) pending: `sedpack resume {name}` submits them", status.pending)?,
        _ => {}
    }
    Ok(())
}

/// The jobs `--only` picks (None without it), and a line saying how many.
async fn selected(store: &Store, name: &str, only: &[String]) -> anyhow::Result<Option<Vec<String>>> {
    let Some(selection) = Selection::parse(only)? else {
        return Ok(None);
    };
    let rows = store.export(name).await?;
    let jobs: Vec<(String, Map<String, Value>)> =
        rows.iter().map(|r| (r.job_id.clone(), r.parameters.clone())).collect();
    let ids = selection.pick(name, &jobs)?;
    let pending = rows.iter().filter(|r| r.state == JobState::Pending && ids.contains(&r.job_id)).count();
    outln!("{name}: --only picks {} job(s), {pending} of them pending; the others are left as they are", ids.len())?;
    Ok(Some(ids))
}

async fn retry_failed(store: &Store, name: &str, retry: bool) -> anyhow::Result<()> {
    if retry {
        let retried = store.requeue_failed(name).await?;
        outln!("{name}: {retried} failed job(s) returned to pending")?;
    }
    Ok(())
}

pub fn resume(args: &ResumeArgs) -> anyhow::Result<()> {
    let interval = checkpoint_interval(args.common.checkpoint_interval)?;
    runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        let executor = Executor::from_stored(store.campaign(&args.name).await?.executor.as_ref())?;
        check_workers(&args.local, &executor)?;
        start_log(&args.db)?;
        continue_campaign(&store, &args.db, &args.name, &executor, &args.local, &args.common, interval).await
    })
}

pub fn cancel(args: &CancelArgs) -> anyhow::Result<()> {
    runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        let name = &args.name;
        if Executor::from_stored(store.campaign(name).await?.executor.as_ref())? == Executor::Local {
            bail!("{name} runs on local workers, not in Slurm: stop its `sedpack run` with Ctrl-C");
        }
        start_log(&args.db)?;
        let cancelled = slurm::cancel(&store, &RunDir::of(&args.db, name)?, name).await?;
        outln!(
            "{name}: {} job(s) pending again, their checkpoints kept (`sedpack resume {name}` continues them); \
             {} finished meanwhile",
            cancelled.pending,
            cancelled.done
        )?;
        if !cancelled.still_ending.is_empty() {
            outln!(
                "tasks {} have not ended yet and keep their jobs: `sedpack cancel {name}` again later",
                cancelled.still_ending.join(", ")
            )?;
        }
        Ok(())
    })
}

/// Brings a Slurm campaign up to date before it is read; gives its executor and run directory
/// (None for a local campaign). When Slurm cannot be asked, a warning says so and the results
/// already in the run directory are ingested all the same.
pub(crate) async fn catch_up(store: &Store, db: &Path, name: &str) -> anyhow::Result<Option<(Executor, RunDir)>> {
    let executor = Executor::from_stored(store.campaign(name).await?.executor.as_ref())?;
    if executor == Executor::Local {
        return Ok(None);
    }
    let run = RunDir::of(db, name)?;
    if let Err(e) = slurm::sync(store, &run, name).await {
        eprintln!("sedpack: warning: {name}: {e:#}; showing what the database and the run directory hold");
    }
    Ok(Some((executor, run)))
}

#[derive(Serialize)]
struct StatusRecord {
    #[serde(flatten)]
    status: CampaignStatus,
    /// Wall time left for one worker (s) by [`TimeLeft`], for the jobs whose setup has a done job.
    estimated_time_left: Option<f64>,
    /// Jobs left whose setup has no done job yet, which the estimate leaves out.
    jobs_not_estimated: usize,
    #[serde(skip)]
    time_left: Option<TimeLeft>,
    /// The porosities of the done jobs, per setup.
    results: Vec<SetupResults>,
    executor: Executor,
    /// A Slurm campaign's jobs beside their tasks' states in Slurm.
    #[serde(skip_serializing_if = "Option::is_none")]
    tasks: Option<Vec<TaskRow>>,
}

async fn status_record(store: &Store, db: &Path, name: &str) -> anyhow::Result<StatusRecord> {
    let caught_up = catch_up(store, db, name).await?;
    let status = store.status(name).await?;
    let checkpoints: HashMap<&str, f64> =
        status.in_progress.iter().filter_map(|p| Some((p.job_id.as_str(), p.checkpoint?.0))).collect();
    let rows = store.export(name).await?;
    let jobs: Vec<Weighed> = rows
        .iter()
        .map(|row| Weighed {
            setup: setup_text(&row.parameters),
            ended: matches!(row.state, JobState::Done | JobState::Failed),
            done: row.result.as_ref().filter(|_| row.state == JobState::Done).map(|r| (r.wall_time, r.simulated_time)),
            checkpoint: checkpoints.get(row.job_id.as_str()).copied(),
        })
        .collect();
    let time_left = TimeLeft::of(&jobs);
    let (executor, tasks) = match caught_up {
        None => (Executor::Local, None),
        Some((executor, run)) => (executor, Some(slurm::task_rows(store, &run, name).await?)),
    };
    Ok(StatusRecord {
        status,
        estimated_time_left: time_left.as_ref().map(|t| t.seconds),
        jobs_not_estimated: time_left.as_ref().map_or(0, |t| t.unestimated),
        time_left,
        results: SetupResults::of(&rows),
        executor,
        tasks,
    })
}

/// The porosities of one setup's done jobs (in submission order), with their mean and
/// population standard deviation, as the report's tables give them.
#[derive(Debug, Clone, PartialEq, Serialize)]
struct SetupResults {
    setup: String,
    porosities: Vec<f64>,
    mean: f64,
    std: f64,
}

impl SetupResults {
    /// One entry per setup with a done job, in the order the setups were submitted.
    fn of(rows: &[ExportRow]) -> Vec<Self> {
        let mut setups: Vec<(String, Vec<f64>)> = Vec::new();
        for row in rows.iter().filter(|r| r.state == JobState::Done) {
            let Some(result) = &row.result else { continue };
            let setup = setup_text(&row.parameters);
            match setups.iter_mut().find(|(s, _)| *s == setup) {
                Some((_, porosities)) => porosities.push(result.porosity),
                None => setups.push((setup, vec![result.porosity])),
            }
        }
        setups
            .into_iter()
            .map(|(setup, porosities)| {
                let (mean, std) = mean_std(&porosities);
                Self { setup, porosities, mean, std }
            })
            .collect()
    }

    /// "grains.size = U3: 0.391, 0.388 (mean 0.389 ± 0.002)".
    fn text(&self) -> String {
        let runs: Vec<String> = self.porosities.iter().map(|n| format!("{n:.3}")).collect();
        let mean = match self.porosities.len() {
            1 => String::new(),
            _ => format!(" (mean {:.3} ± {:.3})", self.mean, self.std),
        };
        format!("{}: {}{mean}", self.setup, runs.join(", "))
    }
}

/// One job as the time left weighs it: its setup, whether it has ended, a done job's wall and
/// simulated time, and the simulated time of the last checkpoint of one in progress.
struct Weighed {
    setup: String,
    ended: bool,
    done: Option<(f64, f64)>,
    checkpoint: Option<f64>,
}

/// Wall time left for one worker: every job left takes as long as the done jobs of its setup did
/// on average, less the share of their simulated time its checkpoint has already simulated.
/// Setups differ widely (a bimodal sieve curve pours several times a unimodal one's grains), so
/// a job whose setup has no done job is not estimated.
#[derive(Debug, Clone, PartialEq)]
struct TimeLeft {
    seconds: f64,
    /// Jobs left whose setup has a done job.
    estimated: usize,
    /// Of those, the jobs already past their setup's done jobs' simulated time (counted as ending now).
    past: usize,
    /// Jobs left whose setup has no done job.
    unestimated: usize,
    /// A done job's mean wall and simulated time, when every job shares one setup.
    one_setup: Option<(f64, f64)>,
}

impl TimeLeft {
    /// None before a job is done or once every job has ended.
    fn of(jobs: &[Weighed]) -> Option<Self> {
        let mut done: HashMap<&str, (f64, f64, usize)> = HashMap::new();
        for job in jobs {
            if let Some((wall, simulated)) = job.done {
                let sums = done.entry(job.setup.as_str()).or_default();
                *sums = (sums.0 + wall, sums.1 + simulated, sums.2 + 1);
            }
        }
        let left: Vec<&Weighed> = jobs.iter().filter(|j| !j.ended).collect();
        if done.is_empty() || left.is_empty() {
            return None;
        }
        let mean = |setup: &str| done.get(setup).map(|&(wall, simulated, n)| (wall / n as f64, simulated / n as f64));
        let mut t = TimeLeft { seconds: 0.0, estimated: 0, past: 0, unestimated: 0, one_setup: None };
        for job in left {
            let Some((wall, simulated)) = mean(&job.setup) else {
                t.unestimated += 1;
                continue;
            };
            let share = job.checkpoint.filter(|_| simulated > 0.0).map_or(0.0, |c| c / simulated);
            t.estimated += 1;
            t.past += usize::from(share >= 1.0);
            t.seconds += wall * (1.0 - share.min(1.0));
        }
        let first = &jobs[0].setup;
        if jobs.iter().all(|j| &j.setup == first) {
            t.one_setup = mean(first);
        }
        Some(t)
    }

    /// In words, with what the estimate rests on and the jobs it leaves out.
    fn text(&self) -> String {
        let past = |what: &str| match self.past {
            0 => String::new(),
            k => format!("; {k} job(s) already past {what}, whose end is not estimated"),
        };
        if let Some((wall, simulated)) = self.one_setup {
            let simulated = if simulated > 0.0 { format!(" for {simulated:.2} s simulated") } else { String::new() };
            return format!(
                "≈ {} for one worker (a done job took {}{simulated}){}",
                duration(self.seconds),
                duration(wall),
                past("that")
            );
        }
        let not = match self.unestimated {
            0 => String::new(),
            k => format!("; {k} job(s) of setups without a done job are not estimated"),
        };
        if self.estimated == 0 {
            return format!(
                "not estimated: none of the {} job(s) left shares its setup with a done job",
                self.unestimated
            );
        }
        format!(
            "≈ {} for one worker for {} job(s), each as long as its setup's done jobs took{}{not}",
            duration(self.seconds),
            self.estimated,
            past("those")
        )
    }
}

pub fn status(args: &StatusArgs) -> anyhow::Result<()> {
    runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        let names: Vec<String> = match &args.name {
            Some(name) => vec![store.campaign(name).await?.name],
            None => store.campaigns().await?.into_iter().map(|c| c.name).collect(),
        };
        let mut records = Vec::new();
        for name in &names {
            records.push(status_record(&store, &args.db, name).await?);
        }
        if args.json {
            // One object for a named campaign, a list of every campaign otherwise.
            return match (&args.name, records.as_slice()) {
                (Some(_), [record]) => print_json(record),
                _ => print_json(&records),
            };
        }
        if records.is_empty() {
            outln!("no campaigns in {}", args.db.display())?;
        }
        for r in &records {
            let s = &r.status;
            let now = unix_now();
            // Slurm tasks report through the run directory, not heartbeats: only local jobs fall silent.
            let silent = if r.tasks.is_none() { s.in_progress.iter().filter(|p| is_silent(p, now)).count() } else { 0 };
            let silent = if silent > 0 { format!(" ({silent} without a heartbeat)") } else { String::new() };
            let mut table = Table::default();
            table
                .row("campaign", s.campaign.clone())
                .row(
                    "jobs",
                    format!(
                        "{} ({} done, {} failed, {} running{silent}, {} pending)",
                        s.jobs, s.done, s.failed, s.running, s.pending
                    ),
                )
                .row("time spent", format!("{} on finished jobs", duration(s.wall_time_finished)));
            if let Some(t) = &r.time_left {
                table.row("time left", t.text());
            }
            for (k, results) in r.results.iter().enumerate() {
                table.row(if k == 0 { "porosity" } else { "" }, results.text());
            }
            for f in &s.failures {
                table.row(format!("failed {}", f.job_id), f.error.clone());
            }
            if r.tasks.is_none() {
                for p in &s.in_progress {
                    table.row(format!("job {}", p.job_id), progress_text(p, now));
                }
            }
            if let Some(tasks) = &r.tasks {
                table.row("executor", r.executor.to_string());
                for t in tasks {
                    let reason = t.slurm_reason.as_ref().map(|r| format!(" ({r})")).unwrap_or_default();
                    let record = t.task_record.map(|k| k.name());
                    let slurm = match (&t.task, &t.slurm_state, record) {
                        (Some(task), Some(state), _) => format!("task {task}: {state}{reason}"),
                        (Some(task), None, Some(record)) => format!("task {task}: {record}, by its own record"),
                        (Some(task), None, None) => format!("task {task}: never started"),
                        (None, Some(state), _) => state.clone(),
                        (None, None, _) => "not submitted".into(),
                    };
                    table.row(format!("job {}", t.job_id), format!("{:<8} {slurm}", t.state.as_str()));
                }
            }
            table.print()?;
        }
        Ok(())
    })
}

fn unix_now() -> f64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0.0, |d| d.as_secs_f64())
}

/// Whether a running local job's runner has not sent a heartbeat for longer than `resume` waits
/// before it takes the job over: the process was killed, or its machine went down.
fn is_silent(p: &Progress, now: f64) -> bool {
    p.state == JobState::Running && p.heartbeat_at.is_some_and(|t| now - t > runner::STALE_AFTER.as_secs_f64())
}

/// A local job in progress in words: "running for 32 min 10 s on vm:1:0 (attempt 2); checkpoint
/// at 1.90 s simulated (generation, 1972 grains, 38 % of the mass), 2 min 05 s ago"; while the
/// packing shakes, its phase says when the shaking ends ("shaking until 6.25 s"). A job whose
/// runner fell silent says so, and what `resume` will do with it.
fn progress_text(p: &Progress, now: f64) -> String {
    let ago = |t: f64| duration((now - t).max(0.0));
    // The share of the mass created says how far the generation is, which simulated time does not.
    let stage = match &p.stage {
        Some(s) => format!(
            " ({}, {} grains, {:.0} % of the mass)",
            phase_words(&s.phase, s.shaking_until),
            s.grains,
            100.0 * s.mass_created
        ),
        None => String::new(),
    };
    let checkpoint = match p.checkpoint {
        Some((simulated, written)) => format!("checkpoint at {simulated:.2} s simulated{stage}, {} ago", ago(written)),
        None => "no checkpoint yet".into(),
    };
    match (&p.worker_id, p.started_at, p.heartbeat_at) {
        (Some(worker), _, Some(heard)) if is_silent(p, now) => {
            let next = if p.checkpoint.is_some() { "`resume` continues from it" } else { "`resume` starts it over" };
            format!(
                "stopped: no heartbeat from {worker} for {} (attempt {}); {checkpoint}: {next}",
                ago(heard),
                p.attempts
            )
        }
        (Some(worker), Some(started), _) => {
            format!("running for {} on {worker} (attempt {}); {checkpoint}", ago(started), p.attempts)
        }
        _ => format!("pending; {checkpoint}: `resume` continues from it"),
    }
}

pub fn export(args: &ExportArgs) -> anyhow::Result<()> {
    let export = runtime()?.block_on(async {
        let store = open_existing(&args.db).await?;
        catch_up(&store, &args.db, &args.name).await?;
        Ok::<_, anyhow::Error>(match args.format {
            ExportFormat::Csv => Export::Csv(store.export(&args.name).await?),
            ExportFormat::Jsonl => Export::Jsonl(store.campaign(&args.name).await?, store.archive(&args.name).await?),
        })
    })?;
    let mut out: Box<dyn Write> = match &args.out {
        Some(path) => Box::new(std::fs::File::create(path).with_context(|| format!("{}", path.display()))?),
        None => Box::new(std::io::stdout().lock()),
    };
    match export {
        Export::Csv(rows) => write_csv(&mut out, &rows)?,
        Export::Jsonl(campaign, jobs) => archive::write(&mut out, &campaign, &jobs)?,
    }
    out.flush()?;
    Ok(())
}

/// What `export` writes: every job's row, or the campaign and its done jobs whole.
enum Export {
    Csv(Vec<ExportRow>),
    Jsonl(store::Campaign, Vec<store::ArchivedJob>),
}

/// One row per job: id, state, seed, the grid keys, the result and the grain statistics.
fn write_csv(out: &mut impl Write, rows: &[ExportRow]) -> anyhow::Result<()> {
    let mut keys: Vec<String> = Vec::new();
    for row in rows {
        for key in row.parameters.keys() {
            if key != "seed" && !keys.contains(key) {
                keys.push(key.clone());
            }
        }
    }
    let statistics = solver::grain::feature_names();
    let mut header = vec!["job_id".to_string(), "state".into(), "seed".into()];
    header.extend(keys.iter().cloned());
    header.extend(["porosity", "z_minus", "z_plus", "particles", "simulated_time", "wall_time"].map(String::from));
    for name in &statistics {
        header.push(format!("mean_{name}"));
        header.push(format!("std_{name}"));
    }
    writeln!(out, "{}", header.iter().map(|h| csv::field(h)).collect::<Vec<_>>().join(","))?;
    for row in rows {
        let mut fields = vec![row.job_id.clone(), row.state.as_str().to_string(), row.seed.to_string()];
        fields.extend(keys.iter().map(|k| csv_value(row.parameters.get(k))));
        match &row.result {
            Some(r) => fields.extend(
                [r.porosity, r.z_minus, r.z_plus, r.particles as f64, r.simulated_time, r.wall_time]
                    .map(|v| v.to_string()),
            ),
            None => fields.extend(std::iter::repeat_n(String::new(), 6)),
        }
        let by_name: Map<String, Value> =
            row.grain_statistics.iter().map(|s| (s.name.clone(), serde_json::json!([s.mean, s.std]))).collect();
        for name in &statistics {
            match by_name.get(name) {
                Some(v) => {
                    fields.push(v[0].to_string());
                    fields.push(v[1].to_string());
                }
                None => fields.extend([String::new(), String::new()]),
            }
        }
        writeln!(out, "{}", fields.join(","))?;
    }
    Ok(())
}

/// A grid value as a CSV field: a string as its text, anything else as its JSON.
fn csv_value(value: Option<&Value>) -> String {
    match value {
        None | Some(Value::Null) => String::new(),
        Some(Value::String(s)) => csv::field(s),
        Some(other) => csv::field(&other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;
    use store::Stage;

    use super::*;

    #[test]
    fn arguments_are_quoted_for_the_shell_unless_plain() {
        assert_eq!(shell_word("grains.size=B50"), "grains.size=B50");
        assert_eq!(shell_word("name=a b"), "'name=a b'");
        assert_eq!(shell_word("k=it's"), r"'k=it'\''s'");
    }

    #[test]
    fn grid_values_become_csv_fields() {
        assert_eq!(csv_value(Some(&json!(0.4))), "0.4");
        assert_eq!(csv_value(Some(&json!("U7"))), "U7");
        assert_eq!(csv_value(Some(&json!("a,b"))), "\"a,b\"");
        assert_eq!(csv_value(Some(&json!({"fl": 0.5, "el": 0.6}))), r#""{""fl"":0.5,""el"":0.6}""#);
        assert_eq!(csv_value(None), "");
    }

    #[test]
    fn jobs_in_progress_say_how_long_they_ran_and_where_they_stopped() {
        let running = Progress {
            job_id: "a".into(),
            state: JobState::Running,
            worker_id: Some("vm:1:0".into()),
            attempts: 2,
            started_at: Some(1000.0),
            heartbeat_at: Some(2925.0),
            checkpoint: Some((1.9, 2800.0)),
            stage: Some(Stage { phase: "generation".into(), grains: 1972, mass_created: 0.382, shaking_until: None }),
        };
        assert_eq!(
            progress_text(&running, 2930.0),
            "running for 32 min 10 s on vm:1:0 (attempt 2); checkpoint at 1.90 s simulated \
             (generation, 1972 grains, 38 % of the mass), 2 min 10 s ago"
        );
        let shaking = Stage { phase: "shaking".into(), grains: 6053, mass_created: 1.0, shaking_until: Some(6.75) };
        let shaking = Progress { checkpoint: Some((6.1234, 2800.0)), stage: Some(shaking), ..running.clone() };
        assert!(
            progress_text(&shaking, 2930.0).ends_with(
                "checkpoint at 6.12 s simulated (shaking until 6.75 s, 6053 grains, 100 % of the mass), 2 min 10 s ago"
            ),
            "{}",
            progress_text(&shaking, 2930.0)
        );
        let old = Progress { stage: None, ..running.clone() };
        assert!(progress_text(&old, 2930.0).ends_with("checkpoint at 1.90 s simulated, 2 min 10 s ago"));
        let fresh = Progress { checkpoint: None, stage: None, heartbeat_at: Some(1025.0), ..running.clone() };
        assert!(progress_text(&fresh, 1030.0).ends_with("(attempt 2); no checkpoint yet"));
        // `resume` takes a job over once its heartbeat is older than 60 s; so does this text.
        assert!(progress_text(&running, 2985.0).starts_with("running for"));
        assert!(!is_silent(&running, 2985.0));
        assert!(is_silent(&running, 2986.0));
        assert_eq!(
            progress_text(&running, 2986.0),
            "stopped: no heartbeat from vm:1:0 for 1 min 01 s (attempt 2); checkpoint at 1.90 s simulated \
             (generation, 1972 grains, 38 % of the mass), 3 min 06 s ago: `resume` continues from it"
        );
        assert_eq!(
            progress_text(&fresh, 1100.0),
            "stopped: no heartbeat from vm:1:0 for 1 min 15 s (attempt 2); no checkpoint yet: `resume` starts it over"
        );
        let stopped = Progress {
            state: JobState::Pending,
            worker_id: None,
            started_at: None,
            heartbeat_at: None,
            stage: None,
            ..running
        };
        assert_eq!(
            progress_text(&stopped, 2810.0),
            "pending; checkpoint at 1.90 s simulated, 10.0 s ago: `resume` continues from it"
        );
    }

    fn weighed(setup: &str, ended: bool, done: Option<(f64, f64)>, checkpoint: Option<f64>) -> Weighed {
        Weighed { setup: setup.into(), ended, done, checkpoint }
    }

    #[test]
    fn the_time_left_counts_what_the_checkpoints_have_already_simulated() {
        // One setup; done jobs took 100 s of wall time for 2 s simulated on average (80 s for
        // 1.8 s, 120 s for 2.2 s). Left: one pending job without a checkpoint (100 s), one
        // running at 1.5 s (a quarter left: 25 s) and one pending at 2.5 s, past the mean
        // (nothing counted): 125 s. A failed job is not waited for.
        let mut jobs = vec![
            weighed("{}", true, Some((80.0, 1.8)), None),
            weighed("{}", true, Some((120.0, 2.2)), None),
            weighed("{}", true, None, None),
            weighed("{}", false, None, None),
            weighed("{}", false, None, Some(1.5)),
            weighed("{}", false, None, Some(2.5)),
        ];
        let t = TimeLeft::of(&jobs).unwrap();
        assert_eq!((t.seconds, t.estimated, t.past, t.unestimated), (125.0, 3, 1, 0));
        assert_eq!(
            t.text(),
            "≈ 2 min 05 s for one worker (a done job took 1 min 40 s for 2.00 s simulated); 1 job(s) already past \
             that, whose end is not estimated"
        );
        // Nothing left to run, or nothing done yet: no estimate.
        let ended: Vec<Weighed> = jobs.iter().filter(|j| j.ended).map(|j| weighed("{}", true, j.done, None)).collect();
        assert_eq!(TimeLeft::of(&ended), None);
        jobs.retain(|j| j.done.is_none());
        assert_eq!(TimeLeft::of(&jobs), None);
    }

    #[test]
    fn the_time_left_weighs_each_job_by_the_done_jobs_of_its_setup() {
        // U3 took 480 s for 2.9 s simulated, U5 1,500 s and 1,700 s for 8 s: U3's second seed
        // 480 s, U5's third 1,600 s less the half its checkpoint at 4 s covers (800 s); B70 has
        // no done job and is not estimated, whatever U3 and U5 took.
        let (u3, u5, b70) = (r#"{"grains.size":"U3"}"#, r#"{"grains.size":"U5"}"#, r#"{"grains.size":"B70"}"#);
        let mut jobs = vec![
            weighed(u3, true, Some((480.0, 2.9)), None),
            weighed(u5, true, Some((1500.0, 8.0)), None),
            weighed(u5, true, Some((1700.0, 8.0)), None),
            weighed(u3, false, None, None),
            weighed(u5, false, None, Some(4.0)),
            weighed(b70, false, None, None),
            weighed(b70, false, None, None),
        ];
        let t = TimeLeft::of(&jobs).unwrap();
        assert_eq!((t.seconds, t.estimated, t.past, t.unestimated, t.one_setup), (1280.0, 2, 0, 2, None));
        assert_eq!(
            t.text(),
            "≈ 21 min 20 s for one worker for 2 job(s), each as long as its setup's done jobs took; 2 job(s) of \
             setups without a done job are not estimated"
        );
        jobs.retain(|j| j.ended || j.setup == b70);
        assert_eq!(
            TimeLeft::of(&jobs).unwrap().text(),
            "not estimated: none of the 2 job(s) left shares its setup with a done job"
        );
        // The setup is the grid values but the seed.
        let key = |json: &str| setup_text(serde_json::from_str::<Value>(json).unwrap().as_object().unwrap());
        assert_eq!(key(r#"{"seed":1,"grains.size":"U3"}"#), key(r#"{"grains.size":"U3","seed":2}"#));
        assert_ne!(key(r#"{"seed":1,"grains.size":"U3"}"#), key(r#"{"seed":1,"grains.size":"U5"}"#));
    }

    #[test]
    fn the_cores_are_divided_among_the_workers_unless_threads_are_given() {
        let plan = |workers, threads, cores| local_threads(&LocalArgs { workers, threads }, cores).ok();
        assert_eq!(plan(None, None, 8), Some((8, 1)));
        assert_eq!(plan(Some(1), None, 8), Some((1, 8)));
        assert_eq!(plan(Some(3), None, 8), Some((3, 2)), "8 cores for 3 workers: 2 each, none oversubscribed");
        assert_eq!(plan(Some(4), None, 2), Some((4, 1)), "more workers than cores: still 1 thread each");
        assert_eq!(plan(Some(1), Some(1), 2), Some((1, 1)), "two campaigns side by side on 2 cores");
        assert_eq!(plan(None, Some(3), 2), Some((2, 3)), "asked threads are taken as given");
        assert_eq!(plan(Some(0), None, 2), None);
        assert_eq!(plan(None, Some(0), 2), None);
    }
}
