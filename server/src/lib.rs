//! Vitrine's storage and HTTP service.
//!
//! Models are ingested into a database ([`storage`]: SQLite or PostgreSQL,
//! one trait) as a base mesh plus one refinement batch per level, and served
//! by an axum [`app`] that caps how many levels each visitor may fetch.
//!
//! ```no_run
//! # async fn demo() -> anyhow::Result<()> {
//! use vitrine::{app, serve, AppState, ServeLimits, ServiceConfig};
//! let storage = vitrine::storage::connect("sqlite:vitrine.db", &Default::default())?;
//! storage.migrate().await?;
//! let state = AppState::new(storage, ServiceConfig::default());
//! state.spawn_load_sampler();
//! let listener = tokio::net::TcpListener::bind("127.0.0.1:0").await?;
//! serve(listener, app(state), ServeLimits::default(), vitrine::shutdown_signal()).await?;
//! # Ok(()) }
//! ```
#![forbid(unsafe_code)]

mod commands;
pub mod ingest;
mod serve;
pub mod service;
pub mod storage;

pub use commands::{init_tracing, new_token, open_storage, run_ingest, run_serve, run_token};
pub use commands::{models_table, run_models, ModelsArgs};
pub use commands::{CccArgs, IngestArgs, ServeArgs, TokenArgs};
pub use serve::{serve, shutdown_signal, ServeLimits};
pub use service::{app, ops_app, AppState, ServiceConfig};
