//! Real answers of every route, over HTTP, against the OpenAPI description
//! the service serves at `/api/openapi.json`: each answer's status must be
//! one the description lists for its route, its media type one listed for
//! that status, and a JSON body must match the schema, tightened so that an
//! object carries no property the description does not name.

mod curators;
mod iiif;
mod texts;
mod tours;

use super::broken::{BrokenStorage, Failure};
use super::colour::tiny_mapping;
use super::harness::{
    ingest_sample, ingest_sample_with, sample_encoded, test_config, TestDb, TestServer,
};
use super::slow::SlowStorage;
use super::story::token_for;
use serde_json::{json, Value};
use std::collections::BTreeSet;
use std::sync::Arc;
use std::time::Duration;
use vitrine::ingest::{ingest_encoded, IngestOptions, ModelMeta};
use vitrine::{AppState, ServiceConfig};

/// The description, and which of its (route, status) pairs were seen.
struct Spec {
    doc: Value,
    http: reqwest::Client,
    seen: BTreeSet<(String, u16)>,
}

/// What one request should get.
struct Call<'a> {
    path: &'a str,
    headers: &'a [(&'a str, &'a str)],
    status: u16,
}

fn call<'a>(path: &'a str, status: u16) -> Call<'a> {
    Call {
        path,
        headers: &[],
        status,
    }
}

fn call_with<'a>(path: &'a str, headers: &'a [(&'a str, &'a str)], status: u16) -> Call<'a> {
    Call {
        path,
        headers,
        status,
    }
}

/// An answer that matched the description.
struct Answer {
    headers: reqwest::header::HeaderMap,
    json: Option<Value>,
}

impl Answer {
    fn json(&self) -> &Value {
        self.json.as_ref().expect("a JSON body")
    }

    fn header(&self, name: &str) -> String {
        self.headers[name].to_str().unwrap().to_owned()
    }
}

impl Spec {
    async fn fetch(server: &TestServer) -> Spec {
        let http = reqwest::Client::new();
        let reply = http.get(server.url("/api/openapi.json")).send().await;
        let doc: Value = reply.unwrap().json().await.unwrap();
        assert_eq!(doc["openapi"], "3.1.0");
        Spec {
            doc,
            http,
            seen: BTreeSet::new(),
        }
    }

    /// Sends `call` to `server` and checks the answer against the description.
    async fn check(&mut self, server: &TestServer, call: Call<'_>) -> Answer {
        let mut request = self.http.get(server.url(call.path));
        for (name, value) in call.headers {
            request = request.header(*name, *value);
        }
        self.judge("get", call.path, call.status, request).await
    }

    /// Sends `method` with an optional bearer and JSON body.
    async fn send(
        &mut self,
        server: &TestServer,
        method: &str,
        path: &str,
        bearer: Option<&str>,
        body: Option<Value>,
        status: u16,
    ) -> Answer {
        let verb = reqwest::Method::from_bytes(method.to_uppercase().as_bytes()).unwrap();
        let mut request = self.http.request(verb, server.url(path));
        if let Some(token) = bearer {
            request = request.header("authorization", format!("Bearer {token}"));
        }
        if let Some(body) = body {
            request = request.json(&body);
        }
        self.judge(method, path, status, request).await
    }

