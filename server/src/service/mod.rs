//! The HTTP service: JSON manifests, binary payloads with strong ETags, level
//! caps by audience, device and load, the viewer's static files, and
//! health, readiness and metrics.
//!
//! [`app`] builds the router so tests can drive it in-process; [`crate::serve`]
//! runs it on a listener.

pub mod admission;
mod api;
mod cache;
mod cache_headers;
pub mod cap;
pub mod coherence;
mod crawl;
pub mod curator;
mod download;
mod error;
mod fast_payload;
mod guard;
mod iiif;
mod language;
mod layers;
pub mod load;
mod manifest;
mod metrics;
mod oembed;
mod ops;
mod parts;
mod payload;
mod precompressed;
mod routes;
mod scene;
mod servable;
mod study;
pub mod texts;
mod tours;
mod ui_strings;
mod visitor;
mod web;

pub use cache::CacheConfig;
pub use error::AppError;
pub use layers::RequestLimits;
pub use routes::{openapi, openapi_json};
pub use ui_strings::{UiStrings, UiStringsError};
pub use visitor::{client_address, ClientAddr, PeerAddr, VisitorHints};

use crate::storage::{sha256_hex, ModelRecord, Storage, TokenGrant, TokenScope};
use admission::{Admission, AdmissionConfig};
use axum::Router;
use cache::{through, Caches};
use cap::{Audience, CapRules, DeviceClass, LevelCap};
pub use fast_payload::FastPayload;
use load::{LoadConfig, LoadMonitor};
use metrics::Metrics;
use std::path::PathBuf;
use std::sync::Arc;
use tokio::sync::Semaphore;

/// Everything the service can be told at start-up.
#[derive(Clone, Debug, PartialEq)]
pub struct ServiceConfig {
    pub caps: CapRules,
    pub load: LoadConfig,
    /// New visitors per second during a surge ([`admission`]).
    pub admission: AdmissionConfig,
    pub cache: CacheConfig,
    pub limits: RequestLimits,
    /// The viewer's build (`index.html` and assets); a minimal built-in page
    /// is served when it has no `index.html`.
    pub web_dir: PathBuf,
    /// Origins allowed by CORS; empty means any.
    pub cors_origins: Vec<String>,
    /// Uploads, their ingest jobs, and the public base URL of `og:image`.
    pub uploads: curator::UploadConfig,
    /// Proxies whose `X-Forwarded-For` / `Forwarded` names the visitor
    /// ([`client_address`]); empty: none is believed.
    pub trusted_proxies: Vec<ipnet::IpNet>,
    /// The museum's name as sites that show its links give it: oEmbed's
    /// `provider_name`, the model page's `og:site_name`.
    pub site_name: String,
    /// The museum's own words in place of the viewer's (`[ui.strings.pt]`
    /// in the configuration file), carried by every page.
    pub ui_strings: UiStrings,
}

impl Default for ServiceConfig {
    fn default() -> Self {
        ServiceConfig {
            caps: CapRules::default(),
            load: LoadConfig::default(),
            admission: AdmissionConfig::default(),
            cache: CacheConfig::default(),
            limits: RequestLimits::default(),
            web_dir: PathBuf::from("web/dist"),
            cors_origins: Vec::new(),
            uploads: curator::UploadConfig::default(),
            trusted_proxies: Vec::new(),
            site_name: "Vitrine".into(),
            ui_strings: UiStrings::default(),
        }
    }
}

/// A visitor once the token is checked.
#[derive(Clone, Debug, PartialEq)]
pub struct Visitor {
    pub audience: Audience,
    pub device: DeviceClass,
    pub device_explicit: bool,
    pub grant: Option<TokenGrant>,
    /// The model version whose study invited this visitor.
    pub study_model: Option<i64>,
}

/// Shared by every request.
#[derive(Clone)]
pub struct AppState(Arc<Inner>);

struct Inner {
    storage: Arc<dyn Storage>,
    config: ServiceConfig,
    caches: Caches,
    load: Arc<LoadMonitor>,
    admission: Admission,
    metrics: Metrics,
    /// The global concurrency limit.
    permits: Arc<Semaphore>,
    /// GLB downloads decoded at once.
    downloads: Arc<Semaphore>,
    /// Upload ingests ([`curator::jobs`]).
    jobs: curator::jobs::JobRunner,
    /// Set once shutdown is asked for: `/readyz` answers 503 from then on.
    draining: std::sync::atomic::AtomicBool,
}

impl AppState {
    /// The load sampler is not started here: see [`AppState::spawn_load_sampler`].
    pub fn new(storage: Arc<dyn Storage>, config: ServiceConfig) -> AppState {
        AppState(Arc::new(Inner {
            storage,
            caches: Caches::new(&config.cache),
            load: LoadMonitor::new(config.load.clone()),
            admission: Admission::new(config.admission.clone()),
            metrics: Metrics::default(),
            permits: Arc::new(Semaphore::new(config.limits.max_concurrency)),
            downloads: Arc::new(Semaphore::new(download::MAX_CONCURRENT_DOWNLOADS)),
            jobs: curator::jobs::JobRunner::new(
                config.uploads.concurrent_jobs,
                config.uploads.max_queued,
            ),
            draining: std::sync::atomic::AtomicBool::new(false),
            config,
        }))
    }

