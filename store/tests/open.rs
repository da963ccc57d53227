//! Opening files: the schema of a new database, reopening, and refusing what is not sedpack's.

mod common;

use std::path::Path;

use common::*;
use sqlx::sqlite::SqliteConnectOptions;
use sqlx::{ConnectOptions, Connection, SqliteConnection};
use store::{JobState, Store, StoreError};

async fn raw(path: &Path) -> SqliteConnection {
    SqliteConnectOptions::new().filename(path).create_if_missing(true).connect().await.unwrap()
}

#[tokio::test]
async fn a_new_file_gets_the_schema_the_mark_and_wal() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    Store::open(&path).await.unwrap().close().await;

    let mut conn = raw(&path).await;
    let tables: Vec<String> = sqlx::query_scalar("SELECT name FROM sqlite_schema WHERE type = 'table' ORDER BY name")
        .fetch_all(&mut conn)
        .await
        .unwrap();
    assert_eq!(tables, ["_sqlx_migrations", "campaigns", "checkpoints", "grain_statistics", "jobs", "results"]);
    let application_id: i32 = sqlx::query_scalar("PRAGMA application_id").fetch_one(&mut conn).await.unwrap();
    assert_eq!(application_id.to_be_bytes(), *b"SDPK");
    let journal_mode: String = sqlx::query_scalar("PRAGMA journal_mode").fetch_one(&mut conn).await.unwrap();
    assert_eq!(journal_mode, "wal");

    // Every file of migrations/ is embedded and applied, under its number and name.
    let mut files: Vec<(i64, String)> = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/migrations"))
        .unwrap()
        .map(|entry| {
            let name = entry.unwrap().file_name().into_string().unwrap();
            let (version, description) = name.strip_suffix(".sql").unwrap().split_once('_').unwrap();
            (version.parse().unwrap(), description.replace('_', " "))
        })
        .collect();
    files.sort();
    let applied: Vec<(i64, String)> =
        sqlx::query_as("SELECT version, description FROM _sqlx_migrations WHERE success ORDER BY version")
            .fetch_all(&mut conn)
            .await
            .unwrap();
    assert_eq!(applied, files);

    // The schema's own constraints: foreign keys and the state check.
    let orphan = sqlx::query(
        "INSERT INTO jobs (id, campaign_id, spec, seed, parameters, created_at) VALUES ('x', 99, '{}', 1, '{}', 0)",
    )
    .execute(&mut conn)
    .await;
    assert!(orphan.unwrap_err().to_string().contains("FOREIGN KEY"));
    sqlx::query("INSERT INTO campaigns (name, spec, created_at, updated_at) VALUES ('c', '', 0, 0)")
        .execute(&mut conn)
        .await
        .unwrap();
    let bad_state = sqlx::query("INSERT INTO jobs (id, campaign_id, spec, seed, parameters, state, created_at) VALUES ('x', 1, '{}', 1, '{}', 'lost', 0)")
        .execute(&mut conn)
        .await;
    assert!(bad_state.unwrap_err().to_string().contains("CHECK"));
    let spread_alone = sqlx::query("INSERT INTO jobs (id, campaign_id, spec, seed, parameters, experiment_std, created_at) VALUES ('y', 1, '{}', 1, '{}', 0.01, 0)")
        .execute(&mut conn)
        .await;
    assert!(spread_alone.unwrap_err().to_string().contains("CHECK"), "a spread without its measurement");
    conn.close().await.unwrap();
}

#[tokio::test]
async fn reopening_keeps_the_data() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    let store = store_with_jobs(&path, 3).await;
    let job = store.claim(CAMPAIGN, "w1", None).await.unwrap().unwrap();
    store.complete(&job.id, "w1", &result(0.37), &statistics(0.6)).await.unwrap();
    let before = store.export(CAMPAIGN).await.unwrap();
    store.close().await;

    let store = Store::open(&path).await.unwrap();
    assert_eq!(store.export(CAMPAIGN).await.unwrap(), before);
    assert_eq!(before[0].state, JobState::Done);
    assert_eq!(store.add_jobs(CAMPAIGN, &jobs(0..3)).await.unwrap(), 0);
    let status = store.status(CAMPAIGN).await.unwrap();
    assert_eq!((status.jobs, status.done, status.pending), (3, 1, 2));
    store.close().await;
}