    async fn judge(
        &mut self,
        method: &str,
        path: &str,
        expected: u16,
        request: reqwest::RequestBuilder,
    ) -> Answer {
        let reply = request.send().await.unwrap();
        let status = reply.status().as_u16();
        let headers = reply.headers().clone();
        let body = reply.bytes().await.unwrap();
        let what = format!(
            "{} {path} → {status} {}",
            method.to_uppercase(),
            String::from_utf8_lossy(&body)
        );
        assert_eq!(status, expected, "{what}");
        let route = self.route_of(path);
        let described = &self.doc["paths"][&route][method]["responses"][status.to_string()];
        assert!(
            described.is_object(),
            "{route} does not describe {status}: {what}"
        );
        self.seen.insert((route.clone(), status));
        let media_type = headers.get("content-type").map(|v| {
            v.to_str()
                .unwrap()
                .split(';')
                .next()
                .unwrap()
                .trim()
                .to_owned()
        });
        let Some(media_type) = media_type else {
            assert!(described.get("content").is_none(), "no body: {what}");
            return Answer {
                headers,
                json: None,
            };
        };
        let content = &described["content"][&media_type];
        assert!(
            content.is_object(),
            "{route} {status} is not {media_type}: {what}"
        );
        let json = (media_type == "application/json").then(|| {
            let json: Value = serde_json::from_slice(&body).expect("JSON");
            self.validate(&content["schema"], &json, &what);
            json
        });
        Answer { headers, json }
    }

    /// The described route whose template matches `path`.
    fn route_of(&self, path: &str) -> String {
        let path = path.split('?').next().unwrap();
        let segments: Vec<&str> = path.split('/').collect();
        let matches: Vec<&String> = self.doc["paths"]
            .as_object()
            .unwrap()
            .keys()
            .filter(|template| {
                let parts: Vec<&str> = template.split('/').collect();
                parts.len() == segments.len()
                    && parts
                        .iter()
                        .zip(&segments)
                        .all(|(t, s)| (t.starts_with('{') && !s.is_empty()) || t == s)
            })
            .collect();
        assert_eq!(matches.len(), 1, "{path} matches {matches:?}");
        matches[0].clone()
    }

    fn validate(&self, schema: &Value, instance: &Value, what: &str) {
        let mut root = closed(schema.clone());
        root["$schema"] = json!("https://json-schema.org/draft/2020-12/schema");
        // `#/components/...` resolves against this document's root.
        root["components"] = closed(self.doc["components"].clone());
        let validator = jsonschema::validator_for(&root).expect("a valid schema");
        let errors: Vec<String> = validator
            .iter_errors(instance)
            .map(|e| format!("{} at {}", e, e.instance_path()))
            .collect();
        assert!(errors.is_empty(), "{what}\ndoes not match: {errors:#?}");
    }

    /// Every route of the description was called.
    fn assert_every_route_called(&self) {
        let called: BTreeSet<&String> = self.seen.iter().map(|(route, _)| route).collect();
        for route in self.doc["paths"].as_object().unwrap().keys() {
            assert!(called.contains(route), "{route} was never called");
        }
        let seen: Vec<String> = self.seen.iter().map(|(r, s)| format!("{s} {r}")).collect();
        eprintln!("{} route × status pairs checked: {seen:#?}", seen.len());
    }
}

/// `schema` with `additionalProperties: false` on every object schema that
/// lists properties and says nothing of others.
fn closed(mut schema: Value) -> Value {
    match &mut schema {
        Value::Object(map) => {
            for value in map.values_mut() {
                *value = closed(value.take());
            }
            if map.contains_key("properties") && !map.contains_key("additionalProperties") {
                map.insert("additionalProperties".into(), Value::Bool(false));
            }
        }
        Value::Array(items) => {
            for item in items {
                *item = closed(item.take());
            }
        }
        _ => {}
    }
    schema
}

/// The models behind the calls, one per kind of answer.
struct Models {
    /// Open policy: every level for everyone.
    open: i64,
    /// Exhibition policy: the last level only with a token.
    shown: i64,
    /// Researchers only.
    vault: i64,
    /// Stored in an older stream format.
    stale: i64,
    /// A CCC mapping: textures, public and restricted.
    textures: Vec<String>,
    hidden_textures: Vec<String>,
    last: u32,
}

