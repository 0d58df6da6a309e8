//! Coherence of several instances on one database: a version ingested or
//! withdrawn (or a policy or token changed) by another instance or by the CLI
//! shows here within a bound, because the records cached in memory
//! ([`super::cache`]) are dropped when the database says something changed.
//!
//! Two signals, both from the `change_generation` counter that the database's
//! own triggers bump on every committed change (migration
//! `20261202200001_change_generation.sql`):
//! - PostgreSQL: `LISTEN vitrine_changes` (sqlx `PgListener`); a
//!   notification arrives when the writing transaction commits, typically
//!   within milliseconds. The listener reconnects after PostgreSQL restarts,
//!   and drops the caches once it listens again (what was sent meanwhile is
//!   lost); while the database is away the cached records keep answering.
//! - Both backends: the counter is read every `poll` (default 2 s), which
//!   bounds staleness when a notification was missed, and is the only signal
//!   on SQLite (one machine: a CLI ingest beside a running server).
//!
//! Payloads are immutable under their compression id and stay cached.

use super::AppState;
use sqlx::postgres::PgListener;
use std::time::Duration;
use tokio::task::JoinHandle;

/// The channel the triggers notify.
pub const CHANNEL: &str = "vitrine_changes";

/// The watching tasks; they stop when this is dropped.
pub struct Coherence(Vec<JoinHandle<()>>);

impl Drop for Coherence {
    fn drop(&mut self) {
        for task in &self.0 {
            task.abort();
        }
    }
}

/// Watches the database behind `state`: `listen_url` (a PostgreSQL URL) for
/// notifications, and the counter every `poll` (zero: not polled).
pub fn spawn(state: &AppState, listen_url: Option<String>, poll: Duration) -> Coherence {
    let mut tasks = Vec::new();
    if !poll.is_zero() {
        tasks.push(tokio::spawn(poll_counter(state.clone(), poll)));
    }
    if let Some(url) = listen_url {
        tasks.push(tokio::spawn(listen(state.clone(), url)));
    }
    Coherence(tasks)
}

async fn poll_counter(state: AppState, every: Duration) {
    let mut known: Option<i64> = None;
    let mut tick = tokio::time::interval(every);
    tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
    loop {
        tick.tick().await;
        match state.storage().change_generation().await {
            Ok(now) => {
                if known.is_some_and(|k| k != now) {
                    tracing::debug!(generation = now, "database changed: cached records dropped");
                    state.invalidate();
                }
                known = Some(now);
            }
            // Unreachable: the next answer compares with the last one seen.
            Err(e) => tracing::debug!(error = %e, "change counter unreadable"),
        }
    }
}

async fn listen(state: AppState, url: String) {
    let mut backoff = Duration::from_millis(250);
    loop {
        let mut listener = match PgListener::connect(&url).await {
            Ok(l) => l,
            Err(e) => {
                tracing::debug!(error = %e, retry_in = ?backoff, "cannot LISTEN yet");
                tokio::time::sleep(backoff).await;
                backoff = (backoff * 2).min(Duration::from_secs(5));
                continue;
            }
        };
        if let Err(e) = listener.listen(CHANNEL).await {
            tracing::debug!(error = %e, "LISTEN failed");
            tokio::time::sleep(backoff).await;
            continue;
        }
        backoff = Duration::from_millis(250);
        // Whatever changed before this LISTEN was not heard.
        state.invalidate();
        tracing::debug!("listening for database changes");
        loop {
            match listener.try_recv().await {
                Ok(Some(n)) => {
                    tracing::debug!(
                        table = n.payload(),
                        "change notified: cached records dropped"
                    );
                    state.invalidate();
                }
                // The connection was lost: connect again above, which drops
                // the caches once it listens (what was sent meanwhile is
                // lost). Not before: while the database is away the cached
                // records keep answering, and nothing can change there.
                Ok(None) => {
                    tracing::debug!("listening connection lost; reconnecting");
                    break;
                }
                Err(e) => {
                    tracing::debug!(error = %e, "listening connection failed; reconnecting");
                    tokio::time::sleep(backoff).await;
                    break;
                }
            }
        }
    }
}
