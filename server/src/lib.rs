//! Vitrine's storage, HTTP service and command line.
//!
//! Models are ingested into a database ([`storage`]: SQLite or PostgreSQL,
//! one trait) as a base mesh plus one refinement batch per level, and served
//! by an axum [`app`] that caps how many levels each visitor may fetch.
//! The command line lives here too ([`commands`], one module per
//! subcommand): the `vitrine` binary and, with the `dev-tools` feature,
//! `vitrine-dev` only parse their arguments and run a [`Command`] or a
//! `DevCommand`.
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

mod ccc_files;
pub mod commands;
pub mod config;
mod connections;
mod database;
pub mod ingest;
pub mod service;
mod source;
pub mod storage;
pub mod study;

pub use commands::ingest::{run as run_ingest, IngestArgs};
pub use commands::models::models_listing;
pub use commands::token::new_token;
pub use commands::Command;
#[cfg(feature = "dev-tools")]
pub use commands::DevCommand;
pub use connections::{serve, shutdown_signal, ServeLimits};
pub use database::open_storage;
pub use service::{app, ops_app, serving, AppState, ServiceConfig, UiStrings};