impl Models {
    async fn ingest(db: &TestDb) -> Models {
        let s = &*db.storage;
        let id = |r: vitrine::ingest::IngestReport| r.stored.compression_id;
        let open = id(ingest_sample_with(s, "open", "open", Some(2)).await);
        let shown = id(ingest_sample(s, "shown", "exhibition").await);
        let vault = id(ingest_sample(s, "vault", "researchers").await);
        let stale = id(ingest_sample(s, "stale", "open").await);
        let measured = id(ingest_sample(s, "measured", "open").await);
        let painted = ingest_coloured(db, "painted", "open").await;
        let hidden = ingest_coloured(db, "hidden", "researchers").await;
        // A point cloud: its manifest has `kind` and per-level `points`.
        let mut meta = ModelMeta::new("cloud", "Cloud");
        meta.policy = "open-download".into();
        vitrine::ingest::points::ingest_points(
            s,
            vitrine::commands::sample::cloud(2000, true, 0.0),
            meta,
            &IngestOptions::default(),
        )
        .await
        .expect("ingest a point cloud");
        let stale_format = vitrine_codec::VERSION - 1;
        for sql in [
            format!("UPDATE compression SET codec_version = {stale_format} WHERE id = {stale}"),
            format!(
                "UPDATE base_mesh SET hausdorff = 0.02, rmse = 9.5, roy_rmse = 4.5 \
                 WHERE compression_id = {measured}"
            ),
            format!(
                "UPDATE refinement_batch SET hausdorff = 0.001, rmse = 1.5, roy_rmse = NULL \
                 WHERE compression_id = {measured}"
            ),
        ] {
            db.execute(&sql).await;
        }
        let texture_urls = |id: i64| async move {
            let record = s.model_by_compression(id).await.unwrap().unwrap();
            let urls: Vec<String> = record
                .textures
                .iter()
                .map(|t| format!("/api/textures/{}", t.id))
                .collect();
            assert_eq!(urls.len(), 3);
            urls
        };
        Models {
            open,
            shown,
            vault,
            stale,
            textures: texture_urls(painted).await,
            hidden_textures: texture_urls(hidden).await,
            last: vitrine_codec::StreamIndex::parse(&sample_encoded().bytes)
                .unwrap()
                .batches
                .len() as u32,
        }
    }
}

async fn ingest_coloured(db: &TestDb, slug: &str, policy: &str) -> i64 {
    let mut meta = ModelMeta::new(slug, format!("Coloured {slug}"));
    meta.policy = policy.into();
    let mapping = tiny_mapping();
    let report = ingest_encoded(
        &*db.storage,
        &sample_encoded(),
        Duration::from_millis(1),
        Some(&mapping),
        meta,
        &IngestOptions::default(),
    )
    .await
    .expect("ingest with a CCC mapping");
    report.stored.compression_id
}

fn config() -> ServiceConfig {
    let mut config = test_config();
    // Admission is checked on its own server below, and load caps only when
    // the test forces them: a busy test machine must not set one.
    config.admission.rate = 0.0;
    config.load.high_inflight = u64::MAX;
    config.load.high_latency = Duration::from_secs(3600);
    config.load.high_queue = Duration::from_secs(3600);
    config
}

