//! A storage decorator that makes payload reads slow.

use async_trait::async_trait;
use std::sync::Arc;
use std::time::Duration;
use tokio::sync::Notify;
use vitrine::storage::{
    ModelRecord, ModelSummary, NewModel, NewToken, Result, StagedModel, Storage, TexturePayload,
    TokenGrant,
};

/// Storage whose payload reads take `delay`: concurrent batch requests then
/// pile up in flight as they would behind a slow disk.
pub struct SlowStorage {
    inner: Arc<dyn Storage>,
    delay: Duration,
    /// Told each time a payload read begins: a request is then in flight.
    reached: Notify,
}

impl SlowStorage {
    pub fn new(inner: Arc<dyn Storage>, delay: Duration) -> Arc<SlowStorage> {
        Arc::new(SlowStorage {
            inner,
            delay,
            reached: Notify::new(),
        })
    }

    /// Returns once a payload read has begun (at once if one began since
    /// the last call).
    pub async fn reached(&self) {
        self.reached.notified().await;
    }

    async fn payload_read(&self) {
        self.reached.notify_one();
        tokio::time::sleep(self.delay).await;
    }
}

#[async_trait]
impl vitrine::storage::StudyStorage for SlowStorage {}
impl vitrine::storage::CuratorStorage for SlowStorage {}
impl vitrine::storage::TourStorage for SlowStorage {}
impl vitrine::storage::TextStorage for SlowStorage {}

#[async_trait]
impl Storage for SlowStorage {
    fn backend(&self) -> &'static str {
        self.inner.backend()
    }
    async fn migrate(&self) -> Result<()> {
        self.inner.migrate().await
    }
    async fn ping(&self) -> Result<()> {
        self.inner.ping().await
    }
    async fn list_models(&self) -> Result<Vec<ModelSummary>> {
        self.inner.list_models().await
    }
    async fn model_by_slug(&self, slug: &str) -> Result<Option<ModelRecord>> {
        self.inner.model_by_slug(slug).await
    }
    async fn model_by_compression(&self, id: i64) -> Result<Option<ModelRecord>> {
        self.inner.model_by_compression(id).await
    }
    async fn base_payload(&self, id: i64) -> Result<Option<Vec<u8>>> {
        self.payload_read().await;
        self.inner.base_payload(id).await
    }
    async fn batch_payload(&self, id: i64, iteration: u32) -> Result<Option<Vec<u8>>> {
        self.payload_read().await;
        self.inner.batch_payload(id, iteration).await
    }
    async fn texture(&self, id: i64) -> Result<Option<TexturePayload>> {
        self.inner.texture(id).await
    }
    async fn token_grant(&self, sha256: &str, now_ms: i64) -> Result<Option<TokenGrant>> {
        self.inner.token_grant(sha256, now_ms).await
    }
    async fn insert_token(&self, token: &NewToken) -> Result<i64> {
        self.inner.insert_token(token).await
    }
    async fn stage_model(&self, model: &NewModel) -> Result<Box<dyn StagedModel>> {
        self.inner.stage_model(model).await
    }
}
