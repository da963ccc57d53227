//! sedpack's SQLite store: campaigns, the job queue, results, grain statistics and checkpoints.
//!
//! The store knows nothing of DEM or YAML: a job's spec, its parameters and a result's porosity
//! profile are opaque JSON to it.
//! Several processes may share one database file: every state change is one statement or one
//! write transaction, and a job changes hands only through [`Store::claim`]. Timestamps are UNIX
//! seconds from the clock of the process that writes them.

mod error;
mod open;
mod sql;
mod types;

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::time::{Duration, SystemTime, UNIX_EPOCH};

use serde::Serialize;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};
use sqlx::sqlite::{
    SqliteConnectOptions, SqliteConnection, SqliteExecutor, SqlitePool, SqlitePoolOptions, SqliteSynchronous,
};

pub use error::StoreError;
pub use types::{
    ArchivedJob, Campaign, CampaignStatus, Checkpoint, ClaimedJob, ExportRow, Failure, GrainStatistic, Imported,
    JobResult, JobState, NewJob, Progress, RunningJob, Stage, StoredJob,
};

/// How long a statement waits for another connection's lock before it fails.
const BUSY_TIMEOUT: Duration = Duration::from_secs(30);
const POOL_SIZE: u32 = 4;

/// An open sedpack database; cheap to clone, all clones share one connection pool.
#[derive(Debug, Clone)]
pub struct Store {
    pool: SqlitePool,
    path: PathBuf,
}

impl Store {
    /// Opens the sedpack database at `path`, creating it if missing and updating its schema.
    /// Refuses, leaving them unchanged, files that are not SQLite and other applications' databases.
    pub async fn open(path: impl AsRef<Path>) -> Result<Store, StoreError> {
        let path = path.as_ref().to_path_buf();
        let options = SqliteConnectOptions::new()
            .filename(&path)
            .foreign_keys(true)
            .busy_timeout(BUSY_TIMEOUT)
            // A committed result survives a power cut.
            .synchronous(SqliteSynchronous::Full);
        open::prepare(&path, &options, BUSY_TIMEOUT).await?;
        let pool = SqlitePoolOptions::new()
            .max_connections(POOL_SIZE)
            .connect_with(options)
            .await
            .map_err(|source| StoreError::Database { path: path.clone(), source })?;
        Ok(Store { pool, path })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Waits for running statements and closes every connection.
    pub async fn close(self) {
        self.pool.close().await;
    }

    /// Records a campaign, or replaces the spec of the campaign of that name.
    pub async fn upsert_campaign(&self, name: &str, spec: &str) -> Result<(), StoreError> {
        sqlx::query(sql::UPSERT_CAMPAIGN)
            .bind(name)
            .bind(spec)
            .bind(now())
            .execute(&self.pool)
            .await
            .map_err(self.db())?;
        Ok(())
    }

    pub async fn campaign(&self, name: &str) -> Result<Campaign, StoreError> {
        let row: Option<CampaignRow> =
            sqlx::query_as(sql::CAMPAIGN).bind(name).fetch_optional(&self.pool).await.map_err(self.db())?;
        self.campaign_of(row.ok_or_else(|| self.no_campaign(name))?)
    }

    pub async fn campaigns(&self) -> Result<Vec<Campaign>, StoreError> {
        let rows: Vec<CampaignRow> = sqlx::query_as(sql::CAMPAIGNS).fetch_all(&self.pool).await.map_err(self.db())?;
        rows.into_iter().map(|row| self.campaign_of(row)).collect()
    }

    fn campaign_of(&self, (name, spec, executor, created_at, updated_at): CampaignRow) -> Result<Campaign, StoreError> {
        let executor = match executor {
            Some(text) => Some(self.decode_json(&text, &format!("executor of campaign {name:?}"))?),
            None => None,
        };
        Ok(Campaign { name, spec, executor, created_at, updated_at })
    }

    /// Records the executor the campaign's jobs are handed to (None: this machine's workers).
    pub async fn set_executor(&self, name: &str, executor: Option<&Value>) -> Result<(), StoreError> {
        let executor = executor.map(|e| self.encode_json(e, &format!("executor of campaign {name:?}"))).transpose()?;
        if self.changed(sqlx::query(sql::SET_EXECUTOR).bind(name).bind(executor)).await? == 0 {
            return Err(self.no_campaign(name));
        }
        Ok(())
    }

    /// Adds the jobs whose id is new and returns how many were; known ids are left as they are.
    /// An id that belongs to another campaign is an error and nothing is added.
    pub async fn add_jobs(&self, campaign: &str, jobs: &[NewJob]) -> Result<u64, StoreError> {
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let now = now();
        let mut added = 0;
        for job in jobs {
            let inserted = self
                .bind_job(sql::INSERT_JOB, job, campaign_id, now)?
                .execute(&mut *tx)
                .await
                .map_err(self.db())?
                .rows_affected();
            if inserted == 0 {
                let (owner, _state): (String, String) = sqlx::query_as(sql::JOB_CAMPAIGN_STATE)
                    .bind(&job.id)
                    .fetch_one(&mut *tx)
                    .await
                    .map_err(self.db())?;
                if owner != campaign {
                    return Err(self.invalid(format!(
                        "job {} already belongs to campaign {owner:?}, not {campaign:?}: job ids \
                         must be unique across campaigns",
                        job.id
                    )));
                }
            }
            added += inserted;
        }
        tx.commit().await.map_err(self.db())?;
        Ok(added)
    }

    /// Hands the campaign's next pending job (in submission order; of those in `only`, if given)
    /// to `worker_id`, or None if no such job is pending. No two claimers, in this process or
    /// another, ever get the same job.
    pub async fn claim(
        &self,
        campaign: &str,
        worker_id: &str,
        only: Option<&[String]>,
    ) -> Result<Option<ClaimedJob>, StoreError> {
        let only = only.map(|ids| self.encode_json(&ids, "job ids")).transpose()?;
        let mut conn = self.pool.acquire().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut conn, campaign).await?;
        // One UPDATE … RETURNING takes the write lock before it reads, so the pick is atomic.
        let row: Option<(String, u32, String, u64, String, u32)> = sqlx::query_as(sql::CLAIM_JOB)
            .bind(campaign_id)
            .bind(worker_id)
            .bind(now())
            .bind(only)
            .fetch_optional(&mut *conn)
            .await
            .map_err(self.db())?;
        let Some((id, format, spec, seed, parameters, attempts)) = row else {
            return Ok(None);
        };
        Ok(Some(ClaimedJob {
            format,
            spec: self.decode_json(&spec, &format!("spec of job {id}"))?,
            parameters: self.decode_json(&parameters, &format!("parameters of job {id}"))?,
            id,
            seed,
            attempts,
        }))
    }

