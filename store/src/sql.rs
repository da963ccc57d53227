//! Every SQL statement of the store, as plain strings with numbered parameters.

// Opening
pub const APPLICATION_ID: &str = "PRAGMA application_id";
pub const USER_TABLES: &str = "
    SELECT name FROM sqlite_schema
    WHERE type IN ('table', 'view') AND name NOT LIKE 'sqlite\\_%' ESCAPE '\\' ORDER BY name";
pub const JOURNAL_MODE_WAL: &str = "PRAGMA journal_mode = WAL";
pub const BEGIN_IMMEDIATE: &str = "BEGIN IMMEDIATE";

// Campaigns
pub const UPSERT_CAMPAIGN: &str = "
    INSERT INTO campaigns (name, spec, created_at, updated_at) VALUES (?1, ?2, ?3, ?3)
    ON CONFLICT (name) DO UPDATE SET spec = excluded.spec, updated_at = excluded.updated_at";
pub const INSERT_CAMPAIGN_IF_NEW: &str = "
    INSERT INTO campaigns (name, spec, created_at, updated_at) VALUES (?1, ?2, ?3, ?3)
    ON CONFLICT (name) DO NOTHING";
pub const CAMPAIGN_ID: &str = "SELECT id FROM campaigns WHERE name = ?1";
pub const CAMPAIGN: &str = "SELECT name, spec, executor, created_at, updated_at FROM campaigns WHERE name = ?1";
pub const CAMPAIGNS: &str =
    "SELECT name, spec, executor, created_at, updated_at FROM campaigns ORDER BY created_at, name";
pub const SET_EXECUTOR: &str = "UPDATE campaigns SET executor = ?2 WHERE name = ?1";

// Jobs
pub const INSERT_JOB: &str = "
    INSERT INTO jobs (id, campaign_id, format, spec, seed, parameters, experiment_porosity, experiment_std,
                      created_at, fluid)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)
    ON CONFLICT (id) DO NOTHING";
pub const INSERT_DONE_JOB: &str = "
    INSERT INTO jobs (id, campaign_id, format, spec, seed, parameters, experiment_porosity, experiment_std,
                      created_at, fluid, state, worker_id, attempts, started_at, finished_at, heartbeat_at,
                      wall_time)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, 'done', ?11, ?12, ?13, ?14, ?14, ?14 - ?13)";
pub const COMPLETE_IMPORTED: &str = "
    UPDATE jobs
    SET state = 'done', error = NULL, worker_id = ?2, attempts = attempts + ?3, started_at = ?4,
        finished_at = ?5, heartbeat_at = ?5, wall_time = ?5 - ?4
    WHERE id = ?1 AND state IN ('pending', 'failed')";
pub const JOB_CAMPAIGN_STATE: &str = "
    SELECT campaigns.name, jobs.state FROM jobs JOIN campaigns ON campaigns.id = jobs.campaign_id
    WHERE jobs.id = ?1";
pub const CLAIM_JOB: &str = "
    UPDATE jobs
    SET state = 'running', attempts = attempts + 1, worker_id = ?2,
        started_at = ?3, heartbeat_at = ?3, finished_at = NULL, wall_time = NULL, error = NULL
    WHERE state = 'pending' AND id = (
        SELECT id FROM jobs
        WHERE campaign_id = ?1 AND state = 'pending' AND (?4 IS NULL OR id IN (SELECT value FROM json_each(?4)))
        ORDER BY rowid LIMIT 1)
    RETURNING id, format, spec, seed, parameters, attempts";
pub const CLAIM_JOBS: &str = "
    UPDATE jobs
    SET state = 'running', attempts = attempts + 1, worker_id = ?3,
        started_at = ?4, heartbeat_at = ?4, finished_at = NULL, wall_time = NULL, error = NULL
    WHERE id = ?1 AND campaign_id = ?2 AND state = 'pending'
    RETURNING id, format, spec, seed, parameters, attempts";
pub const PENDING_JOBS: &str = "
    SELECT id FROM jobs
    WHERE campaign_id = ?1 AND state = 'pending' AND (?3 IS NULL OR id IN (SELECT value FROM json_each(?3)))
    ORDER BY rowid LIMIT ?2";
pub const REASSIGN_JOB: &str = "
    UPDATE jobs SET worker_id = ?3, heartbeat_at = ?4
    WHERE id = ?1 AND worker_id = ?2 AND state = 'running'";
pub const SET_PARAMETERS: &str = "
    UPDATE jobs SET parameters = ?3 WHERE id = ?1 AND campaign_id = ?2 AND parameters <> ?3";
pub const REPLACE_SPEC: &str = "
    UPDATE jobs SET format = ?2, spec = ?3 WHERE id = ?1 AND state <> 'done'";
pub const JOBS: &str = "
    SELECT id, format, spec, state, worker_id, attempts, error FROM jobs
    WHERE campaign_id = ?1 ORDER BY rowid";
pub const HEARTBEAT: &str = "
    UPDATE jobs SET heartbeat_at = ?3
    WHERE id = ?1 AND worker_id = ?2 AND state = 'running'";
pub const FINISH_JOB: &str = "
    UPDATE jobs
    SET state = 'done', started_at = COALESCE(?4, started_at), heartbeat_at = ?3, finished_at = ?3,
        wall_time = ?3 - COALESCE(?4, started_at)
    WHERE id = ?1 AND worker_id = ?2 AND state = 'running'";
