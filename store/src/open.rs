//! Opening a database file: refuse anything that is not sedpack's, then create or update the schema.

use std::fs::File;
use std::io::{ErrorKind, Read};
use std::path::Path;
use std::time::{Duration, Instant};

use sqlx::migrate::{MigrateError, Migration, MigrationType, Migrator};
use sqlx::sqlite::{SqliteConnectOptions, SqliteConnection};
use sqlx::{ConnectOptions, Connection, SqlStr};

use crate::{StoreError, sql};

/// 'SDPK', written into the file header by migrations/0001_schema.sql.
const APPLICATION_ID: i32 = 0x5344_504B;
const MIGRATIONS_TABLE: &str = "_sqlx_migrations";
const SQLITE_HEADER: &[u8] = b"SQLite format 3\0";
const SQLITE_BUSY: i32 = 5;
const SQLITE_CORRUPT: i32 = 11;
const SQLITE_NOTADB: i32 = 26;

/// The numbered files of migrations/, embedded in the binary; list each new file here.
fn migrator() -> Migrator {
    let migration = |version, description: &'static str, sql| {
        let sql = SqlStr::from_static(sql);
        Migration::new(version, description.into(), MigrationType::Simple, sql, false)
    };
    Migrator::with_migrations(vec![
        migration(1, "schema", include_str!("../migrations/0001_schema.sql")),
        migration(2, "job format and experiment", include_str!("../migrations/0002_job_format_and_experiment.sql")),
        migration(3, "executor", include_str!("../migrations/0003_executor.sql")),
        migration(4, "fluid and imbrication", include_str!("../migrations/0004_fluid_and_imbrication.sql")),
        migration(5, "checkpoint stage", include_str!("../migrations/0005_checkpoint_stage.sql")),
        migration(6, "checkpoint shaking until", include_str!("../migrations/0006_checkpoint_shaking_until.sql")),
        migration(7, "result size classes", include_str!("../migrations/0007_result_size_classes.sql")),
    ])
}

/// Makes `path` an up-to-date sedpack database in WAL mode, creating it if missing.
/// A file that is not SQLite, or is another application's SQLite database, is refused unchanged.
pub(crate) async fn prepare(
    path: &Path,
    options: &SqliteConnectOptions,
    busy_timeout: Duration,
) -> Result<(), StoreError> {
    check_header(path)?;
    let mut conn = options.clone().create_if_missing(true).connect().await.map_err(|e| refused_or_database(path, e))?;
    let set_up = set_up(&mut conn, path, busy_timeout).await;
    let closed = conn.close().await.map_err(|e| refused_or_database(path, e));
    set_up.and(closed)
}

fn check_header(path: &Path) -> Result<(), StoreError> {
    let io = |source| StoreError::Io { path: path.to_path_buf(), source };
    let mut header = Vec::new();
    match File::open(path) {
        Err(e) if e.kind() == ErrorKind::NotFound => return Ok(()),
        Err(e) => return Err(io(e)),
        Ok(file) => file.take(SQLITE_HEADER.len() as u64).read_to_end(&mut header).map_err(io)?,
    };
    // SQLite takes an empty file for an empty database.
    if header.is_empty() || header == SQLITE_HEADER {
        Ok(())
    } else {
        Err(StoreError::NotSqlite { path: path.to_path_buf() })
    }
}

async fn set_up(conn: &mut SqliteConnection, path: &Path, busy_timeout: Duration) -> Result<(), StoreError> {
    // Holding the write lock throughout, two processes opening a new file set it up one at a time.
    let mut tx = conn.begin_with(sql::BEGIN_IMMEDIATE).await.map_err(|e| refused_or_database(path, e))?;
    check_ours_or_empty(&mut tx, path).await?;
    // run_direct rather than run: run's Acquire bound makes the future not Send (sqlx's own advice).
    let migrator = migrator();
    let known = migrator.iter().map(|m| m.version).max().unwrap_or(0);
    // A migration this sedpack does not have is refused before any is applied.
    migrator.run_direct(None, &mut *tx, false).await.map_err(|source| match source {
        MigrateError::VersionMissing(applied) => StoreError::Newer { path: path.to_path_buf(), applied, known },
        source => StoreError::Migrate { path: path.to_path_buf(), source },
    })?;
    tx.commit().await.map_err(|e| refused_or_database(path, e))?;
    enter_wal(conn, path, busy_timeout).await
}

async fn check_ours_or_empty(conn: &mut SqliteConnection, path: &Path) -> Result<(), StoreError> {
    let id: i32 = sqlx::query_scalar(sql::APPLICATION_ID)
        .fetch_one(&mut *conn)
        .await
        .map_err(|e| refused_or_database(path, e))?;
    let tables: Vec<String> =
        sqlx::query_scalar(sql::USER_TABLES).fetch_all(&mut *conn).await.map_err(|e| refused_or_database(path, e))?;
    let ours = id == APPLICATION_ID && tables.iter().any(|table| table == MIGRATIONS_TABLE);
    let empty = id == 0 && tables.is_empty();
    if ours || empty {
        return Ok(());
    }
    Err(StoreError::Foreign {
        path: path.to_path_buf(),
        detail: format!("application_id {id:#x}, tables [{}]", tables.join(", ")),
    })
}

/// WAL lets readers work beside the one writer. Entering it takes an exclusive lock that SQLite's
/// busy timeout does not wait for, so a busy answer is retried until the timeout.
async fn enter_wal(conn: &mut SqliteConnection, path: &Path, busy_timeout: Duration) -> Result<(), StoreError> {
    let deadline = Instant::now() + busy_timeout;
    loop {
        let mode = sqlx::query_scalar::<_, String>(sql::JOURNAL_MODE_WAL).fetch_one(&mut *conn).await;
        let retry = Instant::now() < deadline;
        match mode {
            Ok(mode) if mode == "wal" => return Ok(()),
            Err(e) if !(retry && primary_code(&e) == Some(SQLITE_BUSY)) => {
                return Err(refused_or_database(path, e));
            }
            Ok(mode) if !retry => {
                return Err(StoreError::Invalid {
                    path: path.to_path_buf(),
                    detail: format!("SQLite cannot switch the file to WAL mode (it stays {mode})"),
                });
            }
            _ => tokio::time::sleep(Duration::from_millis(20)).await,
        }
    }
}

fn primary_code(error: &sqlx::Error) -> Option<i32> {
    let code = error.as_database_error()?.code()?.parse::<i32>().ok()?;
    Some(code & 0xff)
}

/// SQLite's "corrupt" and "not a database" mean the file is refused; anything else is reported as is.
fn refused_or_database(path: &Path, source: sqlx::Error) -> StoreError {
    match primary_code(&source) {
        Some(SQLITE_CORRUPT | SQLITE_NOTADB) => StoreError::NotSqlite { path: path.to_path_buf() },
        _ => StoreError::Database { path: path.to_path_buf(), source },
    }
}
