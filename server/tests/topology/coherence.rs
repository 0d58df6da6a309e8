//! Two service instances on one database: what one ingests or withdraws
//! shows at the other within the bound, by PostgreSQL NOTIFY alone (the poll
//! off), after the listening connection was cut, and by the poll alone
//! (SQLite, or a lost notification).

use crate::harness::{sample_mesh, test_config, Backend, TestDb, TestServer};
use std::time::{Duration, Instant};
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::service::coherence;
use vitrine::storage::{OnExisting, Storage};
use vitrine::AppState;

/// What a new version must take at most to show at the other instance.
const BOUND: Duration = Duration::from_secs(3);

async fn ingest_version(storage: &dyn Storage) -> u32 {
    let mut meta = ModelMeta::new("amphora", "Amphora");
    meta.policy = "open".into();
    meta.on_existing = OnExisting::NewVersion;
    ingest_mesh(storage, sample_mesh(), meta, &IngestOptions::default())
        .await
        .expect("ingest")
        .stored
        .version
}

async fn version_at(server: &TestServer) -> Option<u64> {
    let r = reqwest::get(server.url("/api/models/amphora")).await.ok()?;
    if r.status() != 200 {
        return None;
    }
    let m: serde_json::Value = r.json().await.ok()?;
    m["version"].as_u64()
}

/// How long until `server` serves `version` (panics past the bound).
async fn shows(server: &TestServer, version: u64, what: &str) -> Duration {
    let t0 = Instant::now();
    loop {
        if version_at(server).await == Some(version) {
            return t0.elapsed();
        }
        assert!(
            t0.elapsed() < BOUND,
            "{what}: version {version} not served within {BOUND:?}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Instance B, whose record cache would keep what it read for a minute
/// were it not told of changes.
async fn instance(db: &TestDb, listen: bool, poll: Duration) -> (TestServer, coherence::Coherence) {
    let mut config = test_config();
    config.cache.record_ttl = Duration::from_secs(60);
    let state = AppState::new(db.connect_again(), config);
    let watch = coherence::spawn(&state, listen.then(|| db.url.clone()), poll);
    (TestServer::serve(state).await, watch)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_notify_reaches_the_other_instance() {
    let Some(db) = TestDb::new(Backend::Postgres).await else {
        return;
    };
    // Instance A ingests through its storage; B listens, never polls.
    assert_eq!(ingest_version(&*db.storage).await, 1);
    let (b, _watch) = instance(&db, true, Duration::ZERO).await;
    shows(&b, 1, "first version").await;
    // Let the listener subscribe (it drops the caches when it does).
    tokio::time::sleep(Duration::from_millis(300)).await;
    assert_eq!(version_at(&b).await, Some(1));

    assert_eq!(ingest_version(&*db.storage).await, 2);
    let took = shows(&b, 2, "new version by NOTIFY").await;
    eprintln!("new version at the other instance after {took:?} (NOTIFY)");

    // Withdrawn by hand (SQL, as an operator would): the previous version again.
    db.execute("UPDATE model SET status = 'withdrawn' WHERE slug = 'amphora' AND version = 2")
        .await;
    shows(&b, 1, "withdrawal by NOTIFY").await;

    // PostgreSQL goes away and comes back: the listener reconnects.
    db.outage().await;
    tokio::time::sleep(Duration::from_millis(500)).await;
    db.restore().await;
    let mut reconnected = false;
    for _ in 0..50 {
        if db.storage.ping().await.is_ok() {
            reconnected = true;
            break;
        }
        tokio::time::sleep(Duration::from_millis(100)).await;
    }
    assert!(reconnected, "database back");
    // Give the listener its backoff to reconnect, then change again.
    tokio::time::sleep(Duration::from_millis(1500)).await;
    assert_eq!(ingest_version(&*db.storage).await, 3);
    shows(&b, 3, "new version after the listener reconnected").await;
    b.shut_down().await;
}

async fn poll_reaches_the_other_instance(backend: Backend) {
    let Some(db) = TestDb::new(backend).await else {
        return;
    };
    assert_eq!(ingest_version(&*db.storage).await, 1);
    let (b, _watch) = instance(&db, false, Duration::from_millis(250)).await;
    shows(&b, 1, "first version").await;
    assert_eq!(ingest_version(&*db.storage).await, 2);
    let took = shows(&b, 2, "new version by the poll").await;
    eprintln!("{backend:?}: new version at the other instance after {took:?} (poll 250 ms)");
    db.execute("UPDATE model SET status = 'withdrawn' WHERE slug = 'amphora' AND version = 2")
        .await;
    shows(&b, 1, "withdrawal by the poll").await;
    b.shut_down().await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sqlite_poll_reaches_the_other_instance() {
    poll_reaches_the_other_instance(Backend::Sqlite).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn postgres_poll_alone_reaches_the_other_instance() {
    poll_reaches_the_other_instance(Backend::Postgres).await;
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn without_a_signal_the_cached_record_stays() {
    // The control: neither listening nor polling, B keeps version 1 for its
    // record TTL (a minute here), so the tests above measure the signals.
    let Some(db) = TestDb::new(Backend::Sqlite).await else {
        return;
    };
    ingest_version(&*db.storage).await;
    let (b, _watch) = instance(&db, false, Duration::ZERO).await;
    shows(&b, 1, "first version").await;
    ingest_version(&*db.storage).await;
    tokio::time::sleep(Duration::from_secs(1)).await;
    assert_eq!(version_at(&b).await, Some(1));
    b.shut_down().await;
}
