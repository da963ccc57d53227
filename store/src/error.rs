use std::path::PathBuf;

/// What went wrong, always naming the database file.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("{}: cannot read the file: {source}", .path.display())]
    Io { path: PathBuf, source: std::io::Error },

    #[error(
        "{}: not a SQLite database, or a corrupt one; sedpack refuses it and left it unchanged \
         (choose another file with --db)",
        .path.display()
    )]
    NotSqlite { path: PathBuf },

    #[error(
        "{}: a SQLite database of another application ({detail}); sedpack refuses it and left it \
         unchanged (choose another file with --db)",
        .path.display()
    )]
    Foreign { path: PathBuf, detail: String },

    #[error("{}: setting up the schema failed: {source}", .path.display())]
    Migrate { path: PathBuf, source: sqlx::migrate::MigrateError },

    #[error(
        "{}: written by a newer sedpack (its schema has migration {applied}, this sedpack knows \
         migrations up to {known}); open it with the sedpack that wrote it, or choose another file \
         with --db; it was left unchanged",
        .path.display()
    )]
    Newer { path: PathBuf, applied: i64, known: i64 },

    #[error("{}: {source}", .path.display())]
    Database { path: PathBuf, source: sqlx::Error },

    #[error("{}: no campaign named {name:?}", .path.display())]
    NoCampaign { path: PathBuf, name: String },

    #[error(
        "{}: job {job_id} is no longer running for worker {worker_id:?} (it was requeued or \
         finished elsewhere); nothing was written",
        .path.display()
    )]
    NotOwner { path: PathBuf, job_id: String, worker_id: String },

    #[error("{}: {detail}", .path.display())]
    Invalid { path: PathBuf, detail: String },
}
