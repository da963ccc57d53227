-- sedpack's schema. Timestamps are UNIX seconds (REAL), durations seconds.

-- Marks the file as sedpack's ('SDPK'); Store::open refuses SQLite files without it.
PRAGMA application_id = 1396985931;

CREATE TABLE campaigns (
    id         INTEGER PRIMARY KEY,
    name       TEXT NOT NULL UNIQUE,
    spec       TEXT NOT NULL,            -- the campaign file as last submitted
    created_at REAL NOT NULL,
    updated_at REAL NOT NULL
) STRICT;

CREATE TABLE jobs (
    id           TEXT PRIMARY KEY,       -- stable hash of the resolved spec, computed by the caller
    campaign_id  INTEGER NOT NULL REFERENCES campaigns (id),
    spec         TEXT NOT NULL CHECK (json_valid(spec)),
    seed         INTEGER NOT NULL,
    parameters   TEXT NOT NULL CHECK (json_valid(parameters)),   -- grid key → value
    state        TEXT NOT NULL DEFAULT 'pending'
                 CHECK (state IN ('pending', 'running', 'done', 'failed')),
    attempts     INTEGER NOT NULL DEFAULT 0,                      -- times claimed
    worker_id    TEXT,                   -- who runs it, or ran it last
    heartbeat_at REAL,
    error        TEXT,
    created_at   REAL NOT NULL,
    started_at   REAL,                   -- of the current or last attempt
    finished_at  REAL,
    wall_time    REAL,                   -- finished_at - started_at of the last attempt
    CHECK (state <> 'running'
           OR (worker_id IS NOT NULL AND started_at IS NOT NULL AND heartbeat_at IS NOT NULL)),
    CHECK (state <> 'failed' OR error IS NOT NULL)
) STRICT;

CREATE INDEX jobs_by_campaign_state ON jobs (campaign_id, state);

CREATE TABLE results (
    job_id         TEXT PRIMARY KEY REFERENCES jobs (id),
    porosity       REAL NOT NULL,
    z_minus        REAL NOT NULL,        -- m, bottom of the averaged range
    z_plus         REAL NOT NULL,        -- m, top of the averaged range
    profile        TEXT NOT NULL CHECK (json_valid(profile)),     -- [{"z": slice centre, "n": porosity}]
    particles      INTEGER NOT NULL,
    simulated_time REAL NOT NULL,
    steps          INTEGER NOT NULL,
    wall_time      REAL NOT NULL,        -- as reported by the runner
    solver_version TEXT NOT NULL,
    created_at     REAL NOT NULL
) STRICT;

-- Number-based mean and std over the grains actually created, per form factor ("FL") or inverse ("inv_FL").
CREATE TABLE grain_statistics (
    job_id TEXT NOT NULL REFERENCES jobs (id),
    name   TEXT NOT NULL,
    mean   REAL NOT NULL,
    std    REAL NOT NULL,
    PRIMARY KEY (job_id, name)
) STRICT;

-- The solver state of a long packing, so a job resumes where it stopped.
CREATE TABLE checkpoints (
    job_id         TEXT PRIMARY KEY REFERENCES jobs (id),
    data           BLOB NOT NULL,
    simulated_time REAL NOT NULL,
    written_at     REAL NOT NULL
) STRICT;