    /// Starts sampling load; the task ends when the state is dropped.
    pub fn spawn_load_sampler(&self) -> tokio::task::JoinHandle<()> {
        self.0.load.spawn_sampler()
    }

    pub fn storage(&self) -> &Arc<dyn Storage> {
        &self.0.storage
    }

    pub fn config(&self) -> &ServiceConfig {
        &self.0.config
    }

    pub fn load(&self) -> &Arc<LoadMonitor> {
        &self.0.load
    }

    pub fn admission(&self) -> &Admission {
        &self.0.admission
    }

    pub(crate) fn caches(&self) -> &Caches {
        &self.0.caches
    }

    pub(crate) fn metrics(&self) -> &Metrics {
        &self.0.metrics
    }

    pub(crate) fn permits(&self) -> &Arc<Semaphore> {
        &self.0.permits
    }

    pub(crate) fn downloads(&self) -> &Arc<Semaphore> {
        &self.0.downloads
    }

    pub(crate) fn jobs(&self) -> &curator::jobs::JobRunner {
        &self.0.jobs
    }

    /// Shutdown has begun: `/readyz` answers 503 (requests are still served).
    pub fn start_draining(&self) {
        self.0
            .draining
            .store(true, std::sync::atomic::Ordering::Relaxed);
    }

    pub fn is_draining(&self) -> bool {
        self.0.draining.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Forgets cached records, tokens and the model list, so that a new
    /// ingest or policy change shows before the TTL runs out.
    pub fn invalidate(&self) {
        self.0.caches.invalidate();
    }

    pub async fn record_by_slug(&self, slug: &str) -> Result<Arc<ModelRecord>, AppError> {
        let storage = self.storage();
        let load = async { Ok(storage.model_by_slug(slug).await?.map(Arc::new)) };
        let record = through(
            &self.caches().by_slug,
            self.metrics(),
            "record",
            slug.to_owned(),
            load,
        )
        .await?;
        record.ok_or(AppError::NotFound("model"))
    }

    pub async fn record_by_compression(&self, id: i64) -> Result<Arc<ModelRecord>, AppError> {
        let storage = self.storage();
        let load = async { Ok(storage.model_by_compression(id).await?.map(Arc::new)) };
        let record = through(
            &self.caches().by_compression,
            self.metrics(),
            "record",
            id,
            load,
        )
        .await?;
        record.ok_or(AppError::NotFound("compression"))
    }

    /// Checks the token, if any, and decides the audience for model `slug`.
    pub async fn visitor(&self, hints: &VisitorHints, slug: &str) -> Result<Visitor, AppError> {
        if let Some(token) = hints
            .token
            .as_deref()
            .filter(|t| crate::study::is_invitation(t))
        {
            let invitation = study::live_invitation(self, token).await?;
            let invited = invitation.study.slug == slug;
            return Ok(Visitor {
                audience: if invited {
                    Audience::Study
                } else {
                    Audience::Public
                },
                device: hints.device,
                device_explicit: hints.device_explicit,
                grant: None,
                study_model: invited.then_some(invitation.study.model_id),
            });
        }
        let grant = match &hints.token {
            None => None,
            Some(token) => {
                let digest = sha256_hex(token.as_bytes());
                let storage = self.storage();
                let load = async { storage.token_grant(&digest, crate::storage::now_ms()).await };
                let grant = through(
                    &self.caches().tokens,
                    self.metrics(),
                    "token",
                    digest.clone(),
                    load,
                )
                .await?;
                Some(grant.ok_or(AppError::InvalidToken)?)
            }
        };
        // Scopes are separate: a curator token publishes and annotates but
        // sees what the public sees.
        let researcher = grant
            .as_ref()
            .is_some_and(|g| g.scope == TokenScope::Researcher && g.covers(slug));
        Ok(Visitor {
            audience: if researcher {
                Audience::Researcher
            } else {
                Audience::Public
            },
            device: hints.device,
            device_explicit: hints.device_explicit,
            grant,
            study_model: None,
        })
    }

    pub fn level_cap(&self, record: &ModelRecord, visitor: &Visitor) -> LevelCap {
        let pressure = self.load().pressure();
        cap::level_cap(
            record,
            visitor.audience,
            visitor.device,
            pressure,
            &self.config().caps,
        )
    }

    /// `(slug, load cap, good-enough level)` of every cached model.
    fn current_load_caps(&self) -> Vec<(String, u32, u32)> {
        let pressure = self.load().pressure();
        let rules = &self.config().caps;
        self.caches()
            .cached_records()
            .iter()
            .map(|r| {
                (
                    r.slug.clone(),
                    cap::load_cap(r, pressure, rules),
                    cap::good_enough_level(r, rules),
                )
            })
            .collect()
    }
}

/// The whole service as one router.
pub fn app(state: AppState) -> Router {
    layers::apply(routes::all(state.config()), &state).with_state(state)
}

/// What `vitrine serve` answers with: [`app`] behind the fast path for
/// cached public payloads ([`fast_payload`]).
pub fn serving(state: AppState) -> FastPayload<Router> {
    FastPayload::new(app(state.clone()), state)
}

/// Only `/healthz`, `/readyz`, `/metrics` and the OpenAPI description, for a
/// separate metrics listener.
pub fn ops_app(state: AppState) -> Router {
    layers::apply(routes::ops_only(), &state).with_state(state)
}
