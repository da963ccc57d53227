//! The values that go in and out of the store. Specs, parameters and porosity profiles are
//! opaque JSON to it.

use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};

/// A job's place in the queue: pending → running → done | failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    Pending,
    Running,
    Done,
    Failed,
}

impl JobState {
    pub fn as_str(self) -> &'static str {
        match self {
            JobState::Pending => "pending",
            JobState::Running => "running",
            JobState::Done => "done",
            JobState::Failed => "failed",
        }
    }

    pub(crate) fn parse(text: &str) -> Option<JobState> {
        [JobState::Pending, JobState::Running, JobState::Done, JobState::Failed]
            .into_iter()
            .find(|state| state.as_str() == text)
    }
}

/// A campaign as submitted: its name, the campaign file's text and the executor its jobs are
/// handed to (None: the submitting machine's workers).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Campaign {
    pub name: String,
    pub spec: String,
    pub executor: Option<Value>,
    pub created_at: f64,
    pub updated_at: f64,
}

/// A job to add to a campaign.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct NewJob {
    /// Stable hash of the resolved spec; unique across all campaigns of the database.
    pub id: String,
    /// The format `spec` is written in, for the caller that reads it back.
    pub format: u32,
    pub spec: Value,
    pub seed: u64,
    /// Grid key (dotted) → the value this job takes.
    pub parameters: Map<String, Value>,
    /// The measured porosity the job is compared with, if any, and its standard deviation, if given.
    pub experiment_porosity: Option<f64>,
    pub experiment_std: Option<f64>,
    /// The job's fluid forces as the caller describes them; None: buoyancy only.
    pub fluid: Option<Value>,
}

/// A job handed to a worker by [`crate::Store::claim`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ClaimedJob {
    pub id: String,
    pub format: u32,
    pub spec: Value,
    pub seed: u64,
    pub parameters: Map<String, Value>,
    /// How many times the job has been claimed, this time included.
    pub attempts: u32,
}

/// A stored job and where it stands.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StoredJob {
    pub id: String,
    pub format: u32,
    pub spec: Value,
    pub state: JobState,
    /// Who runs it, or ran it last.
    pub worker_id: Option<String>,
    pub attempts: u32,
    pub error: Option<String>,
}

/// What a finished packing reports.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JobResult {
    pub porosity: f64,
    pub z_minus: f64,
    pub z_plus: f64,
    /// The porosity profile as the caller wrote it.
    pub profile: Value,
    pub particles: u64,
    /// s of simulated time.
    pub simulated_time: f64,
    pub steps: u64,
    /// s of wall-clock time spent stepping, measured by the solver and summed over resumed attempts.
    pub wall_time: f64,
    pub solver_version: String,
    /// The grains' imbrication as the caller wrote it, for packings that report one.
    pub imbrication: Option<Value>,
    /// Grains and mass per sieve class as the caller wrote them; None for results stored
    /// before sedpack recorded them.
    #[serde(default)]
    pub size_classes: Option<Value>,
}

/// Number-based mean and std of one form factor ("FL") or its inverse ("inv_FL") over a job's grains.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GrainStatistic {
    pub name: String,
    pub mean: f64,
    pub std: f64,
}

/// A job's saved solver state, opaque to the store.
#[derive(Debug, Clone, PartialEq)]
pub struct Checkpoint {
    pub data: Vec<u8>,
    pub simulated_time: f64,
    pub written_at: f64,
}

/// Where a packing stood when its checkpoint was written, as the caller described it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Stage {
    /// The packing's phase by name ("generation", "shaking", "damping").
    pub phase: String,
    pub grains: u64,
    /// Fraction of the target mass created.
    pub mass_created: f64,
    /// While the packing shakes, the simulated time the shaking ends.
    pub shaking_until: Option<f64>,
}

/// A job some worker holds, for deciding whether that worker is still alive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RunningJob {
    pub job_id: String,
    pub worker_id: String,
    pub attempts: u32,
    pub started_at: f64,
    pub heartbeat_at: f64,
}

/// A failed job and its error text.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Failure {
    pub job_id: String,
    pub attempts: u32,
    pub error: String,
}

/// Counts per state and the timings an ETA needs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CampaignStatus {
    pub campaign: String,
    pub jobs: u64,
    pub pending: u64,
    pub running: u64,
    pub done: u64,
    pub failed: u64,
    pub failures: Vec<Failure>,
    /// s of wall-clock time of every done or failed job, summed: a done job's packing time over
    /// all its attempts (its result's), a failed job's last attempt.
    pub wall_time_finished: f64,
    /// s per done job (its packing time over all attempts), None before the first one is done.
    pub mean_wall_time_done: Option<f64>,
    /// s of simulated time per done job, None before the first one is done.
    pub mean_simulated_time_done: Option<f64>,
    /// The running jobs and the pending ones with a checkpoint, in submission order.
    pub in_progress: Vec<Progress>,
}

/// How far a running job, or a pending one that stopped with a checkpoint, has come.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Progress {
    pub job_id: String,
    pub state: JobState,
    /// Who runs it (None when pending).
    pub worker_id: Option<String>,
    pub attempts: u32,
    /// Unix time the current attempt started (None when pending).
    pub started_at: Option<f64>,
    /// Unix time of the running attempt's last heartbeat (None when pending).
    pub heartbeat_at: Option<f64>,
    /// Simulated time (s) and unix time of its last checkpoint in the database, if any.
    pub checkpoint: Option<(f64, f64)>,
    /// Where the packing stood at that checkpoint (None for checkpoints of sedpack before 0.2.1).
    pub stage: Option<Stage>,
}

/// One job of an export, with its result and grain statistics if it is done.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ExportRow {
    pub job_id: String,
    pub state: JobState,
    pub seed: u64,
    pub attempts: u32,
    pub error: Option<String>,
    pub parameters: Map<String, Value>,
    pub experiment_porosity: Option<f64>,
    pub experiment_std: Option<f64>,
    pub fluid: Option<Value>,
    pub result: Option<JobResult>,
    pub grain_statistics: Vec<GrainStatistic>,
}

/// A done job as one database hands it to another (`sedpack export --format jsonl`, `sedpack
/// import`): the job as submitted, its last attempt and its result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArchivedJob {
    #[serde(flatten)]
    pub job: NewJob,
    /// Who ran it last, how many times it was claimed, and when its last attempt started and
    /// ended (UNIX seconds of the machine that ran it).
    pub worker_id: Option<String>,
    pub attempts: u32,
    pub started_at: Option<f64>,
    pub finished_at: Option<f64>,
    pub result: JobResult,
    pub grain_statistics: Vec<GrainStatistic>,
}

/// What [`crate::Store::import`] did with the jobs it was given.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Imported {
    /// Jobs the database did not have, added done.
    pub added: u64,
    /// Jobs the database had pending or failed, now done with the imported result (their
    /// checkpoints dropped).
    pub completed: u64,
    /// Jobs the database had done already: their stored results are kept.
    pub kept: u64,
    /// Jobs a worker of the database is running: left to it.
    pub running: Vec<String>,
}
