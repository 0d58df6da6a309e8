//! Where models, compressions, refinement batches, policies and tokens live.
//!
//! One [`Storage`] trait, two backends chosen by URL at start-up (atuin's
//! design): SQLite, the embedded default (`sqlite:vitrine.db`, a file created
//! on first run, WAL mode), and PostgreSQL (`postgres://…`) for several servers
//! sharing one database. Both run the same SQL (`sql.rs`); they differ in how
//! they connect, migrate and classify errors.

mod backend;
mod curator;
mod postgres;
mod sql;
mod sqlite;
mod stage;
mod study;
mod texts;
mod tours;
mod types;

pub use curator::CuratorStorage;
pub use postgres::PostgresStorage;
pub use sqlite::SqliteStorage;
pub use study::{
    for_analysis, AnswerRecord, InvitationRecord, NewSession, SessionRecord, StudyRecord,
    StudyStorage, ViewEvent,
};
pub use texts::{
    Localized, ModelTexts, Picked, TextField, TextStorage, Translation, Translations, VersionTexts,
};
pub use tours::{LanguageMap, NewTour, TourRecord, TourStep, TourStorage};
pub use types::*;

use async_trait::async_trait;
use sha2::{Digest, Sha256};
use std::sync::Arc;
use std::time::Duration;

pub type Result<T, E = StorageError> = std::result::Result<T, E>;