    /// Hands up to `count` of the campaign's pending jobs (of those in `only`, if given), in
    /// submission order, to the workers `worker(k)` (k = 0, 1, … in the order handed) in one
    /// transaction, and gives them.
    pub async fn claim_many(
        &self,
        campaign: &str,
        only: Option<&[String]>,
        count: usize,
        worker: impl Fn(usize) -> String,
    ) -> Result<Vec<ClaimedJob>, StoreError> {
        let only = only.map(|ids| self.encode_json(&ids, "job ids")).transpose()?;
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let limit = i64::try_from(count).unwrap_or(i64::MAX);
        let ids: Vec<String> = sqlx::query_scalar(sql::PENDING_JOBS)
            .bind(campaign_id)
            .bind(limit)
            .bind(only)
            .fetch_all(&mut *tx)
            .await
            .map_err(self.db())?;
        let now = now();
        let mut claimed = Vec::with_capacity(ids.len());
        for id in ids {
            let (id, format, spec, seed, parameters, attempts): (String, u32, String, u64, String, u32) =
                sqlx::query_as(sql::CLAIM_JOBS)
                    .bind(&id)
                    .bind(campaign_id)
                    .bind(worker(claimed.len()))
                    .bind(now)
                    .fetch_one(&mut *tx)
                    .await
                    .map_err(self.db())?;
            claimed.push(ClaimedJob {
                format,
                spec: self.decode_json(&spec, &format!("spec of job {id}"))?,
                parameters: self.decode_json(&parameters, &format!("parameters of job {id}"))?,
                id,
                seed,
                attempts,
            });
        }
        tx.commit().await.map_err(self.db())?;
        Ok(claimed)
    }

    /// Hands a running job from worker `from` to worker `to`; false, changing nothing, if it is
    /// no longer running for `from`.
    pub async fn reassign(&self, job_id: &str, from: &str, to: &str) -> Result<bool, StoreError> {
        Ok(self.changed(sqlx::query(sql::REASSIGN_JOB).bind(job_id).bind(from).bind(to).bind(now())).await? == 1)
    }

