//! A storage whose every call fails, for the answers a service gives
//! without its database.

use async_trait::async_trait;
use vitrine::storage::{
    ModelRecord, ModelSummary, NewModel, NewToken, Result, StagedModel, Storage, StorageError,
    TexturePayload, TokenGrant,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Failure {
    /// The database cannot be reached (503 `database_unavailable`).
    Unavailable,
    /// Stored rows break an invariant (500 `internal`).
    Corrupt,
}

pub struct BrokenStorage(pub Failure);

impl BrokenStorage {
    fn fail<T>(&self) -> Result<T> {
        Err(match self.0 {
            Failure::Unavailable => StorageError::Unavailable(sqlx::Error::PoolTimedOut),
            Failure::Corrupt => StorageError::Corrupt("broken on purpose".into()),
        })
    }
}

#[async_trait]
impl vitrine::storage::StudyStorage for BrokenStorage {}
impl vitrine::storage::CuratorStorage for BrokenStorage {}
impl vitrine::storage::TourStorage for BrokenStorage {}
impl vitrine::storage::TextStorage for BrokenStorage {}

#[async_trait]
impl Storage for BrokenStorage {
    fn backend(&self) -> &'static str {
        "broken"
    }
    async fn migrate(&self) -> Result<()> {
        self.fail()
    }
    async fn ping(&self) -> Result<()> {
        self.fail()
    }
    async fn list_models(&self) -> Result<Vec<ModelSummary>> {
        self.fail()
    }
    async fn model_by_slug(&self, _: &str) -> Result<Option<ModelRecord>> {
        self.fail()
    }
    async fn model_by_compression(&self, _: i64) -> Result<Option<ModelRecord>> {
        self.fail()
    }
    async fn base_payload(&self, _: i64) -> Result<Option<Vec<u8>>> {
        self.fail()
    }
    async fn batch_payload(&self, _: i64, _: u32) -> Result<Option<Vec<u8>>> {
        self.fail()
    }
    async fn texture(&self, _: i64) -> Result<Option<TexturePayload>> {
        self.fail()
    }
    async fn token_grant(&self, _: &str, _: i64) -> Result<Option<TokenGrant>> {
        self.fail()
    }
    async fn insert_token(&self, _: &NewToken) -> Result<i64> {
        self.fail()
    }
    async fn stage_model(&self, _: &NewModel) -> Result<Box<dyn StagedModel>> {
        self.fail()
    }
}
