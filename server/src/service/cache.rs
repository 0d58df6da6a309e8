//! In-memory caches, so a crowd on one model does not hit the database per request.
//!
//! Payloads (immutable: base meshes and batches) sit in a cache bounded by a
//! byte budget, a charted stream's part and split rows (as immutable) in
//! one bounded by rows. Model records, token grants and the model list (which carry
//! policies, so they may change) expire after a TTL. Concurrent misses on one
//! key share a single database read (moka's `entry().or_try_insert_with`).

use super::metrics::Metrics;
use crate::storage::{
    ModelRecord, ModelSummary, PartRecord, SplitRecord, StorageError, TokenGrant,
};
use bytes::Bytes;
use moka::future::Cache;
use std::future::Future;
use std::hash::Hash;
use std::sync::Arc;
use std::time::Duration;

/// Which payload of a compression.
#[derive(Clone, Copy, Debug, Hash, PartialEq, Eq)]
pub enum PayloadKey {
    Base(i64),
    Batch(i64, u32),
    Texture(i64),
}

/// A texture and who may see it.
#[derive(Clone, Debug)]
pub struct TextureEntry {
    pub bytes: Bytes,
    pub media_type: String,
    pub sha256: String,
    pub model_slug: String,
    pub public_access: bool,
}

#[derive(Clone, Debug)]
pub enum Payload {
    Mesh(Bytes),
    /// `None`: no such texture (remembered, so probing ids costs no queries).
    Texture(Option<Arc<TextureEntry>>),
}

impl Payload {
    fn weight(&self) -> u32 {
        let len = match self {
            Payload::Mesh(b) => b.len(),
            Payload::Texture(Some(t)) => t.bytes.len(),
            Payload::Texture(None) => 64,
        };
        u32::try_from(len).unwrap_or(u32::MAX)
    }
}

/// A charted or nested stream's part and split rows, as stored at ingest:
/// every part request of a nested stream reads them (the layout of a batch
/// needs the one before's phase and chart count), so a close-up crowd would
/// otherwise query them once per part.
#[derive(Debug, Default)]
pub struct PartRows {
    pub parts: Vec<PartRecord>,
    pub splits: Vec<SplitRecord>,
    /// Each parted batch's phase and chart count, by batch: what slicing
    /// the batch after it needs, looked up per part request.
    batches: std::collections::BTreeMap<u32, (usize, usize)>,
    /// The index as served (`parts::index`): its JSON and compressed
    /// copies, each made on first use.
    pub index: super::precompressed::Precompressed,
}

impl PartRows {
    pub fn new(parts: Vec<PartRecord>, splits: Vec<SplitRecord>) -> PartRows {
        let mut batches = std::collections::BTreeMap::new();
        for p in &parts {
            batches
                .entry(p.iteration)
                .or_insert((p.phase as usize, 0))
                .1 += 1;
        }
        PartRows {
            parts,
            splits,
            batches,
            index: Default::default(),
        }
    }

    /// Batch `iteration`'s phase and chart count; `None` for a batch
    /// without parts.
    pub fn batch(&self, iteration: u32) -> Option<(usize, usize)> {
        self.batches.get(&iteration).copied()
    }

    fn weight(&self) -> u32 {
        u32::try_from(self.parts.len() + self.splits.len() + 1).unwrap_or(u32::MAX)
    }
}

/// Rows of [`PartRows`] kept, all streams together: a 20 M-vertex nested
/// stream has some 20,000.
const MAX_PART_ROWS: u64 = 2_000_000;

/// Sizes and lifetimes.
#[derive(Clone, Debug, PartialEq)]
pub struct CacheConfig {
    /// Byte budget of the payload cache; 0 turns it off.
    pub payload_bytes: u64,
    /// How long model records, token grants and the model list are trusted.
    pub record_ttl: Duration,
    pub max_records: u64,
}

impl Default for CacheConfig {
    fn default() -> Self {
        CacheConfig {
            payload_bytes: 256 << 20,
            record_ttl: Duration::from_secs(10),
            max_records: 10_000,
        }
    }
}