pub async fn responses_match_openapi(db: TestDb) {
    let m = Models::ingest(&db).await;
    let token = token_for(&db, None).await;
    let bearer = format!("Bearer {token}");
    let with_token: &[(&str, &str)] = &[("authorization", &bearer)];
    let bad_token: &[(&str, &str)] = &[("authorization", "Bearer nope")];
    let state = AppState::new(db.storage.clone(), config());
    let server = TestServer::serve(state.clone()).await;
    let mut spec = Spec::fetch(&server).await;

    for c in [
        call("/api/openapi.json", 200),
        call("/healthz", 200),
        call("/readyz", 200),
        call("/metrics", 200),
        call("/api/models", 200),
        call_with("/api/models", with_token, 200),
        call("/api/models?device=watch", 400),
        call_with("/api/models", bad_token, 401),
        call("/", 200),
        call("/m/open", 200),
        call("/embed/open", 200),
        call("/m/Not_A_Slug", 400),
        call("/embed/missing", 404),
        call("/m/stale", 409),
        call("/api/models/open", 200),
        call("/api/models/measured", 200),
        call("/api/models/painted", 200),
        call("/api/models/cloud", 200),
        call("/m/cloud", 200),
        call("/api/models/open?device=phone", 200),
        call_with("/api/models/vault", with_token, 200),
        call("/api/models/Not_A_Slug", 400),
        call_with("/api/models/open", bad_token, 401),
        call("/api/models/missing", 404),
        call("/api/models/vault", 404),
        call("/api/models/stale", 409),
    ] {
        spec.check(&server, c).await;
    }
    payloads(&mut spec, &server, &m, with_token).await;
    textures(&mut spec, &server, &m, with_token).await;

    // Load at its highest: the cap falls to the good-enough level.
    state.load().force_pressure(Some(u8::MAX));
    let manifest = spec.check(&server, call("/api/models/open", 200)).await;
    assert_eq!(manifest.json()["cap"]["reason"], "load");
    let last = format!("/api/compressions/{}/batches/{}", m.open, m.last);
    spec.check(&server, call(&last, 429)).await;

    study_calls(&mut spec, &server, &db).await;
    download_calls(&mut spec, &server, &db).await;
    curators::curator_calls(&mut spec, &server, &db).await;
    iiif::iiif_calls(&mut spec, &server, &db).await;
    tours::tour_calls(&mut spec, &server, &db).await;
    texts::text_calls(&mut spec, &server, &db).await;
    refusals(&mut spec, &db, &m).await;
    spec.assert_every_route_called();
}

async fn payloads(spec: &mut Spec, server: &TestServer, m: &Models, with_token: &[(&str, &str)]) {
    let (open, shown, last) = (m.open, m.shown, m.last);
    let base = format!("/api/compressions/{open}/base");
    let first = format!("/api/compressions/{open}/batches/1");
    let etag = spec.check(server, call(&base, 200)).await.header("etag");
    let if_none_match: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(server, call_with(&base, if_none_match, 304))
        .await;
    let etag = spec.check(server, call(&first, 200)).await.header("etag");
    let if_none_match: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(server, call_with(&first, if_none_match, 304))
        .await;
    let shown_last = format!("/api/compressions/{shown}/batches/{last}");
    let phone_last = format!("/api/compressions/{open}/batches/{last}?device=phone");
    for c in [
        call("/api/compressions/abc/base", 400),
        call_with(&base, &[("authorization", "Bearer nope")], 401),
        call("/api/compressions/0/base", 404),
        call(&format!("/api/compressions/{}/base", m.vault), 404),
        call(&format!("/api/compressions/{}/base", m.stale), 409),
        call(&format!("/api/compressions/{open}/batches/x"), 400),
        call(&shown_last, 403),
        call_with(&shown_last, with_token, 200),
        call(&phone_last, 403),
        call(&format!("/api/compressions/{open}/batches/0"), 404),
        call(
            &format!("/api/compressions/{open}/batches/{}", last + 1),
            404,
        ),
        call(&format!("/api/compressions/{}/batches/1", m.stale), 409),
    ] {
        spec.check(server, c).await;
    }
}

async fn textures(spec: &mut Spec, server: &TestServer, m: &Models, with_token: &[(&str, &str)]) {
    for url in &m.textures {
        let etag = spec.check(server, call(url, 200)).await.header("etag");
        let if_none_match: &[(&str, &str)] = &[("if-none-match", &etag)];
        spec.check(server, call_with(url, if_none_match, 304)).await;
    }
    for url in &m.hidden_textures {
        spec.check(server, call(url, 404)).await;
        spec.check(server, call_with(url, with_token, 200)).await;
    }
    for c in [
        call("/api/textures/1%20OR%201", 400),
        call("/api/textures/999999", 404),
    ] {
        spec.check(server, c).await;
    }
}

