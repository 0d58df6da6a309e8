//! The embedded backend: one SQLite file in WAL mode, created on first run.

use super::backend::sql_storage;
use super::curator::curator_storage;
use super::study::study_storage;
use super::texts::text_storage;
use super::tours::tour_storage;
use super::{
    is_connection_error, AudiencePolicy, Bounds, ConnectOptions, Curation, LevelRecord,
    MappingRecord, ModelKind, ModelRecord, ModelSummary, NewModel, NewToken, PartRecord,
    SplitRecord, StagedModel, Storage, StorageError, TexturePayload, TextureRef, TokenGrant,
    TokenScope, UpAxis,
};
use sqlx::sqlite::{SqliteConnectOptions, SqliteJournalMode, SqlitePoolOptions, SqliteSynchronous};
use sqlx::{Sqlite, SqlitePool, Transaction};
use std::str::FromStr;

static MIGRATOR: sqlx::migrate::Migrator = sqlx::migrate!("../migrations/sqlite");

#[derive(Clone, Debug)]
pub struct SqliteStorage {
    pool: SqlitePool,
    /// For creating the file: pool connections never do, so a database file
    /// that disappears gives errors (503) rather than an empty new database.
    create: SqliteConnectOptions,
}

impl SqliteStorage {
    /// Opens (lazily) the file named by a `sqlite:` URL, creating it if missing.
    pub fn open(url: &str, options: &ConnectOptions) -> super::Result<Self> {
        let connect = SqliteConnectOptions::from_str(url)
            .map_err(|e| StorageError::Url(e.to_string()))?
            .journal_mode(SqliteJournalMode::Wal)
            // WAL + NORMAL is durable across application crashes; only an OS
            // crash can lose the last commits, which an ingest can redo.
            .synchronous(SqliteSynchronous::Normal)
            .foreign_keys(true)
            .busy_timeout(options.acquire_timeout);
        let pool = SqlitePoolOptions::new()
            .max_connections(options.max_connections)
            .acquire_timeout(options.acquire_timeout)
            .max_lifetime(options.max_lifetime)
            .connect_lazy_with(connect.clone());
        Ok(SqliteStorage {
            pool,
            create: connect.create_if_missing(true),
        })
    }

    /// Creates the file (in WAL mode) if it is missing; run before migrating.
    async fn prepare(&self) -> super::Result<()> {
        use sqlx::{ConnectOptions as _, Connection as _};
        let conn = self.create.connect().await.map_err(Self::classify)?;
        conn.close().await.map_err(Self::classify)
    }

    pub fn pool(&self) -> &SqlitePool {
        &self.pool
    }

    /// `BEGIN IMMEDIATE` takes the write lock up front, so an ingest waits for
    /// another writer (busy timeout) instead of failing when it upgrades.
    async fn begin_write(&self) -> super::Result<Transaction<'static, Sqlite>> {
        self.pool
            .begin_with("BEGIN IMMEDIATE")
            .await
            .map_err(Self::classify)
    }

    fn classify(e: sqlx::Error) -> StorageError {
        let unavailable = is_connection_error(&e)
            || match &e {
                // SQLITE_BUSY, SQLITE_LOCKED, SQLITE_IOERR, SQLITE_CANTOPEN, SQLITE_FULL
                // (primary code in the low byte of the extended code).
                sqlx::Error::Database(d) => d
                    .code()
                    .and_then(|c| c.parse::<i32>().ok())
                    .is_some_and(|c| matches!(c & 0xff, 5 | 6 | 10 | 13 | 14)),
                _ => false,
            };
        if unavailable {
            StorageError::Unavailable(e)
        } else {
            StorageError::Database(e)
        }
    }
}

sql_storage!(SqliteStorage, Sqlite, "sqlite", MIGRATOR);
study_storage!(SqliteStorage, Sqlite);
curator_storage!(SqliteStorage, Sqlite);
tour_storage!(SqliteStorage, Sqlite);
text_storage!(SqliteStorage, Sqlite);