    /// Gives the campaign's stored jobs among `jobs` (id → grid parameters) the parameters given,
    /// in one transaction, and returns how many changed: a job keeps its id when its campaign's
    /// grid gains an axis (`grains.size: [U1]` becoming `[U1, U7]`), but not its grid values.
    /// Ids of other campaigns, or unknown, change nothing.
    pub async fn set_parameters(
        &self,
        campaign: &str,
        jobs: &[(String, Map<String, Value>)],
    ) -> Result<u64, StoreError> {
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let mut changed = 0;
        for (id, parameters) in jobs {
            changed += sqlx::query(sql::SET_PARAMETERS)
                .bind(id)
                .bind(campaign_id)
                .bind(self.encode_json(parameters, &format!("parameters of job {id}"))?)
                .execute(&mut *tx)
                .await
                .map_err(self.db())?
                .rows_affected();
        }
        tx.commit().await.map_err(self.db())?;
        Ok(changed)
    }

    /// Replaces the stored spec of a job that is not done (the same job, described anew); false,
    /// changing nothing, for a done job.
    pub async fn replace_spec(&self, job_id: &str, format: u32, spec: &Value) -> Result<bool, StoreError> {
        let spec = self.encode_json(spec, &format!("spec of job {job_id}"))?;
        Ok(self.changed(sqlx::query(sql::REPLACE_SPEC).bind(job_id).bind(format).bind(spec)).await? == 1)
    }