/// The answers of a service that cannot serve: database away or broken,
/// every permit taken, a request past its timeout, a surge of visitors.
async fn refusals(spec: &mut Spec, db: &TestDb, m: &Models) {
    let base = format!("/api/compressions/{}/base", m.open);
    let batch = format!("/api/compressions/{}/batches/1", m.open);
    let texture = m.textures[0].as_str();
    let storage_routes = [
        "/api/models",
        "/api/models/open",
        &base,
        &batch,
        texture,
        "/",
        "/m/open",
        "/embed/open",
    ];
    for (failure, status) in [(Failure::Unavailable, 503), (Failure::Corrupt, 500)] {
        let broken = TestServer::start(Arc::new(BrokenStorage(failure)), config()).await;
        for path in storage_routes {
            spec.check(&broken, call(path, status)).await;
        }
        spec.check(&broken, call("/readyz", status)).await;
        spec.check(&broken, call("/healthz", 200)).await;
    }

    let mut full = config();
    full.limits.max_concurrency = 0;
    let full = TestServer::start(db.storage.clone(), full).await;
    let routes: Vec<String> = spec.doc["paths"]
        .as_object()
        .unwrap()
        .keys()
        .cloned()
        .collect();
    for route in routes {
        let path = route
            .replace("{slug}", "open")
            .replace("{id}", "1")
            .replace("{iteration}", "1")
            .replace("{step}", "1")
            .replace("{version}", "1");
        let methods: Vec<String> = spec.doc["paths"][&route]
            .as_object()
            .unwrap()
            .keys()
            .filter(|k| ["get", "post", "put"].contains(&k.as_str()))
            .cloned()
            .collect();
        for method in methods {
            let body = (method != "get").then(|| json!({}));
            spec.send(&full, &method, &path, None, body, 503).await;
        }
    }

    let mut hasty = config();
    hasty.limits.timeout = Duration::from_millis(1);
    hasty.cache.payload_bytes = 0;
    let slow = SlowStorage::new(db.storage.clone(), Duration::from_secs(1));
    let hasty = TestServer::start(slow, hasty).await;
    spec.check(&hasty, call(&base, 504)).await;

    let mut surge = config();
    surge.admission.burst = 1.0;
    surge.admission.rate = 0.01;
    let surge = TestServer::start(db.storage.clone(), surge).await;
    spec.check(&surge, call("/api/models/open", 200)).await;
    spec.check(&surge, call("/api/models/open", 503)).await;

    // Bodies over the limit (64 KiB).
    for path in ["/api/models", "/healthz"] {
        let request = spec.http.get(surge.url(path)).body(vec![b'x'; 70_000]);
        spec.judge("get", path, 413, request).await;
    }
}