pub const FAIL_JOB: &str = "
    UPDATE jobs
    SET state = 'failed', error = ?4, heartbeat_at = ?3, finished_at = ?3, wall_time = ?3 - started_at
    WHERE id = ?1 AND worker_id = ?2 AND state = 'running'";
pub const RELEASE_JOB: &str = "
    UPDATE jobs SET state = 'pending', worker_id = NULL, heartbeat_at = NULL, started_at = NULL
    WHERE id = ?1 AND worker_id = ?2 AND state = 'running'";
pub const REQUEUE_STALE: &str = "
    UPDATE jobs SET state = 'pending', worker_id = NULL, heartbeat_at = NULL, started_at = NULL
    WHERE campaign_id = ?1 AND state = 'running' AND heartbeat_at < ?2
    RETURNING id";
pub const REQUEUE_FAILED: &str = "
    UPDATE jobs
    SET state = 'pending', error = NULL, worker_id = NULL, heartbeat_at = NULL,
        started_at = NULL, finished_at = NULL, wall_time = NULL
    WHERE campaign_id = ?1 AND state = 'failed'";
pub const RUNNING_JOBS: &str = "
    SELECT id, worker_id, attempts, started_at, heartbeat_at FROM jobs
    WHERE campaign_id = ?1 AND state = 'running' ORDER BY rowid";

// Results
pub const INSERT_RESULT: &str = "
    INSERT INTO results (job_id, porosity, z_minus, z_plus, profile, particles, simulated_time,
                         steps, wall_time, solver_version, created_at, imbrication, size_classes)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13)";
pub const INSERT_GRAIN_STATISTIC: &str =
    "INSERT INTO grain_statistics (job_id, name, mean, std) VALUES (?1, ?2, ?3, ?4)";

// Checkpoints
pub const UPSERT_CHECKPOINT: &str = "
    INSERT INTO checkpoints (job_id, data, simulated_time, written_at, phase, grains, mass_created, shaking_until)
    VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)
    ON CONFLICT (job_id) DO UPDATE
    SET data = excluded.data, simulated_time = excluded.simulated_time, written_at = excluded.written_at,
        phase = excluded.phase, grains = excluded.grains, mass_created = excluded.mass_created,
        shaking_until = excluded.shaking_until";
pub const LOAD_CHECKPOINT: &str = "SELECT data, simulated_time, written_at FROM checkpoints WHERE job_id = ?1";
pub const DELETE_CHECKPOINT: &str = "DELETE FROM checkpoints WHERE job_id = ?1";

// Status and export
// A done job's time is its packing's own over all its attempts (the result's); the job row
// keeps only the last attempt's, which for a packing resumed from checkpoints is a part of it.
pub const STATUS_COUNTS: &str = "
    SELECT COUNT(*),
           COUNT(*) FILTER (WHERE jobs.state = 'pending'),
           COUNT(*) FILTER (WHERE jobs.state = 'running'),
           COUNT(*) FILTER (WHERE jobs.state = 'done'),
           COUNT(*) FILTER (WHERE jobs.state = 'failed'),
           TOTAL(COALESCE(results.wall_time, jobs.wall_time)) FILTER (WHERE jobs.state IN ('done', 'failed')),
           AVG(COALESCE(results.wall_time, jobs.wall_time)) FILTER (WHERE jobs.state = 'done'),
           AVG(results.simulated_time) FILTER (WHERE jobs.state = 'done')
    FROM jobs LEFT JOIN results ON results.job_id = jobs.id WHERE jobs.campaign_id = ?1";
pub const IN_PROGRESS: &str = "
    SELECT jobs.id, jobs.state, jobs.worker_id, jobs.attempts, jobs.started_at, jobs.heartbeat_at,
           checkpoints.simulated_time, checkpoints.written_at,
           checkpoints.phase, checkpoints.grains, checkpoints.mass_created, checkpoints.shaking_until
    FROM jobs LEFT JOIN checkpoints ON checkpoints.job_id = jobs.id
    WHERE jobs.campaign_id = ?1
      AND (jobs.state = 'running' OR (jobs.state = 'pending' AND checkpoints.job_id IS NOT NULL))
    ORDER BY jobs.rowid";
pub const FAILURES: &str = "
    SELECT id, attempts, error FROM jobs
    WHERE campaign_id = ?1 AND state = 'failed' ORDER BY rowid";
pub const EXPORT_JOBS: &str = "
    SELECT id, state, seed, attempts, error, parameters, experiment_porosity, experiment_std, fluid FROM jobs
    WHERE campaign_id = ?1 ORDER BY rowid";
pub const ARCHIVE_JOBS: &str = "
    SELECT id, format, spec, seed, parameters, experiment_porosity, experiment_std, fluid,
           worker_id, attempts, started_at, finished_at
    FROM jobs WHERE campaign_id = ?1 AND state = 'done' ORDER BY rowid";
pub const EXPORT_RESULTS: &str = "
    SELECT results.job_id, porosity, z_minus, z_plus, profile, particles, simulated_time, steps,
           results.wall_time, solver_version, imbrication, size_classes
    FROM results JOIN jobs ON jobs.id = results.job_id
    WHERE jobs.campaign_id = ?1";
pub const EXPORT_GRAIN_STATISTICS: &str = "
    SELECT grain_statistics.job_id, name, mean, std
    FROM grain_statistics JOIN jobs ON jobs.id = grain_statistics.job_id
    WHERE jobs.campaign_id = ?1 ORDER BY grain_statistics.rowid";
