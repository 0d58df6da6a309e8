//! The database as the commands open it: migrations applied, an unreachable
//! server waited for when asked, the password kept out of messages.

use crate::storage::{self, ConnectOptions, Storage};
use std::sync::Arc;
use std::time::Duration;

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