/// The study's routes with an invitation of `open`'s study (T = 0, so steps
/// may be answered at once).
async fn study_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    use vitrine::storage::sha256_hex;
    use vitrine::study::{new_invitation, Transition};
    let record = db.storage.model_by_slug("open").await.unwrap().unwrap();
    let id = db
        .storage
        .create_study(record.model_id, &[Transition(0, 1), Transition(1, 2)], 0)
        .await
        .unwrap();
    let invitation = new_invitation();
    db.storage
        .insert_invitations(id, &[sha256_hex(invitation.as_bytes())], None)
        .await
        .unwrap();
    let inv = Some(invitation.as_str());
    let consent =
        json!({"consent": true, "device": "tablet", "viewport": [1024, 768], "pixel_ratio": 2.0});
    let answer = json!({"improvement": "a-little", "sufficient": true, "shown_ms": [0, 0]});
    let event = json!({"at_ms": 5.0, "step": 1, "state": "pre", "kind": "camera",
        "camera": {"eye": [0, 0, 2], "target": [0, 0, 0], "up": [0, 1, 0], "fov": 50}, "zoom": 1.5});
    // Begun, no answers yet: linked from the manifest, so not a 404.
    let results = spec
        .send(server, "get", "/api/study/open/results", None, None, 200)
        .await;
    assert_eq!(results.json()["valid_sessions"], 0);
    spec.send(server, "get", "/api/study/missing/results", None, None, 404)
        .await;
    spec.send(server, "get", "/api/study/open", None, None, 403)
        .await;
    spec.send(server, "get", "/api/study/missing", inv, None, 404)
        .await;
    spec.send(server, "get", "/api/study/Not_A_Slug", inv, None, 400)
        .await;
    let info = spec
        .send(server, "get", "/api/study/open", inv, None, 200)
        .await;
    assert_eq!(info.json()["step_count"], 3);
    spec.send(server, "get", "/api/study/open/session", inv, None, 409)
        .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session",
        inv,
        Some(json!({"consent": false, "device": "tablet", "viewport": [1, 1], "pixel_ratio": 1.0})),
        422,
    )
    .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session",
        inv,
        Some(consent.clone()),
        201,
    )
    .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session",
        inv,
        Some(consent),
        200,
    )
    .await;
    let plan = spec
        .send(server, "get", "/api/study/open/session", inv, None, 200)
        .await;
    assert_eq!(plan.json()["next_step"], 1);
    spec.send(
        server,
        "put",
        "/api/study/open/session/answers/9",
        inv,
        Some(answer.clone()),
        404,
    )
    .await;
    spec.send(
        server,
        "put",
        "/api/study/open/session/answers/2",
        inv,
        Some(answer.clone()),
        409,
    )
    .await;
    spec.send(
        server,
        "put",
        "/api/study/open/session/answers/1",
        inv,
        Some(json!({"improvement": "meh"})),
        422,
    )
    .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session/finish",
        inv,
        Some(json!({})),
        409,
    )
    .await;
    for step in 1..=3 {
        let path = format!("/api/study/open/session/answers/{step}");
        spec.send(server, "put", &path, inv, Some(answer.clone()), 201)
            .await;
    }
    spec.send(
        server,
        "put",
        "/api/study/open/session/answers/3",
        inv,
        Some(answer),
        200,
    )
    .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session/views",
        inv,
        Some(json!({"events": [event]})),
        204,
    )
    .await;
    spec.send(
        server,
        "post",
        "/api/study/open/session/views",
        inv,
        Some(json!({"events": [{"at_ms": 1.0}]})),
        422,
    )
    .await;
    let done = spec
        .send(
            server,
            "post",
            "/api/study/open/session/finish",
            inv,
            Some(json!({})),
            200,
        )
        .await;
    assert_eq!(done.json()["good_level"], 1);
    spec.send(server, "get", "/api/study/open/results", None, None, 200)
        .await;
    spec.check(server, call("/study/open", 200)).await;
    spec.check(server, call("/study/Not_A_Slug", 400)).await;
}

/// The GLB download of a level, where the policy allows it and where not.
async fn download_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    ingest_sample(&*db.storage, "handout", "open-download").await;
    let glb = spec
        .check(
            server,
            call("/api/models/handout/download.glb?level=1", 200),
        )
        .await;
    let etag = glb.header("etag");
    let revalidate: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(
        server,
        call_with("/api/models/handout/download.glb?level=1", revalidate, 304),
    )
    .await;
    spec.check(
        server,
        call("/api/models/handout/download.glb?level=x", 400),
    )
    .await;
    spec.check(
        server,
        call("/api/models/handout/download.glb?level=99", 404),
    )
    .await;
    spec.check(server, call("/api/models/open/download.glb", 403))
        .await;
    // A point cloud is no mesh: 409, whatever its policy allows.
    spec.check(server, call("/api/models/cloud/download.glb", 409))
        .await;
}
