//! The shared backend: PostgreSQL, for several servers on one database.

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
use sqlx::postgres::{PgConnectOptions, PgPoolOptions};
use sqlx::{PgPool, Postgres, Transaction};
use std::str::FromStr;

static MIGRATOR: sqlx::migrate::Migrator = sqlx::migrate!("../migrations/postgres");

#[derive(Clone, Debug)]
pub struct PostgresStorage {
    pool: PgPool,
}

impl PostgresStorage {
    /// Builds the pool without connecting: the database may come up later.
    pub fn connect_lazy(url: &str, options: &ConnectOptions) -> super::Result<Self> {
        let connect = PgConnectOptions::from_str(url)
            .map_err(|e| StorageError::Url(e.to_string()))?
            .application_name("vitrine");
        let pool = PgPoolOptions::new()
            .max_connections(options.max_connections)
            .acquire_timeout(options.acquire_timeout)
            .max_lifetime(options.max_lifetime)
            .connect_lazy_with(connect);
        Ok(PostgresStorage { pool })
    }

    pub fn pool(&self) -> &PgPool {
        &self.pool
    }

    async fn prepare(&self) -> super::Result<()> {
        Ok(())
    }

    async fn begin_write(&self) -> super::Result<Transaction<'static, Postgres>> {
        self.pool.begin().await.map_err(Self::classify)
    }

    fn classify(e: sqlx::Error) -> StorageError {
        let unavailable = is_connection_error(&e)
            || match &e {
                // Class 08 connection exception, 53 insufficient resources,
                // 57P0x shutdown / cannot connect now, 3D000 no such database.
                sqlx::Error::Database(d) => d.code().is_some_and(|c| {
                    c.starts_with("08")
                        || c.starts_with("53")
                        || c.starts_with("57P")
                        || c == "3D000"
                }),
                _ => false,
            };
        if unavailable {
            StorageError::Unavailable(e)
        } else {
            StorageError::Database(e)
        }
    }
}

sql_storage!(PostgresStorage, Postgres, "postgres", MIGRATOR);
study_storage!(PostgresStorage, Postgres);
curator_storage!(PostgresStorage, Postgres);
tour_storage!(PostgresStorage, Postgres);
text_storage!(PostgresStorage, Postgres);
