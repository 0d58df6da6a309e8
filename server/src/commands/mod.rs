//! The `ingest`, `serve`, `token` and `models` subcommands, for `main.rs` to wire in.

mod ingest;
mod models;
mod serve;
mod token;

pub use ingest::{run_ingest, CccArgs, IngestArgs};
pub use models::{models_table, run_models, ModelsArgs};
pub use serve::{run_serve, ServeArgs};
pub use token::{new_token, run_token, TokenArgs};

use crate::storage::{self, ConnectOptions, Storage};
use std::sync::Arc;
use std::time::Duration;

/// Logs to stderr, filtered by `RUST_LOG` (default `info`). Safe to call twice.
pub fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_default_env()
        .unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_writer(std::io::stderr)
        .try_init();
}

/// Opens the database and applies migrations. With `wait`, an unreachable
/// database is retried with backoff until it answers instead of failing.
pub async fn open_storage(
    url: &str,
    options: &ConnectOptions,
    wait: bool,
) -> anyhow::Result<Arc<dyn Storage>> {
    let storage = storage::connect(url, options)?;
    let mut backoff = Duration::from_millis(250);
    loop {
        match storage.migrate().await {
            Ok(()) => return Ok(storage),
            Err(e) if wait && e.is_unavailable() => {
                tracing::warn!(error = %e, retry_in = ?backoff, "database unavailable; retrying");
                tokio::time::sleep(backoff).await;
                backoff = (backoff * 2).min(Duration::from_secs(15));
            }
            Err(e) => return Err(anyhow::Error::new(e).context(format!("opening {}", redact(url)))),
        }
    }
}

/// The URL without its password, for messages.
pub fn redact(url: &str) -> String {
    match (url.find("://"), url.rfind('@')) {
        (Some(scheme), Some(at)) if at > scheme => {
            let userinfo = &url[scheme + 3..at];
            match userinfo.split_once(':') {
                Some((user, _)) => format!("{}{user}:***{}", &url[..scheme + 3], &url[at..]),
                None => url.to_owned(),
            }
        }
        _ => url.to_owned(),
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn passwords_are_redacted() {
        assert_eq!(
            super::redact("postgres://u:secret@h/db"),
            "postgres://u:***@h/db"
        );
        assert_eq!(super::redact("postgres://u@h/db"), "postgres://u@h/db");
        assert_eq!(super::redact("sqlite:x.db"), "sqlite:x.db");
    }
}
