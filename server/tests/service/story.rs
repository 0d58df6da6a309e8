//! The shared suite: storage and in-process service tests, run on both backends.

use super::harness::{ingest_sample, sample_encoded, sample_mesh, test_config, TestDb};
use axum::body::Body;
use axum::http::{header, HeaderMap, Request, StatusCode};
use axum::Router;
use bytes::Bytes;
use http_body_util::BodyExt;
use serde_json::Value;
use tower::ServiceExt;
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::{now_ms, sha256_hex, NewToken, OnExisting, StorageError};
use vitrine::{app, models_listing, new_token, AppState};
use vitrine_codec::{decode, Decoder, Limits, StreamIndex, VERSION};

pub struct Reply {
    pub status: StatusCode,
    pub headers: HeaderMap,
    pub body: Bytes,
}

impl Reply {
    pub fn json(&self) -> Value {
        serde_json::from_slice(&self.body)
            .unwrap_or_else(|e| panic!("not JSON ({e}): {:?}", self.body))
    }

    pub fn header(&self, name: header::HeaderName) -> &str {
        self.headers
            .get(&name)
            .and_then(|v| v.to_str().ok())
            .unwrap_or("")
    }
}

pub async fn get(app: &Router, uri: &str, headers: &[(&str, &str)]) -> Reply {
    get_from(app.clone(), uri, headers).await
}

/// A GET through any service that answers as the router does.
pub async fn get_from<S>(service: S, uri: &str, headers: &[(&str, &str)]) -> Reply
where
    S: tower::Service<
        Request<Body>,
        Response = axum::response::Response,
        Error = std::convert::Infallible,
    >,
{
    let mut request = Request::get(uri);
    for (name, value) in headers {
        request = request.header(*name, *value);
    }
    let response = service
        .oneshot(request.body(Body::empty()).unwrap())
        .await
        .unwrap();
    let status = response.status();
    let headers = response.headers().clone();
    let body = response.into_body().collect().await.unwrap().to_bytes();
    Reply {
        status,
        headers,
        body,
    }
}

pub async fn token_for(db: &TestDb, slug: Option<&str>) -> String {
    let token = new_token();
    let new = NewToken {
        token_sha256: sha256_hex(token.as_bytes()),
        scope: vitrine::storage::TokenScope::Researcher,
        label: "test".into(),
        model_slug: slug.map(str::to_owned),
        expires_at_ms: None,
    };
    db.storage.insert_token(&new).await.unwrap();
    token
}

pub async fn storage_round_trip(db: TestDb) {
    let s = &*db.storage;
    assert!(s.list_models().await.unwrap().is_empty());
    let report = ingest_sample(s, "torus", "exhibition").await;
    let encoded = sample_encoded();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    let id = report.stored.compression_id;

    let record = s
        .model_by_slug("torus")
        .await
        .unwrap()
        .expect("visible after commit");
    assert_eq!(
        (
            record.compression_id,
            record.version,
            record.policy.name.as_str()
        ),
        (id, 1, "exhibition")
    );
    assert_eq!(record.levels.len(), index.header.levels.len());
    assert_eq!(
        s.base_payload(id).await.unwrap().unwrap(),
        encoded.bytes[index.base.clone()]
    );
    assert_eq!(
        record.levels[0].sha256,
        sha256_hex(&encoded.bytes[index.base.clone()])
    );
    for (k, range) in index.batches.iter().enumerate() {
        let level = &record.levels[k + 1];
        let header = index.header.levels[k + 1];
        assert_eq!(
            (level.vertices, level.faces, level.bytes),
            (header.vertices, header.faces, u64::from(header.bytes))
        );
        let stored = s.batch_payload(id, k as u32 + 1).await.unwrap().unwrap();
        assert_eq!(stored, encoded.bytes[range.clone()], "batch {}", k + 1);
        assert_eq!(level.sha256, sha256_hex(&stored));
        // Measured by default at ingest (sampled; issue 22).
        assert!(level.hausdorff.is_some_and(|h| h.is_finite() && h >= 0.0));
    }
    assert!(s
        .batch_payload(id, index.batches.len() as u32 + 1)
        .await
        .unwrap()
        .is_none());
    assert!(s.base_payload(id + 1000).await.unwrap().is_none());
    assert_eq!(
        s.model_by_compression(id).await.unwrap().as_ref(),
        Some(&record)
    );
    assert!(s.model_by_slug("nope").await.unwrap().is_none());

    // Re-ingesting a slug is refused unless a new version is asked for.
    let err = ingest_mesh(
        s,
        sample_mesh(),
        ModelMeta::new("torus", "Again"),
        &IngestOptions::default(),
    )
    .await
    .unwrap_err();
    assert!(
        matches!(
            err.downcast_ref::<StorageError>(),
            Some(StorageError::Conflict(_))
        ),
        "{err:#}"
    );
    let mut meta = ModelMeta::new("torus", "Torus, second scan");
    meta.on_existing = OnExisting::NewVersion;
    let second = ingest_mesh(s, sample_mesh(), meta, &IngestOptions::default())
        .await
        .unwrap();
    assert_eq!(second.stored.version, 2);
    let current = s.model_by_slug("torus").await.unwrap().unwrap();
    assert_eq!(
        (current.version, current.compression_id),
        (2, second.stored.compression_id)
    );
    // The old version's URLs keep working for viewers that started on it.
    assert_eq!(
        s.model_by_compression(id).await.unwrap().unwrap().version,
        1
    );
    let list = s.list_models().await.unwrap();
    assert_eq!(list.len(), 1);
    assert_eq!(
        (
            list[0].slug.as_str(),
            list[0].version,
            list[0].title.as_str()
        ),
        ("torus", 2, "Torus, second scan")
    );

    let mut meta = ModelMeta::new("other", "Other");
    meta.policy = "no-such-policy".into();
    let err = ingest_mesh(s, sample_mesh(), meta, &IngestOptions::default())
        .await
        .unwrap_err();
    assert!(
        matches!(
            err.downcast_ref::<StorageError>(),
            Some(StorageError::Unknown(_))
        ),
        "{err:#}"
    );
    assert!(ingest_mesh(
        s,
        sample_mesh(),
        ModelMeta::new("Bad Slug", "x"),
        &IngestOptions::default()
    )
    .await
    .is_err());

    let token = token_for(&db, Some("torus")).await;
    let grant = s
        .token_grant(&sha256_hex(token.as_bytes()), now_ms())
        .await
        .unwrap()
        .unwrap();
    assert!(grant.covers("torus") && !grant.covers("other"));
    let expired = NewToken {
        token_sha256: sha256_hex(b"old"),
        scope: vitrine::storage::TokenScope::Researcher,
        label: "old".into(),
        model_slug: None,
        expires_at_ms: Some(now_ms() - 1),
    };
    s.insert_token(&expired).await.unwrap();
    assert!(s
        .token_grant(&sha256_hex(b"old"), now_ms())
        .await
        .unwrap()
        .is_none());
}