    /// Every job of the campaign in submission order: its stored spec and where it stands.
    pub async fn jobs(&self, campaign: &str) -> Result<Vec<StoredJob>, StoreError> {
        type Row = (String, u32, String, String, Option<String>, u32, Option<String>);
        let mut conn = self.pool.acquire().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut conn, campaign).await?;
        let rows: Vec<Row> =
            sqlx::query_as(sql::JOBS).bind(campaign_id).fetch_all(&mut *conn).await.map_err(self.db())?;
        rows.into_iter()
            .map(|(id, format, spec, state, worker_id, attempts, error)| {
                Ok(StoredJob {
                    spec: self.decode_json(&spec, &format!("spec of job {id}"))?,
                    state: self.state(&id, &state)?,
                    id,
                    format,
                    worker_id,
                    attempts,
                    error,
                })
            })
            .collect()
    }

    /// Tells the store that `worker_id` is still working on the job.
    /// Fails with [`StoreError::NotOwner`] if the job was taken away, so the worker can stop.
    pub async fn heartbeat(&self, job_id: &str, worker_id: &str) -> Result<(), StoreError> {
        self.update_owned(&self.pool, sql::HEARTBEAT, job_id, worker_id, now(), None).await
    }

    /// Marks the job done with its result and grain statistics, all or nothing, and drops its
    /// checkpoint. Fails with [`StoreError::NotOwner`], writing nothing, unless the job is still
    /// running for `worker_id`.
    pub async fn complete(
        &self,
        job_id: &str,
        worker_id: &str,
        result: &JobResult,
        statistics: &[GrainStatistic],
    ) -> Result<(), StoreError> {
        self.finish(job_id, worker_id, None, result, statistics).await
    }

    /// [`Store::complete`] for a job that ran elsewhere from `started_at` to `finished_at`
    /// (UNIX seconds), rather than from its claim to now.
    pub async fn complete_ran(
        &self,
        job_id: &str,
        worker_id: &str,
        (started_at, finished_at): (f64, f64),
        result: &JobResult,
        statistics: &[GrainStatistic],
    ) -> Result<(), StoreError> {
        self.finish(job_id, worker_id, Some((started_at, finished_at)), result, statistics).await
    }

    async fn finish(
        &self,
        job_id: &str,
        worker_id: &str,
        ran: Option<(f64, f64)>,
        result: &JobResult,
        statistics: &[GrainStatistic],
    ) -> Result<(), StoreError> {
        let now = now();
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        let finished = sqlx::query(sql::FINISH_JOB)
            .bind(job_id)
            .bind(worker_id)
            .bind(ran.map_or(now, |(_, finished_at)| finished_at))
            .bind(ran.map(|(started_at, _)| started_at))
            .execute(&mut *tx)
            .await
            .map_err(self.db())?
            .rows_affected();
        if finished != 1 {
            return Err(self.not_owner(job_id, worker_id));
        }
        self.insert_result(&mut tx, job_id, result, statistics, now).await?;
        tx.commit().await.map_err(self.db())
    }

    /// Stores a done job's result and grain statistics and drops its checkpoint, in the caller's
    /// transaction.
    async fn insert_result(
        &self,
        conn: &mut SqliteConnection,
        job_id: &str,
        result: &JobResult,
        statistics: &[GrainStatistic],
        now: f64,
    ) -> Result<(), StoreError> {
        let profile = self.encode_json(&result.profile, &format!("profile of job {job_id}"))?;
        let particles = self.to_sql_int(result.particles, &format!("particles of job {job_id}"))?;
        let steps = self.to_sql_int(result.steps, &format!("steps of job {job_id}"))?;
        let imbrication = result
            .imbrication
            .as_ref()
            .map(|i| self.encode_json(i, &format!("imbrication of job {job_id}")))
            .transpose()?;
        let size_classes = result
            .size_classes
            .as_ref()
            .map(|c| self.encode_json(c, &format!("size classes of job {job_id}")))
            .transpose()?;
        sqlx::query(sql::INSERT_RESULT)
            .bind(job_id)
            .bind(result.porosity)
            .bind(result.z_minus)
            .bind(result.z_plus)
            .bind(profile)
            .bind(particles)
            .bind(result.simulated_time)
            .bind(steps)
            .bind(result.wall_time)
            .bind(&result.solver_version)
            .bind(now)
            .bind(imbrication)
            .bind(size_classes)
            .execute(&mut *conn)
            .await
            .map_err(self.db())?;
        for statistic in statistics {
            sqlx::query(sql::INSERT_GRAIN_STATISTIC)
                .bind(job_id)
                .bind(&statistic.name)
                .bind(statistic.mean)
                .bind(statistic.std)
                .execute(&mut *conn)
                .await
                .map_err(self.db())?;
        }
        sqlx::query(sql::DELETE_CHECKPOINT).bind(job_id).execute(&mut *conn).await.map_err(self.db())?;
        Ok(())
    }

    /// Marks the job failed with its error text and drops its checkpoint, so that a retry starts
    /// afresh rather than from the state that failed. Same ownership rule as [`Store::complete`].
    pub async fn fail(&self, job_id: &str, worker_id: &str, error: &str) -> Result<(), StoreError> {
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        self.update_owned(&mut *tx, sql::FAIL_JOB, job_id, worker_id, now(), Some(error)).await?;
        sqlx::query(sql::DELETE_CHECKPOINT).bind(job_id).execute(&mut *tx).await.map_err(self.db())?;
        tx.commit().await.map_err(self.db())
    }

    /// Returns the job to pending if it is still running for `worker_id`: a worker's own job on
    /// Ctrl-C, or the job of a worker the caller knows is gone. Its checkpoint stays, attempts
    /// keep counting. Returns false, changing nothing, if the job had already changed hands.
    pub async fn release(&self, job_id: &str, worker_id: &str) -> Result<bool, StoreError> {
        Ok(self.changed(sqlx::query(sql::RELEASE_JOB).bind(job_id).bind(worker_id)).await? == 1)
    }

    /// The campaign's running jobs with their workers and heartbeats.
    pub async fn running_jobs(&self, campaign: &str) -> Result<Vec<RunningJob>, StoreError> {
        let mut conn = self.pool.acquire().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut conn, campaign).await?;
        let rows: Vec<(String, String, u32, f64, f64)> =
            sqlx::query_as(sql::RUNNING_JOBS).bind(campaign_id).fetch_all(&mut *conn).await.map_err(self.db())?;
        Ok(rows
            .into_iter()
            .map(|(job_id, worker_id, attempts, started_at, heartbeat_at)| RunningJob {
                job_id,
                worker_id,
                attempts,
                started_at,
                heartbeat_at,
            })
            .collect())
    }

    /// Returns to pending every running job of the campaign whose last heartbeat is older than
    /// `older_than`, and gives their ids.
    pub async fn requeue_stale(&self, campaign: &str, older_than: Duration) -> Result<Vec<String>, StoreError> {
        let mut conn = self.pool.acquire().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut conn, campaign).await?;
        sqlx::query_scalar(sql::REQUEUE_STALE)
            .bind(campaign_id)
            .bind(now() - older_than.as_secs_f64())
            .fetch_all(&mut *conn)
            .await
            .map_err(self.db())
    }

    /// Returns the campaign's failed jobs to pending, clearing their errors; gives how many.
    pub async fn requeue_failed(&self, campaign: &str) -> Result<u64, StoreError> {
        let mut conn = self.pool.acquire().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut conn, campaign).await?;
        let requeued = sqlx::query(sql::REQUEUE_FAILED)
            .bind(campaign_id)
            .execute(&mut *conn)
            .await
            .map_err(self.db())?
            .rows_affected();
        Ok(requeued)
    }

    /// Saves (replacing any earlier one) the job's checkpoint, taken at `simulated_time` and
    /// `stage`; counts as a heartbeat.
    /// Fails with [`StoreError::NotOwner`], writing nothing, unless the job is running for `worker_id`.
    pub async fn save_checkpoint(
        &self,
        job_id: &str,
        worker_id: &str,
        data: &[u8],
        simulated_time: f64,
        stage: Option<&Stage>,
    ) -> Result<(), StoreError> {
        let now = now();
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        self.update_owned(&mut *tx, sql::HEARTBEAT, job_id, worker_id, now, None).await?;
        sqlx::query(sql::UPSERT_CHECKPOINT)
            .bind(job_id)
            .bind(data)
            .bind(simulated_time)
            .bind(now)
            .bind(stage.map(|s| s.phase.as_str()))
            .bind(stage.map(|s| s.grains as i64))
            .bind(stage.map(|s| s.mass_created))
            .bind(stage.and_then(|s| s.shaking_until))
            .execute(&mut *tx)
            .await
            .map_err(self.db())?;
        tx.commit().await.map_err(self.db())
    }

    pub async fn load_checkpoint(&self, job_id: &str) -> Result<Option<Checkpoint>, StoreError> {
        let row: Option<(Vec<u8>, f64, f64)> =
            sqlx::query_as(sql::LOAD_CHECKPOINT).bind(job_id).fetch_optional(&self.pool).await.map_err(self.db())?;
        Ok(row.map(|(data, simulated_time, written_at)| Checkpoint { data, simulated_time, written_at }))
    }

    /// Deletes the job's checkpoint; returns whether there was one.
    pub async fn delete_checkpoint(&self, job_id: &str) -> Result<bool, StoreError> {
        Ok(self.changed(sqlx::query(sql::DELETE_CHECKPOINT).bind(job_id)).await? == 1)
    }

    /// Counts per state, the failures with their errors and the wall times, from one snapshot.
    pub async fn status(&self, campaign: &str) -> Result<CampaignStatus, StoreError> {
        let mut tx = self.pool.begin().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        type Counts = (u64, u64, u64, u64, u64, f64, Option<f64>, Option<f64>);
        let counts: Counts =
            sqlx::query_as(sql::STATUS_COUNTS).bind(campaign_id).fetch_one(&mut *tx).await.map_err(self.db())?;
        let (jobs, pending, running, done, failed, wall_time_finished, mean_wall_time_done, mean_simulated_time_done) =
            counts;
        let failures: Vec<(String, u32, String)> =
            sqlx::query_as(sql::FAILURES).bind(campaign_id).fetch_all(&mut *tx).await.map_err(self.db())?;
        type ProgressRow = (
            String,
            String,
            Option<String>,
            u32,
            Option<f64>,
            Option<f64>,
            Option<f64>,
            Option<f64>,
            Option<String>,
            Option<i64>,
            Option<f64>,
            Option<f64>,
        );
        let in_progress: Vec<ProgressRow> =
            sqlx::query_as(sql::IN_PROGRESS).bind(campaign_id).fetch_all(&mut *tx).await.map_err(self.db())?;
        tx.commit().await.map_err(self.db())?;
        let in_progress = in_progress
            .into_iter()
            .map(|row| {
                let (
                    job_id,
                    state,
                    worker_id,
                    attempts,
                    started_at,
                    heartbeat_at,
                    simulated,
                    written,
                    phase,
                    grains,
                    mass,
                    until,
                ) = row;
                let stage = match (phase, grains, mass) {
                    (Some(phase), Some(grains), Some(mass_created)) => {
                        Some(Stage { phase, grains: grains as u64, mass_created, shaking_until: until })
                    }
                    _ => None,
                };
                Ok(Progress {
                    state: self.state(&job_id, &state)?,
                    job_id,
                    worker_id,
                    attempts,
                    started_at,
                    heartbeat_at,
                    checkpoint: simulated.zip(written),
                    stage,
                })
            })
            .collect::<Result<_, StoreError>>()?;
        Ok(CampaignStatus {
            campaign: campaign.to_string(),
            jobs,
            pending,
            running,
            done,
            failed,
            failures: failures
                .into_iter()
                .map(|(job_id, attempts, error)| Failure { job_id, attempts, error })
                .collect(),
            wall_time_finished,
            mean_wall_time_done,
            mean_simulated_time_done,
            in_progress,
        })
    }

    /// Every job of the campaign in submission order, with its result and grain statistics,
    /// from one snapshot.
    pub async fn export(&self, campaign: &str) -> Result<Vec<ExportRow>, StoreError> {
        type JobRow = (String, String, u64, u32, Option<String>, String, Option<f64>, Option<f64>, Option<String>);
        let mut tx = self.pool.begin().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let jobs: Vec<JobRow> =
            sqlx::query_as(sql::EXPORT_JOBS).bind(campaign_id).fetch_all(&mut *tx).await.map_err(self.db())?;
        let (mut results, mut statistics) = self.results_of(&mut tx, campaign_id).await?;
        tx.commit().await.map_err(self.db())?;
        jobs.into_iter()
            .map(|(job_id, state, seed, attempts, error, parameters, experiment_porosity, experiment_std, fluid)| {
                Ok(ExportRow {
                    state: self.state(&job_id, &state)?,
                    seed,
                    attempts,
                    error,
                    parameters: self.decode_json(&parameters, &format!("parameters of job {job_id}"))?,
                    experiment_porosity,
                    experiment_std,
                    fluid: fluid.map(|f| self.decode_json(&f, &format!("fluid of job {job_id}"))).transpose()?,
                    result: results.remove(&job_id),
                    grain_statistics: statistics.remove(&job_id).unwrap_or_default(),
                    job_id,
                })
            })
            .collect()
    }

    /// The campaign's done jobs in submission order, whole, from one snapshot: what
    /// [`Store::import`] takes into another database.
    pub async fn archive(&self, campaign: &str) -> Result<Vec<ArchivedJob>, StoreError> {
        type JobRow = (
            String,
            u32,
            String,
            u64,
            String,
            Option<f64>,
            Option<f64>,
            Option<String>,
            Option<String>,
            u32,
            Option<f64>,
            Option<f64>,
        );
        let mut tx = self.pool.begin().await.map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let jobs: Vec<JobRow> =
            sqlx::query_as(sql::ARCHIVE_JOBS).bind(campaign_id).fetch_all(&mut *tx).await.map_err(self.db())?;
        let (mut results, mut statistics) = self.results_of(&mut tx, campaign_id).await?;
        tx.commit().await.map_err(self.db())?;
        jobs.into_iter()
            .map(|row| {
                let (
                    id,
                    format,
                    spec,
                    seed,
                    parameters,
                    experiment_porosity,
                    experiment_std,
                    fluid,
                    worker_id,
                    attempts,
                    started_at,
                    finished_at,
                ) = row;
                let result =
                    results.remove(&id).ok_or_else(|| self.invalid(format!("job {id} is done but has no result")))?;
                Ok(ArchivedJob {
                    job: NewJob {
                        format,
                        spec: self.decode_json(&spec, &format!("spec of job {id}"))?,
                        seed,
                        parameters: self.decode_json(&parameters, &format!("parameters of job {id}"))?,
                        experiment_porosity,
                        experiment_std,
                        fluid: fluid.map(|f| self.decode_json(&f, &format!("fluid of job {id}"))).transpose()?,
                        id: id.clone(),
                    },
                    worker_id,
                    attempts,
                    started_at,
                    finished_at,
                    result,
                    grain_statistics: statistics.remove(&id).unwrap_or_default(),
                })
            })
            .collect()
    }

    /// Takes done jobs of another database into this one, all or nothing: the campaign is
    /// created with `spec` if this database has none of that name (else its spec is kept); a job
    /// it lacks is added done, one it has pending or failed is completed with the imported result,
    /// one it has done keeps its own result, and one a worker runs is left to it. A job id that
    /// belongs to another campaign is an error and nothing is imported.
    pub async fn import(&self, campaign: &str, spec: &str, jobs: &[ArchivedJob]) -> Result<Imported, StoreError> {
        let now = now();
        let mut tx = self.pool.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(self.db())?;
        sqlx::query(sql::INSERT_CAMPAIGN_IF_NEW)
            .bind(campaign)
            .bind(spec)
            .bind(now)
            .execute(&mut *tx)
            .await
            .map_err(self.db())?;
        let campaign_id = self.campaign_id(&mut tx, campaign).await?;
        let mut imported = Imported::default();
        for archived in jobs {
            let job = &archived.job;
            let stored: Option<(String, String)> = sqlx::query_as(sql::JOB_CAMPAIGN_STATE)
                .bind(&job.id)
                .fetch_optional(&mut *tx)
                .await
                .map_err(self.db())?;
            match stored {
                Some((owner, _)) if owner != campaign => {
                    return Err(self.invalid(format!(
                        "job {} already belongs to campaign {owner:?}, not {campaign:?}: job ids must be unique \
                         across campaigns",
                        job.id
                    )));
                }
                Some((_, state)) => match self.state(&job.id, &state)? {
                    JobState::Done => {
                        imported.kept += 1;
                        continue;
                    }
                    JobState::Running => {
                        imported.running.push(job.id.clone());
                        continue;
                    }
                    JobState::Pending | JobState::Failed => {
                        bind_attempt(sqlx::query(sql::COMPLETE_IMPORTED).bind(&job.id), archived)
                            .execute(&mut *tx)
                            .await
                            .map_err(self.db())?;
                        imported.completed += 1;
                    }
                },
                None => {
                    bind_attempt(self.bind_job(sql::INSERT_DONE_JOB, job, campaign_id, now)?, archived)
                        .execute(&mut *tx)
                        .await
                        .map_err(self.db())?;
                    imported.added += 1;
                }
            }
            self.insert_result(&mut tx, &job.id, &archived.result, &archived.grain_statistics, now).await?;
        }
        tx.commit().await.map_err(self.db())?;
        Ok(imported)
    }

    /// The results and grain statistics of the campaign's jobs, by job id.
    async fn results_of(
        &self,
        conn: &mut SqliteConnection,
        campaign_id: i64,
    ) -> Result<(HashMap<String, JobResult>, HashMap<String, Vec<GrainStatistic>>), StoreError> {
        type ResultRow = (String, f64, f64, f64, String, u64, f64, u64, f64, String, Option<String>, Option<String>);
        let results: Vec<ResultRow> =
            sqlx::query_as(sql::EXPORT_RESULTS).bind(campaign_id).fetch_all(&mut *conn).await.map_err(self.db())?;
        let statistics: Vec<(String, String, f64, f64)> = sqlx::query_as(sql::EXPORT_GRAIN_STATISTICS)
            .bind(campaign_id)
            .fetch_all(&mut *conn)
            .await
            .map_err(self.db())?;
        let mut results_by_job = HashMap::new();
        for (
            job_id,
            porosity,
            z_minus,
            z_plus,
            profile,
            particles,
            simulated_time,
            steps,
            wall_time,
            solver_version,
            imbrication,
            size_classes,
        ) in results
        {
            let profile = self.decode_json(&profile, &format!("profile of job {job_id}"))?;
            let imbrication =
                imbrication.map(|i| self.decode_json(&i, &format!("imbrication of job {job_id}"))).transpose()?;
            let size_classes =
                size_classes.map(|c| self.decode_json(&c, &format!("size classes of job {job_id}"))).transpose()?;
            let result = JobResult {
                porosity,
                z_minus,
                z_plus,
                profile,
                particles,
                simulated_time,
                steps,
                wall_time,
                solver_version,
                imbrication,
                size_classes,
            };
            results_by_job.insert(job_id, result);
        }
        let mut statistics_by_job: HashMap<String, Vec<GrainStatistic>> = HashMap::new();
        for (job_id, name, mean, std) in statistics {
            statistics_by_job.entry(job_id).or_default().push(GrainStatistic { name, mean, std });
        }
        Ok((results_by_job, statistics_by_job))
    }

    async fn campaign_id(&self, conn: &mut SqliteConnection, name: &str) -> Result<i64, StoreError> {
        let id: Option<i64> =
            sqlx::query_scalar(sql::CAMPAIGN_ID).bind(name).fetch_optional(conn).await.map_err(self.db())?;
        id.ok_or_else(|| self.no_campaign(name))
    }

    /// Runs an UPDATE of the job that applies only while it runs for `worker_id` (parameters: ?1
    /// the job, ?2 the worker, ?3 the time, ?4 `text` if given); touching no row is
    /// [`StoreError::NotOwner`].
    async fn update_owned<'c>(
        &self,
        executor: impl SqliteExecutor<'c>,
        statement: &'static str,
        job_id: &str,
        worker_id: &str,
        now: f64,
        text: Option<&str>,
    ) -> Result<(), StoreError> {
        let mut query = sqlx::query(statement).bind(job_id).bind(worker_id).bind(now);
        if let Some(text) = text {
            query = query.bind(text);
        }
        let updated = query.execute(executor).await.map_err(self.db())?.rows_affected();
        if updated == 1 { Ok(()) } else { Err(self.not_owner(job_id, worker_id)) }
    }

    /// The statement with ?1 to ?10 bound to the job as submitted, as [`sql::INSERT_JOB`] and
    /// [`sql::INSERT_DONE_JOB`] take it.
    fn bind_job<'q>(
        &self,
        statement: &'static str,
        job: &'q NewJob,
        campaign_id: i64,
        now: f64,
    ) -> Result<sqlx::query::Query<'q, sqlx::Sqlite, sqlx::sqlite::SqliteArguments>, StoreError> {
        let what = |field: &str| format!("{field} of job {}", job.id);
        Ok(sqlx::query(statement)
            .bind(&job.id)
            .bind(campaign_id)
            .bind(job.format)
            .bind(self.encode_json(&job.spec, &what("spec"))?)
            .bind(self.to_sql_int(job.seed, &what("seed"))?)
            .bind(self.encode_json(&job.parameters, &what("parameters"))?)
            .bind(job.experiment_porosity)
            .bind(job.experiment_std)
            .bind(now)
            .bind(job.fluid.as_ref().map(|f| self.encode_json(f, &what("fluid"))).transpose()?))
    }

    /// Runs one statement on the pool; gives how many rows it changed.
    async fn changed(
        &self,
        query: sqlx::query::Query<'_, sqlx::Sqlite, sqlx::sqlite::SqliteArguments>,
    ) -> Result<u64, StoreError> {
        Ok(query.execute(&self.pool).await.map_err(self.db())?.rows_affected())
    }

    fn not_owner(&self, job_id: &str, worker_id: &str) -> StoreError {
        StoreError::NotOwner { path: self.path.clone(), job_id: job_id.to_string(), worker_id: worker_id.to_string() }
    }

    fn state(&self, job_id: &str, state: &str) -> Result<JobState, StoreError> {
        JobState::parse(state).ok_or_else(|| self.invalid(format!("job {job_id} has the unknown state {state:?}")))
    }

    fn db(&self) -> impl Fn(sqlx::Error) -> StoreError + '_ {
        |source| StoreError::Database { path: self.path.clone(), source }
    }

    fn invalid(&self, detail: String) -> StoreError {
        StoreError::Invalid { path: self.path.clone(), detail }
    }

    fn no_campaign(&self, name: &str) -> StoreError {
        StoreError::NoCampaign { path: self.path.clone(), name: name.to_string() }
    }

    fn encode_json(&self, value: &impl Serialize, what: &str) -> Result<String, StoreError> {
        serde_json::to_string(value).map_err(|e| self.invalid(format!("{what}: {e}")))
    }

    fn decode_json<T: DeserializeOwned>(&self, text: &str, what: &str) -> Result<T, StoreError> {
        serde_json::from_str(text).map_err(|e| self.invalid(format!("{what} is unreadable: {e}")))
    }

    /// SQLite integers are signed 64-bit.
    fn to_sql_int(&self, value: u64, what: &str) -> Result<i64, StoreError> {
        i64::try_from(value)
            .map_err(|_| self.invalid(format!("{what} = {value} exceeds 2^63 - 1, the largest SQLite integer")))
    }
}

/// The query with its next four parameters bound to the archived job's last attempt: who ran
/// it, how many times it was claimed, when it started and ended.
fn bind_attempt<'q>(
    query: sqlx::query::Query<'q, sqlx::Sqlite, sqlx::sqlite::SqliteArguments>,
    archived: &'q ArchivedJob,
) -> sqlx::query::Query<'q, sqlx::Sqlite, sqlx::sqlite::SqliteArguments> {
    query.bind(&archived.worker_id).bind(archived.attempts).bind(archived.started_at).bind(archived.finished_at)
}

/// name, spec, executor, created_at, updated_at
type CampaignRow = (String, String, Option<String>, f64, f64);

/// UNIX seconds from this process's clock.
fn now() -> f64 {
    SystemTime::now().duration_since(UNIX_EPOCH).unwrap_or_default().as_secs_f64()
}