/// What went wrong, grouped by what the caller should do about it.
#[derive(Debug, thiserror::Error)]
pub enum StorageError {
    /// The database cannot be reached or is busy: retry later (HTTP 503).
    #[error("database unavailable: {0}")]
    Unavailable(#[source] sqlx::Error),
    /// The write contradicts what is stored (slug taken, concurrent ingest).
    #[error("{0}")]
    Conflict(String),
    /// The write names something that does not exist (an unknown policy).
    #[error("{0}")]
    Unknown(String),
    /// Stored rows break an invariant the schema cannot express.
    #[error("stored data is inconsistent: {0}")]
    Corrupt(String),
    #[error("database error: {0}")]
    Database(#[source] sqlx::Error),
    #[error("migration failed: {0}")]
    Migrate(#[from] sqlx::migrate::MigrateError),
    #[error("bad database URL: {0}")]
    Url(String),
}

impl StorageError {
    pub fn is_unavailable(&self) -> bool {
        match self {
            StorageError::Unavailable(_) => true,
            StorageError::Migrate(sqlx::migrate::MigrateError::Execute(e)) => {
                is_connection_error(e)
            }
            _ => false,
        }
    }
}

/// Errors that say nothing about the query, only that the database is not there.
pub(crate) fn is_connection_error(e: &sqlx::Error) -> bool {
    matches!(
        e,
        sqlx::Error::Io(_)
            | sqlx::Error::Tls(_)
            | sqlx::Error::Protocol(_)
            | sqlx::Error::PoolTimedOut
            | sqlx::Error::PoolClosed
            | sqlx::Error::WorkerCrashed
    )
}

/// The one interface the service and the ingest command use.
#[async_trait]
pub trait Storage:
    StudyStorage + CuratorStorage + TourStorage + TextStorage + Send + Sync + 'static
{
    /// Which backend, for logs and metrics: `"sqlite"` or `"postgres"`.
    fn backend(&self) -> &'static str;

    /// Applies the embedded migrations.
    async fn migrate(&self) -> Result<()>;

    /// A trivial round trip, for `/readyz`.
    async fn ping(&self) -> Result<()>;

    /// The change counter (`change_generation`): bumped by every committed
    /// change to model versions, policies or tokens, whoever made it. A
    /// storage without one (a test double) never changes behind our back.
    async fn change_generation(&self) -> Result<i64> {
        Ok(0)
    }

    /// The visible version of every model, by slug.
    async fn list_models(&self) -> Result<Vec<ModelSummary>>;

    /// The models whose visible version has parts measured before their bulk
    /// error was: viewers refine those by the largest error (ingest again).
    /// Reads every part row: for `vitrine models`, not the visitors' list.
    async fn slugs_with_unmeasured_parts(&self) -> Result<Vec<String>> {
        Ok(Vec::new())
    }

    /// The visible version of `slug` with its newest compression.
    async fn model_by_slug(&self, slug: &str) -> Result<Option<ModelRecord>>;

    /// The model version a compression belongs to, if that version is visible.
    async fn model_by_compression(&self, compression_id: i64) -> Result<Option<ModelRecord>>;

    /// Stream header plus base mesh chunk.
    async fn base_payload(&self, compression_id: i64) -> Result<Option<Vec<u8>>>;

    /// Refinement batch `iteration` (1-based).
    async fn batch_payload(&self, compression_id: i64, iteration: u32) -> Result<Option<Vec<u8>>>;

    /// A charted stream's parts, batch by batch and chart by chart; empty
    /// for a plain stream or one ingested before parts were recorded.
    async fn parts(&self, compression_id: i64) -> Result<Vec<PartRecord>> {
        let _ = compression_id;
        Ok(Vec::new())
    }

    /// A nested stream's split entries, batch by batch and parent by
    /// parent; empty for any other stream.
    async fn splits(&self, compression_id: i64) -> Result<Vec<SplitRecord>> {
        let _ = compression_id;
        Ok(Vec::new())
    }

    async fn texture(&self, texture_id: i64) -> Result<Option<TexturePayload>>;

    /// The live (not revoked, not expired) token with this digest.
    async fn token_grant(&self, token_sha256: &str, now_ms: i64) -> Result<Option<TokenGrant>>;

    /// Stores a token digest; returns the token's row id.
    async fn insert_token(&self, token: &NewToken) -> Result<i64>;

    /// Writes a whole model version inside one transaction and returns it
    /// uncommitted: nothing is visible until [`StagedModel::commit`].
    async fn stage_model(&self, model: &NewModel) -> Result<Box<dyn StagedModel>>;
}

/// A model version written inside an open transaction. Dropping it rolls back.
#[async_trait]
pub trait StagedModel: Send {
    fn stored(&self) -> &StoredModel;
    async fn commit(self: Box<Self>) -> Result<StoredModel>;
}

/// Connection settings shared by both backends.
#[derive(Clone, Debug)]
pub struct ConnectOptions {
    pub max_connections: u32,
    /// How long a query waits for a connection (or, on SQLite, a lock) before
    /// the request fails with 503.
    pub acquire_timeout: Duration,
    /// Connections are reopened after this long, so a database file that was
    /// replaced or a server that failed over is picked up.
    pub max_lifetime: Duration,
}

impl Default for ConnectOptions {
    fn default() -> Self {
        ConnectOptions {
            max_connections: 16,
            acquire_timeout: Duration::from_secs(3),
            max_lifetime: Duration::from_secs(30 * 60),
        }
    }
}

/// Opens the backend the URL names: `postgres://` / `postgresql://`, or
/// `sqlite:` (a bare path is taken as a SQLite file). Does not touch the
/// database yet: call [`Storage::migrate`] next.
pub fn connect(url: &str, options: &ConnectOptions) -> Result<Arc<dyn Storage>> {
    if url.starts_with("postgres://") || url.starts_with("postgresql://") {
        Ok(Arc::new(PostgresStorage::connect_lazy(url, options)?))
    } else if url.starts_with("sqlite:") {
        Ok(Arc::new(SqliteStorage::open(url, options)?))
    } else if url.contains("://") {
        Err(StorageError::Url(format!(
            "unsupported scheme in {url:?} (use sqlite: or postgres://)"
        )))
    } else {
        Ok(Arc::new(SqliteStorage::open(
            &format!("sqlite:{url}"),
            options,
        )?))
    }
}

/// Lowercase hex SHA-256: payload digests (strong ETags) and token digests.
pub fn sha256_hex(bytes: &[u8]) -> String {
    hex::encode(Sha256::digest(bytes))
}

pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_millis() as i64)
        .unwrap_or(0)
}