pub async fn manifest_and_payloads_match_codec(db: TestDb) {
    ingest_sample(&*db.storage, "open-torus", "open").await;
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let encoded = sample_encoded();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();

    let list = get(&app, "/api/models", &[]).await;
    assert_eq!(list.status, StatusCode::OK);
    assert_eq!(list.json()["models"][0]["slug"], "open-torus");

    let manifest = get(&app, "/api/models/open-torus?device=desktop", &[]).await;
    assert_eq!(manifest.status, StatusCode::OK);
    // Shared caches may keep a public manifest for two seconds (issue 24).
    assert!(manifest
        .header(header::CACHE_CONTROL)
        .starts_with("public, max-age=2,"));
    let m = manifest.json();
    let last = index.batches.len();
    assert_eq!(m["last_level"], last);
    assert_eq!(m["cap"]["level"], last, "{m}");
    assert_eq!(m["cap"]["reason"], Value::Null);
    // No study begun: no results to ask for (issue 45).
    assert!(m.get("study_results").is_none(), "{m}");
    let levels = m["levels"].as_array().unwrap();
    assert_eq!(levels.len(), index.header.levels.len());
    for (k, (level, header)) in levels.iter().zip(&index.header.levels).enumerate() {
        assert_eq!(level["vertices"], header.vertices);
        assert_eq!(level["faces"], header.faces);
        // What the viewer downloads: the base payload carries the stream header too.
        let bytes = if k == 0 {
            index.base.len()
        } else {
            index.batches[k - 1].len()
        };
        assert_eq!(level["bytes"], bytes);
        assert_eq!(level["allowed"], true);
    }

    let base = get(&app, levels[0]["url"].as_str().unwrap(), &[]).await;
    assert_eq!(base.status, StatusCode::OK);
    assert_eq!(
        base.header(header::CONTENT_TYPE),
        "application/octet-stream"
    );
    assert_eq!(base.body, encoded.bytes[index.base.clone()]);
    let mut decoder = Decoder::new(&base.body, Limits::default()).unwrap();
    for (k, level) in levels.iter().enumerate().skip(1) {
        let batch = get(&app, level["url"].as_str().unwrap(), &[]).await;
        assert_eq!(batch.status, StatusCode::OK, "batch {k}");
        assert_eq!(
            batch.body,
            encoded.bytes[index.batches[k - 1].clone()],
            "batch {k}"
        );
        decoder.apply_batch(&batch.body).unwrap();
    }
    let whole = decode(&encoded.bytes, None, Limits::default()).unwrap();
    assert_eq!(decoder.positions(), whole.positions());
    assert_eq!(decoder.indices(), whole.indices());
    assert_eq!(decoder.colours(), whole.colours());
}

