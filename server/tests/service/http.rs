//! Over real HTTP on port 0: headers on the wire, load from concurrent slow
//! requests, database loss and recovery.

use super::harness::{
    eventually, ingest_sample, ingest_sample_with, sample_encoded, test_config, TestDb, TestServer,
};
use super::slow::SlowStorage;
use reqwest::StatusCode;
use std::sync::Arc;
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use vitrine_codec::StreamIndex;

fn client() -> reqwest::Client {
    reqwest::Client::builder()
        .pool_max_idle_per_host(64)
        .build()
        .unwrap()
}

pub async fn end_to_end(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "open")
        .await
        .stored
        .compression_id;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = client();
    let encoded = sample_encoded();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();

    let manifest = http
        .get(server.url("/api/models/torus"))
        .send()
        .await
        .unwrap();
    assert_eq!(manifest.status(), StatusCode::OK);
    let m: serde_json::Value = manifest.json().await.unwrap();
    assert_eq!(m["compression_id"], id);
    let base = http
        .get(server.url(m["levels"][0]["url"].as_str().unwrap()))
        .send()
        .await
        .unwrap();
    assert!(
        base.headers().get("content-encoding").is_none(),
        "payloads are not recompressed"
    );
    assert_eq!(
        base.bytes().await.unwrap(),
        encoded.bytes[index.base.clone()]
    );
    for (k, range) in index.batches.iter().enumerate() {
        let url = server.url(&format!("/api/compressions/{id}/batches/{}", k + 1));
        let reply = http
            .get(&url)
            .header("accept-encoding", "gzip, br")
            .send()
            .await
            .unwrap();
        assert_eq!(reply.status(), StatusCode::OK);
        assert!(reply.headers().get("content-encoding").is_none());
        let etag = reply.headers()["etag"].clone();
        assert_eq!(reply.bytes().await.unwrap(), encoded.bytes[range.clone()]);
        let again = http
            .get(&url)
            .header("if-none-match", etag)
            .send()
            .await
            .unwrap();
        assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
    }

    // JSON is compressed when asked; CORS answers museum sites.
    let list = http
        .get(server.url("/api/models"))
        .header("accept-encoding", "gzip")
        .header("origin", "https://museum.example")
        .send()
        .await
        .unwrap();
    assert_eq!(list.headers()["content-encoding"], "gzip");
    assert_eq!(list.headers()["access-control-allow-origin"], "*");
    let preflight = http
        .request(reqwest::Method::OPTIONS, server.url("/api/models/torus"))
        .header("origin", "https://museum.example")
        .header("access-control-request-method", "GET")
        .header("access-control-request-headers", "authorization")
        .send()
        .await
        .unwrap();
    assert!(preflight.status().is_success(), "{}", preflight.status());

    let gallery = http.get(server.url("/")).send().await.unwrap();
    assert_eq!(gallery.status(), StatusCode::OK);
    assert!(gallery.text().await.unwrap().contains("Sample torus"));
    assert_eq!(
        http.get(server.url("/m/torus"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );
    assert_eq!(
        http.get(server.url("/embed/nope"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::NOT_FOUND
    );
    assert_eq!(
        http.get(server.url("/healthz"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );
    assert_eq!(
        http.get(server.url("/readyz"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );
    let metrics = http
        .get(server.url("/metrics"))
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert!(metrics.contains("vitrine_http_requests_total{route=\"/api/compressions/{id}/batches/{iteration}\",status=\"200\"}"));
    let openapi: serde_json::Value = http
        .get(server.url("/api/openapi.json"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(openapi["openapi"], "3.1.0");

    // Oversized headers are refused before any handler runs.
    let addr = server.base.trim_start_matches("http://").to_owned();
    let mut raw = tokio::net::TcpStream::connect(addr).await.unwrap();
    let huge = format!(
        "GET /healthz HTTP/1.1\r\nhost: x\r\nx-big: {}\r\n\r\n",
        "a".repeat(64 * 1024)
    );
    let _ = raw.write_all(huge.as_bytes()).await;
    let mut answer = vec![0u8; 64];
    let n = raw.read(&mut answer).await.unwrap_or(0);
    assert!(
        String::from_utf8_lossy(&answer[..n]).starts_with("HTTP/1.1 431"),
        "{:?}",
        String::from_utf8_lossy(&answer[..n])
    );
}

async fn manifest_cap(http: &reqwest::Client, server: &TestServer) -> (u64, Option<String>) {
    let m: serde_json::Value = http
        .get(server.url("/api/models/crowd"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    (
        m["cap"]["level"].as_u64().unwrap(),
        m["cap"]["reason"].as_str().map(str::to_owned),
    )
}

pub async fn load_cap_under_real_load(db: TestDb) {
    let id = ingest_sample_with(&*db.storage, "crowd", "open", Some(2))
        .await
        .stored
        .compression_id;
    let slow = SlowStorage::new(db.storage.clone(), Duration::from_millis(150));
    let mut config = test_config();
    config.cache.payload_bytes = 0; // every batch request reads the (slow) database
    config.load.high_inflight = 16;
    config.load.low_inflight = 2;
    config.load.sample_every = Duration::from_millis(20);
    config.load.cooldown_samples = 3;
    let server = TestServer::start(slow, config).await;
    let http = client();
    let index = StreamIndex::parse(&sample_encoded().bytes).unwrap();
    let last = index.batches.len() as u64;
    assert_eq!(manifest_cap(&http, &server).await, (last, None));

    // A crowd: 48 visitors fetching batch 1 in a loop for a bounded time.
    let stop = Arc::new(std::sync::atomic::AtomicBool::new(false));
    let crowd: Vec<_> = (0..48)
        .map(|_| {
            let (http, stop) = (http.clone(), Arc::clone(&stop));
            let url = server.url(&format!("/api/compressions/{id}/batches/1"));
            tokio::spawn(async move {
                let deadline = tokio::time::Instant::now() + Duration::from_secs(20);
                while !stop.load(std::sync::atomic::Ordering::Relaxed)
                    && tokio::time::Instant::now() < deadline
                {
                    let _ = http
                        .get(&url)
                        .send()
                        .await
                        .and_then(|r| r.error_for_status());
                }
            })
        })
        .collect();
    eventually(
        Duration::from_secs(10),
        "the cap to fall to the good-enough level",
        || async {
            let (level, reason) = manifest_cap(&http, &server).await;
            level == 2 && reason.as_deref() == Some("load")
        },
    )
    .await;
    let refused = http
        .get(server.url(&format!("/api/compressions/{id}/batches/{last}")))
        .send()
        .await
        .unwrap();
    assert_eq!(refused.status(), StatusCode::TOO_MANY_REQUESTS);
    assert!(refused.headers().contains_key("retry-after"));
    let metrics = http
        .get(server.url("/metrics"))
        .send()
        .await
        .unwrap()
        .text()
        .await
        .unwrap();
    assert!(!metrics.contains("vitrine_load_pressure 0\n"), "{metrics}");

    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    for visitor in crowd {
        visitor.await.unwrap();
    }
    eventually(Duration::from_secs(10), "the cap to rise again", || async {
        manifest_cap(&http, &server).await == (last, None)
    })
    .await;
}

pub async fn database_outage_and_recovery(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "open")
        .await
        .stored
        .compression_id;
    let mut config = test_config();
    config.cache.payload_bytes = 0;
    config.cache.record_ttl = Duration::from_millis(1);
    let server = TestServer::start(db.connect_again(), config).await;
    let http = client();
    let manifest = server.url("/api/models/torus");
    let batch = server.url(&format!("/api/compressions/{id}/batches/1"));
    assert_eq!(
        http.get(&manifest).send().await.unwrap().status(),
        StatusCode::OK
    );

    db.outage().await;
    // Connections opened before the outage live on until their max_lifetime.
    tokio::time::sleep(2 * super::harness::test_connect_options().max_lifetime).await;
    for url in [
        &manifest,
        &batch,
        &server.url("/readyz"),
        &server.url("/api/models"),
    ] {
        let reply = http.get(url.as_str()).send().await.unwrap();
        assert_eq!(reply.status(), StatusCode::SERVICE_UNAVAILABLE, "{url}");
        assert!(reply.headers().contains_key("retry-after"), "{url}");
        let body: serde_json::Value = reply.json().await.unwrap();
        assert_eq!(body["error"], "database_unavailable", "{url}");
    }
    assert_eq!(
        http.get(server.url("/healthz"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );

    db.restore().await;
    eventually(
        Duration::from_secs(15),
        "recovery once the database is back",
        || async { http.get(&batch).send().await.unwrap().status() == StatusCode::OK },
    )
    .await;
    assert_eq!(
        http.get(&manifest).send().await.unwrap().status(),
        StatusCode::OK
    );
    assert_eq!(
        http.get(server.url("/readyz"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );
}

/// A surge of new visitors: past the burst, manifests get 503 `busy` with
/// `Retry-After`, visits already under way still get their payloads, and
/// new visitors are admitted again as the bucket refills.
pub async fn admission_in_a_surge(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "open")
        .await
        .stored
        .compression_id;
    let mut config = test_config();
    config.admission.burst = 3.0;
    config.admission.rate = 1.0;
    let server = TestServer::start(db.storage.clone(), config).await;
    let http = client();
    let manifest = server.url("/api/models/torus");
    let mut statuses = Vec::new();
    let mut retry_after = Vec::new();
    for _ in 0..7 {
        let reply = http.get(&manifest).send().await.unwrap();
        statuses.push(reply.status().as_u16());
        if reply.status() == StatusCode::SERVICE_UNAVAILABLE {
            let after: u64 = reply.headers()["retry-after"]
                .to_str()
                .unwrap()
                .parse()
                .unwrap();
            retry_after.push(after);
            let body: serde_json::Value = reply.json().await.unwrap();
            assert_eq!(body["error"], "busy");
        }
    }
    assert_eq!(&statuses[..3], &[200, 200, 200]);
    assert!(statuses[3..].iter().all(|s| *s == 503), "{statuses:?}");
    // Each refused visitor is told its turn: ⌈place in the backlog / rate⌉ s.
    assert_eq!(retry_after, vec![1, 2, 3, 4]);
    let batch = server.url(&format!("/api/compressions/{id}/batches/1"));
    assert_eq!(
        http.get(&batch).send().await.unwrap().status(),
        StatusCode::OK
    );
    tokio::time::sleep(Duration::from_millis(1100)).await;
    assert_eq!(
        http.get(&manifest).send().await.unwrap().status(),
        StatusCode::OK
    );
}

pub async fn shedding_and_body_limit(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "open")
        .await
        .stored
        .compression_id;
    let slow = SlowStorage::new(db.storage.clone(), Duration::from_secs(1));
    let mut config = test_config();
    config.cache.payload_bytes = 0;
    config.limits.max_concurrency = 2;
    let server = TestServer::start(slow, config).await;
    let http = client();
    let url = server.url(&format!("/api/compressions/{id}/batches/1"));
    let replies: Vec<_> = (0..6)
        .map(|_| tokio::spawn(http.get(&url).send()))
        .collect();
    let mut statuses = Vec::new();
    for reply in replies {
        let reply = reply.await.unwrap().unwrap();
        if reply.status() == StatusCode::SERVICE_UNAVAILABLE {
            assert!(reply.headers().contains_key("retry-after"));
            let body: serde_json::Value = reply.json().await.unwrap();
            assert_eq!(body["error"], "overloaded");
            statuses.push(503);
        } else {
            statuses.push(reply.status().as_u16());
        }
    }
    statuses.sort();
    assert_eq!(statuses, vec![200, 200, 503, 503, 503, 503]);

    let big = http
        .get(server.url("/api/models"))
        .body(vec![b'x'; 70_000])
        .send()
        .await
        .unwrap();
    assert_eq!(big.status(), StatusCode::PAYLOAD_TOO_LARGE);
}

pub async fn graceful_shutdown(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "open")
        .await
        .stored
        .compression_id;
    let slow = SlowStorage::new(db.storage.clone(), Duration::from_millis(500));
    let mut config = test_config();
    config.cache.payload_bytes = 0;
    let server = TestServer::start(slow.clone(), config).await;
    let http = client();
    let url = server.url(&format!("/api/compressions/{id}/batches/1"));
    let healthz = server.url("/healthz");
    assert_eq!(
        http.get(&healthz).send().await.unwrap().status(),
        StatusCode::OK
    );
    let in_flight = tokio::spawn(http.get(&url).send());
    slow.reached().await;
    let started = tokio::time::Instant::now();
    server.shut_down().await;
    // The request that was in flight finished; the listener is gone.
    assert_eq!(in_flight.await.unwrap().unwrap().status(), StatusCode::OK);
    assert!(
        started.elapsed() < Duration::from_secs(5),
        "shutdown waited for the request, not the grace period"
    );
    assert!(reqwest::Client::new().get(&healthz).send().await.is_err());
}