pub struct Caches {
    payloads: Option<Cache<PayloadKey, Payload>>,
    pub(super) by_slug: Cache<String, Option<Arc<ModelRecord>>>,
    pub(super) by_compression: Cache<i64, Option<Arc<ModelRecord>>>,
    pub(super) tokens: Cache<String, Option<TokenGrant>>,
    pub(super) list: Cache<(), Arc<Vec<ModelSummary>>>,
    /// By compression id; never stale (a compression's rows never change).
    pub(super) part_rows: Cache<i64, Arc<PartRows>>,
}

impl Caches {
    pub fn new(config: &CacheConfig) -> Caches {
        fn records<K, V>(n: u64, ttl: Duration) -> Cache<K, V>
        where
            K: Hash + Eq + Send + Sync + 'static,
            V: Clone + Send + Sync + 'static,
        {
            Cache::builder().max_capacity(n).time_to_live(ttl).build()
        }
        let ttl = config.record_ttl;
        Caches {
            payloads: (config.payload_bytes > 0).then(|| {
                Cache::builder()
                    .max_capacity(config.payload_bytes)
                    .weigher(|_: &PayloadKey, p: &Payload| p.weight())
                    .build()
            }),
            by_slug: records(config.max_records, ttl),
            by_compression: records(config.max_records, ttl),
            tokens: records(config.max_records, ttl),
            list: records(1, ttl),
            part_rows: Cache::builder()
                .max_capacity(MAX_PART_ROWS)
                .weigher(|_: &i64, rows: &Arc<PartRows>| rows.weight())
                .build(),
        }
    }

    /// Forgets records, grants and the list (payloads are immutable and stay).
    pub fn invalidate(&self) {
        self.by_slug.invalidate_all();
        self.by_compression.invalidate_all();
        self.tokens.invalidate_all();
        self.list.invalidate_all();
    }

    pub fn payload_bytes(&self) -> u64 {
        self.payloads.as_ref().map_or(0, |c| c.weighted_size())
    }

    pub async fn payload<F>(
        &self,
        metrics: &Metrics,
        key: PayloadKey,
        load: F,
    ) -> Result<Payload, Arc<StorageError>>
    where
        F: Future<Output = Result<Payload, StorageError>>,
    {
        match &self.payloads {
            Some(cache) => through(cache, metrics, "payload", key, load).await,
            None => {
                metrics.cache_lookup("payload", false);
                load.await.map_err(Arc::new)
            }
        }
    }

    /// `key`'s payload if the cache holds it now: never waits, never loads
    /// (the fast path's read, [`super::fast_payload`]).
    pub fn payload_now(&self, metrics: &Metrics, key: PayloadKey) -> Option<Payload> {
        use futures_util::FutureExt;
        let payload = self.payloads.as_ref()?.get(&key).now_or_never().flatten()?;
        metrics.cache_lookup("payload", true);
        Some(payload)
    }

    /// Compression `id`'s model record if the cache holds it now (and it
    /// is a visible version), without waiting or loading.
    pub fn record_now(&self, metrics: &Metrics, id: i64) -> Option<Arc<ModelRecord>> {
        use futures_util::FutureExt;
        let record = self
            .by_compression
            .get(&id)
            .now_or_never()
            .flatten()
            .flatten()?;
        metrics.cache_lookup("record", true);
        Some(record)
    }

    /// Every cached model record, for the per-model gauges.
    pub fn cached_records(&self) -> Vec<Arc<ModelRecord>> {
        self.by_slug.iter().filter_map(|(_, v)| v).collect()
    }
}

/// Looks `key` up, loading it (once, however many ask at the same time) on a miss.
pub async fn through<K, V, F>(
    cache: &Cache<K, V>,
    metrics: &Metrics,
    name: &'static str,
    key: K,
    load: F,
) -> Result<V, Arc<StorageError>>
where
    K: Hash + Eq + Send + Sync + 'static,
    V: Clone + Send + Sync + 'static,
    F: Future<Output = Result<V, StorageError>>,
{
    let entry = cache.entry(key).or_try_insert_with(load).await?;
    metrics.cache_lookup(name, !entry.is_fresh());
    Ok(entry.into_value())
}