pub async fn etags_and_not_modified(db: TestDb) {
    let report = ingest_sample(&*db.storage, "torus", "exhibition").await;
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let id = report.stored.compression_id;
    let url = format!("/api/compressions/{id}/batches/1");
    let first = get(&app, &url, &[]).await;
    assert_eq!(first.status, StatusCode::OK);
    let etag = first.header(header::ETAG).to_owned();
    assert!(
        etag.starts_with('"') && etag.ends_with('"') && etag.len() == 34,
        "{etag}"
    );
    assert_eq!(
        first.header(header::CACHE_CONTROL),
        "public, max-age=31536000, immutable"
    );

    let again = get(&app, &url, &[("if-none-match", &etag)]).await;
    assert_eq!(again.status, StatusCode::NOT_MODIFIED);
    assert!(again.body.is_empty());
    assert_eq!(again.header(header::ETAG), etag);
    let weak = format!("\"nope\", W/{etag}");
    assert_eq!(
        get(&app, &url, &[("if-none-match", &weak)]).await.status,
        StatusCode::NOT_MODIFIED
    );
    let other = get(&app, &url, &[("if-none-match", "\"0000\"")]).await;
    assert_eq!((other.status, &other.body), (StatusCode::OK, &first.body));

    let base = get(&app, &format!("/api/compressions/{id}/base"), &[]).await;
    assert_ne!(base.header(header::ETAG), etag);
    let base304 = get(
        &app,
        &format!("/api/compressions/{id}/base"),
        &[("if-none-match", base.header(header::ETAG))],
    )
    .await;
    assert_eq!(base304.status, StatusCode::NOT_MODIFIED);

    let metrics = String::from_utf8(get(&app, "/metrics", &[]).await.body.to_vec()).unwrap();
    assert!(
        metrics.contains("vitrine_cache_lookups_total{cache=\"payload\",result=\"hit\"} 1"),
        "{metrics}"
    );
    assert!(
        metrics.contains("vitrine_cache_lookups_total{cache=\"payload\",result=\"miss\"} 2"),
        "{metrics}"
    );
}

/// A model stored by a build with another stream format (an upgrade) is
/// refused with its reason instead of failing in the visitor's decoder,
/// left out of the list, hidden as before when restricted, and served again
/// once ingested anew.
pub async fn stale_stream_format_is_refused(db: TestDb) {
    let s = &*db.storage;
    let old = ingest_sample(s, "torus", "open")
        .await
        .stored
        .compression_id;
    let vault = ingest_sample(s, "vault", "researchers")
        .await
        .stored
        .compression_id;
    ingest_sample(s, "ring", "open").await;
    let stale = VERSION - 1;
    db.execute(&format!(
        "UPDATE compression SET codec_version = {stale} WHERE id IN ({old}, {vault})"
    ))
    .await;
    let state = AppState::new(db.storage.clone(), test_config());
    let app = app(state.clone());
    for uri in [
        "/api/models/torus".to_owned(),
        format!("/api/compressions/{old}/base"),
        format!("/api/compressions/{old}/batches/1"),
    ] {
        let r = get(&app, &uri, &[]).await;
        assert_eq!(r.status, StatusCode::CONFLICT, "{uri}");
        let body = r.json();
        assert_eq!(body["error"], "stale_format", "{uri}");
        let message = body["message"].as_str().unwrap();
        assert!(
            message.contains(&format!("stream format {stale}"))
                && message.contains(&format!("reads format {VERSION}"))
                && message.contains("ingest it again"),
            "{message}"
        );
    }
    // A restricted model stays invisible without a token, whatever its format.
    let r = get(&app, "/api/models/vault", &[]).await;
    assert_eq!(r.status, StatusCode::NOT_FOUND);
    let list = get(&app, "/api/models", &[]).await.json();
    let slugs: Vec<&str> = list["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| m["slug"].as_str().unwrap())
        .collect();
    assert_eq!(slugs, ["ring"]);
    // `vitrine models` names both stale ones, restricted or not.
    let (table, stale_count) = models_listing(s).await.unwrap();
    assert_eq!(stale_count, 2, "{table}");
    for slug in ["torus", "vault"] {
        let line = table.lines().find(|l| l.starts_with(slug)).unwrap();
        let expected = format!("{stale} (this build reads {VERSION}: ingest it again)");
        assert!(line.ends_with(&expected), "{line}");
    }
    assert!(
        table
            .lines()
            .any(|l| l.starts_with("ring") && l.ends_with(&format!("  {VERSION}"))),
        "{table}"
    );

    // Ingested again by this build: a new version, served.
    let mut meta = ModelMeta::new("torus", "Torus");
    meta.policy = "open".into();
    meta.on_existing = OnExisting::NewVersion;
    ingest_mesh(s, sample_mesh(), meta, &IngestOptions::default())
        .await
        .unwrap();
    state.invalidate();
    let r = get(&app, "/api/models/torus", &[]).await;
    assert_eq!(r.status, StatusCode::OK);
    let manifest = r.json();
    assert_eq!(manifest["version"], 2);
    let base = get(&app, manifest["levels"][0]["url"].as_str().unwrap(), &[]).await;
    assert_eq!(base.status, StatusCode::OK);
    Decoder::new(&base.body, Limits::default()).expect("the new version decodes");
    let (table, stale_count) = models_listing(s).await.unwrap();
    assert_eq!(stale_count, 1, "only the restricted one is left: {table}");
}