#[tokio::test]
async fn a_database_of_a_newer_sedpack_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    store_with_jobs(&path, 2).await.close().await;
    // A later sedpack's migration, as sqlx records one.
    let mut conn = raw(&path).await;
    sqlx::query(
        "INSERT INTO _sqlx_migrations (version, description, success, checksum, execution_time) \
         VALUES (9999, 'from the future', TRUE, x'00', 0)",
    )
    .execute(&mut conn)
    .await
    .unwrap();
    conn.close().await.unwrap();
    for _ in 0..2 {
        let error = Store::open(&path).await.unwrap_err();
        assert!(matches!(error, StoreError::Newer { applied: 9999, .. }), "{error:?}");
        let text = error.to_string();
        assert!(text.contains("written by a newer sedpack") && text.contains("migration 9999"), "{text}");
    }
    // What it held is still there: the refusal wrote nothing.
    let mut conn = raw(&path).await;
    let jobs: i64 = sqlx::query_scalar("SELECT COUNT(*) FROM jobs").fetch_one(&mut conn).await.unwrap();
    let migrations: i64 =
        sqlx::query_scalar("SELECT COUNT(*) FROM _sqlx_migrations").fetch_one(&mut conn).await.unwrap();
    let files = std::fs::read_dir(concat!(env!("CARGO_MANIFEST_DIR"), "/migrations")).unwrap().count() as i64;
    assert_eq!((jobs, migrations), (2, files + 1));
    conn.close().await.unwrap();
}

#[tokio::test]
async fn an_existing_empty_file_becomes_a_database() {
    let dir = tempfile::tempdir().unwrap();
    let path = db_path(&dir);
    std::fs::write(&path, b"").unwrap();
    let store = store_with_jobs(&path, 2).await;
    assert_eq!(store.status(CAMPAIGN).await.unwrap().pending, 2);
    store.close().await;
}

/// Opens `path`, expects a refusal naming the file, and checks that nothing was changed or added.
async fn assert_refused(path: &Path) -> StoreError {
    let bytes = std::fs::read(path).unwrap();
    let siblings = std::fs::read_dir(path.parent().unwrap()).unwrap().count();
    let error = Store::open(path).await.unwrap_err();
    assert!(error.to_string().contains(&path.display().to_string()), "{error}");
    assert_eq!(std::fs::read(path).unwrap(), bytes, "the refused file was modified");
    assert_eq!(std::fs::read_dir(path.parent().unwrap()).unwrap().count(), siblings, "files were added beside it");
    error
}

#[tokio::test]
async fn random_bytes_are_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("random.db");
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let bytes: Vec<u8> = (0..8192)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state as u8
        })
        .collect();
    std::fs::write(&path, &bytes).unwrap();
    assert!(matches!(assert_refused(&path).await, StoreError::NotSqlite { .. }));
}

#[tokio::test]
async fn a_sqlite_header_over_garbage_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("corrupt.db");
    let mut bytes = b"SQLite format 3\0".to_vec();
    bytes.extend((0..4080).map(|i| (i * 7 % 251) as u8));
    std::fs::write(&path, &bytes).unwrap();
    let error = assert_refused(&path).await;
    assert!(matches!(error, StoreError::NotSqlite { .. }), "{error:?}");
}

#[tokio::test]
async fn a_foreign_sqlite_database_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("notes.db");
    let mut conn = raw(&path).await;
    sqlx::query("CREATE TABLE notes (id INTEGER PRIMARY KEY, text TEXT)").execute(&mut conn).await.unwrap();
    sqlx::query("INSERT INTO notes (text) VALUES ('keep me')").execute(&mut conn).await.unwrap();
    conn.close().await.unwrap();

    let error = assert_refused(&path).await;
    assert!(matches!(error, StoreError::Foreign { .. }), "{error:?}");
    assert!(error.to_string().contains("notes"), "{error}");
}

#[tokio::test]
async fn a_database_marked_by_another_application_is_refused_untouched() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("other.db");
    let mut conn = raw(&path).await;
    sqlx::query("PRAGMA application_id = 42").execute(&mut conn).await.unwrap();
    conn.close().await.unwrap();

    let error = assert_refused(&path).await;
    assert!(matches!(error, StoreError::Foreign { .. }), "{error:?}");
    assert!(error.to_string().contains("0x2a"), "{error}");
}
