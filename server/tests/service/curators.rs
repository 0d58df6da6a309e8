//! Issue 22 over real HTTP: token scopes, annotations (sanitised Markdown),
//! uploads as background jobs (size limit, corrupt files, a client that
//! leaves), versions, thumbnails with ETags, and the manifest's up axis,
//! unit, bounds and per-level Hausdorff distance.

use super::harness::{eventually, ingest_sample, test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use vitrine::commands::token::new_token;
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta, SourceInfo};
use vitrine::storage::{sha256_hex, NewToken, TokenScope, UpAxis};
use vitrine::ServiceConfig;
use vitrine_codec::{Decoder, Limits};

pub async fn token(db: &TestDb, scope: TokenScope, slug: Option<&str>) -> String {
    let token = new_token();
    let new = NewToken {
        token_sha256: sha256_hex(token.as_bytes()),
        scope,
        label: "test".into(),
        model_slug: slug.map(str::to_owned),
        expires_at_ms: None,
    };
    db.storage.insert_token(&new).await.unwrap();
    token
}

fn annotation(text: &str) -> Value {
    json!({
        "title": "Tool mark",
        "text": text,
        "position": [0.5, 0.25, -1.0],
        "normal": [0.0, 0.0, 2.0],
        "view": { "yaw": 0.5, "pitch": 0.1, "distance": 3.0 }
    })
}

pub async fn annotations_and_scopes(db: TestDb) {
    ingest_sample(&*db.storage, "torus", "open").await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let other_model = token(&db, TokenScope::Curator, Some("elsewhere")).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let url = server.url("/api/models/torus/annotations");

    let empty: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
    assert_eq!(empty, json!([]));

    let body = annotation("Chisel *marks* <script>alert('x')</script> [link](javascript:alert(1))");
    let post = |t: Option<&str>| {
        let mut r = http.post(&url).json(&body);
        if let Some(t) = t {
            r = r.bearer_auth(t);
        }
        r.send()
    };
    let no_token = post(None).await.unwrap();
    assert_eq!(no_token.status(), StatusCode::UNAUTHORIZED);
    assert_eq!(no_token.headers()["www-authenticate"], "Bearer");
    assert_eq!(
        post(Some("vtr_unknown")).await.unwrap().status(),
        StatusCode::UNAUTHORIZED
    );
    let refused = post(Some(&researcher)).await.unwrap();
    assert_eq!(refused.status(), StatusCode::FORBIDDEN);
    let message: Value = refused.json().await.unwrap();
    assert!(
        message["message"].as_str().unwrap().contains("curator"),
        "{message}"
    );
    assert_eq!(
        post(Some(&other_model)).await.unwrap().status(),
        StatusCode::FORBIDDEN
    );

    let created = post(Some(&curator)).await.unwrap();
    assert_eq!(created.status(), StatusCode::CREATED);
    let created: Value = created.json().await.unwrap();
    let html = created["html"].as_str().unwrap();
    assert!(html.contains("<em>marks</em>"), "{html}");
    for bad in ["<script", "alert(", "javascript:"] {
        assert!(!html.to_ascii_lowercase().contains(bad), "{bad} in {html}");
    }
    assert!(
        created["text"].as_str().unwrap().contains("<script>"),
        "the source is kept"
    );
    assert_eq!(
        created["normal"],
        json!([0.0, 0.0, 1.0]),
        "stored normalised"
    );
    assert_eq!(created["position"], json!([0.5, 0.25, -1.0]));
    assert_eq!(created["view"]["yaw"], 0.5);
    let id = created["id"].as_i64().unwrap();

    // Validation: 422 with a message; unknown model 404.
    for (change, needle) in [
        (json!({"normal": [0.0, 0.0, 0.0]}), "normal"),
        (json!({"title": "x".repeat(201)}), "title"),
        (json!({"title": "  "}), "title"),
        (json!({"position": [1.0, "a", 2.0]}), "position"),
        (json!({"view": [1, 2]}), "view"),
        (json!({"text": "y".repeat(10_001)}), "text"),
    ] {
        let mut bad = annotation("ok");
        for (k, v) in change.as_object().unwrap() {
            bad[k] = v.clone();
        }
        let reply = http
            .post(&url)
            .bearer_auth(&curator)
            .json(&bad)
            .send()
            .await
            .unwrap();
        assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY, "{change}");
        let body: Value = reply.json().await.unwrap();
        assert!(
            body["message"].as_str().unwrap().contains(needle),
            "{change}: {body}"
        );
    }
    let unknown = http
        .post(server.url("/api/models/nowhere/annotations"))
        .bearer_auth(&curator)
        .json(&body)
        .send()
        .await
        .unwrap();
    assert_eq!(unknown.status(), StatusCode::NOT_FOUND);

    // Replace, list, delete.
    let one = server.url(&format!("/api/models/torus/annotations/{id}"));
    let mut changed = annotation("Now **bold**");
    changed["view"] = Value::Null;
    let put = http.put(&one).json(&changed).send().await.unwrap();
    assert_eq!(put.status(), StatusCode::UNAUTHORIZED);
    let put = http
        .put(&one)
        .bearer_auth(&researcher)
        .json(&changed)
        .send()
        .await
        .unwrap();
    assert_eq!(put.status(), StatusCode::FORBIDDEN);
    let put: Value = http
        .put(&one)
        .bearer_auth(&curator)
        .json(&changed)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(put["html"], "<p>Now <strong>bold</strong></p>\n");
    assert_eq!(put["view"], Value::Null);
    assert!(put["updated_at"].as_i64() >= put["created_at"].as_i64());
    let listed: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
    assert_eq!(listed.as_array().unwrap().len(), 1);
    assert_eq!(listed[0]["id"], id);
    assert_eq!(listed[0]["html"], put["html"]);
    let missing = server.url(&format!("/api/models/torus/annotations/{}", id + 1000));
    let put = http
        .put(&missing)
        .bearer_auth(&curator)
        .json(&changed)
        .send()
        .await
        .unwrap();
    assert_eq!(put.status(), StatusCode::NOT_FOUND);
    let delete = http
        .delete(&one)
        .bearer_auth(&researcher)
        .send()
        .await
        .unwrap();
    assert_eq!(delete.status(), StatusCode::FORBIDDEN);
    let delete = http
        .delete(&one)
        .bearer_auth(&curator)
        .send()
        .await
        .unwrap();
    assert_eq!(delete.status(), StatusCode::NO_CONTENT);
    let delete = http
        .delete(&one)
        .bearer_auth(&curator)
        .send()
        .await
        .unwrap();
    assert_eq!(delete.status(), StatusCode::NOT_FOUND);
    let empty: Value = http.get(&url).send().await.unwrap().json().await.unwrap();
    assert_eq!(empty, json!([]));

    // A curator token does not open researcher-only models (separate scopes).
    ingest_sample(&*db.storage, "hidden", "researchers").await;
    server_check_scope(&server, &http, &curator, &researcher).await;
}

async fn server_check_scope(
    server: &TestServer,
    http: &reqwest::Client,
    curator: &str,
    researcher: &str,
) {
    let manifest = server.url("/api/models/hidden");
    let as_curator = http
        .get(&manifest)
        .bearer_auth(curator)
        .send()
        .await
        .unwrap();
    assert_eq!(as_curator.status(), StatusCode::NOT_FOUND);
    let as_researcher = http
        .get(&manifest)
        .bearer_auth(researcher)
        .send()
        .await
        .unwrap();
    assert_eq!(as_researcher.status(), StatusCode::OK);
}

/// A PLY of the sample torus, as a file a curator would upload.
fn sample_ply() -> Vec<u8> {
    let mut bytes = Vec::new();
    vitrine_mesh::export::write_ply(&super::harness::sample_mesh(), &mut bytes).unwrap();
    bytes
}

fn form(file_name: &str, bytes: Vec<u8>, slug: &str) -> reqwest::multipart::Form {
    reqwest::multipart::Form::new()
        .text("slug", slug.to_owned())
        .text("title", format!("Uploaded {slug}"))
        .text("description", "Sent through the API")
        .text("policy", "open")
        .part(
            "file",
            reqwest::multipart::Part::bytes(bytes).file_name(file_name.to_owned()),
        )
}

fn upload_config(dir: &std::path::Path) -> ServiceConfig {
    let mut config = test_config();
    config.uploads.dir = dir.to_owned();
    config.uploads.limit_bytes = 512 * 1024;
    config
}

async fn job_until_finished(http: &reqwest::Client, url: &str, token: &str) -> Value {
    let mut last = Value::Null;
    for _ in 0..1500 {
        last = http
            .get(url)
            .bearer_auth(token)
            .send()
            .await
            .unwrap()
            .json()
            .await
            .unwrap();
        if matches!(last["state"].as_str(), Some("done" | "failed")) {
            return last;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    panic!("job never finished: {last}");
}

pub async fn uploads_as_jobs(db: TestDb) {
    let spool = tempfile::tempdir().unwrap();
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let server = TestServer::start(db.storage.clone(), upload_config(spool.path())).await;
    let http = reqwest::Client::new();
    let upload = server.url("/api/models");

    // Scopes.
    let reply = http
        .post(&upload)
        .multipart(form("t.ply", sample_ply(), "t"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNAUTHORIZED);
    let reply = http
        .post(&upload)
        .bearer_auth(&researcher)
        .multipart(form("t.ply", sample_ply(), "t"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::FORBIDDEN);

    // Over the limit: 413, whether the length is declared or streamed.
    let big = vec![b'x'; 600 * 1024];
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("big.ply", big.clone(), "big"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::PAYLOAD_TOO_LARGE);
    let chunks: Vec<Result<Vec<u8>, std::io::Error>> =
        big.chunks(64 * 1024).map(|c| Ok(c.to_vec())).collect();
    let streamed =
        reqwest::multipart::Part::stream(reqwest::Body::wrap_stream(futures_util_stream(chunks)))
            .file_name("big.ply");
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(
            reqwest::multipart::Form::new()
                .text("slug", "big")
                .text("title", "Big")
                .part("file", streamed),
        )
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::PAYLOAD_TOO_LARGE);
    // A name that is a path is refused for its extension, never used.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("../../etc/passwd", sample_ply(), "t"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);

    // A corrupt file: a failed job with the importer's message, nothing stored.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("broken.ply", BROKEN_PLY.to_vec(), "broken"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::ACCEPTED);
    let accepted: Value = reply.json().await.unwrap();
    let status_url = server.url(accepted["status_url"].as_str().unwrap());
    let failed = job_until_finished(&http, &status_url, &curator).await;
    assert_eq!(failed["state"], "failed", "{failed}");
    let error = failed["error"].as_str().unwrap();
    assert!(
        error.contains("bad number \"banana\"") && error.contains("broken.ply"),
        "not the importer's message: {error}"
    );
    assert!(
        !error.contains("vitrine-upload-"),
        "the spool file is not named: {error}"
    );
    assert_eq!(failed["source_name"], "broken.ply");
    assert!(
        db.storage.versions("broken").await.unwrap().is_empty(),
        "nothing stored"
    );
    assert_eq!(
        http.get(server.url("/api/models/broken"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::NOT_FOUND
    );

    // A job that outlives its client: the request is written on a raw
    // socket, which is dropped as soon as the 202's status line arrives.
    let body = form_bytes("vase.ply", &sample_ply(), "vase");
    let addr = server.base.trim_start_matches("http://").to_owned();
    let mut socket = tokio::net::TcpStream::connect(&addr).await.unwrap();
    let head = format!(
        "POST /api/models HTTP/1.1\r\nHost: {addr}\r\nAuthorization: Bearer {curator}\r\n\
         Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {}\r\n\r\n",
        body.len()
    );
    socket.write_all(head.as_bytes()).await.unwrap();
    socket.write_all(&body).await.unwrap();
    let mut first = [0u8; 12];
    socket.read_exact(&mut first).await.unwrap();
    assert_eq!(&first, b"HTTP/1.1 202");
    drop(socket);
    eventually(Duration::from_secs(60), "the uploaded model", || async {
        http.get(server.url("/api/models/vase"))
            .send()
            .await
            .unwrap()
            .status()
            == StatusCode::OK
    })
    .await;
    let jobs: Value = http
        .get(server.url("/api/jobs"))
        .bearer_auth(&curator)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    let vase = &jobs["jobs"][0];
    assert_eq!(vase["slug"], "vase");
    assert_eq!(vase["state"], "done", "{vase}");
    assert_eq!(vase["progress"], 1.0);
    assert_eq!(vase["model_version"], 1);
    assert_eq!(jobs["jobs"][1]["state"], "failed");
    assert_eq!(
        http.get(server.url("/api/jobs"))
            .bearer_auth(&researcher)
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::FORBIDDEN
    );
    let manifest: Value = http
        .get(server.url("/api/models/vase"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(manifest["title"], "Uploaded vase");
    assert_eq!(manifest["description"], "Sent through the API");
    assert!(manifest["thumbnail"].is_string());
    assert!(
        std::fs::read_dir(spool.path()).unwrap().next().is_none(),
        "spooled uploads are removed"
    );

    // Versions: a second upload adds version 2; withdraw it, set a level.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("vase.PLY", sample_ply(), "vase"))
        .send()
        .await
        .unwrap();
    let accepted: Value = reply.json().await.unwrap();
    let done = job_until_finished(
        &http,
        &server.url(accepted["status_url"].as_str().unwrap()),
        &curator,
    )
    .await;
    assert_eq!(done["model_version"], 2, "{done}");
    let versions_url = server.url("/api/admin/models/vase/versions");
    let versions: Value = http
        .get(&versions_url)
        .bearer_auth(&curator)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(versions["versions"][0]["version"], 2);
    assert_eq!(versions["versions"][1]["version"], 1);
    let v2 = server.url("/api/admin/models/vase/versions/2");
    let withdrawn: Value = http
        .put(&v2)
        .bearer_auth(&curator)
        .json(&json!({"status": "withdrawn"}))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(withdrawn["status"], "withdrawn");
    let manifest: Value = http
        .get(server.url("/api/models/vase"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(
        manifest["version"], 1,
        "the withdrawn version is no longer served"
    );
    let v1 = server.url("/api/admin/models/vase/versions/1");
    let set: Value = http
        .put(&v1)
        .bearer_auth(&curator)
        .json(&json!({"good_enough_level": 2}))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(set["good_enough_level"], 2);
    assert_eq!(set["status"], "ready");
    let manifest: Value = http
        .get(server.url("/api/models/vase"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(manifest["good_enough_level"], 2);
    let past = http
        .put(&v1)
        .bearer_auth(&curator)
        .json(&json!({"good_enough_level": 99}))
        .send()
        .await
        .unwrap();
    assert_eq!(past.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let as_researcher = http
        .put(&v1)
        .bearer_auth(&researcher)
        .json(&json!({"status": "withdrawn"}))
        .send()
        .await
        .unwrap();
    assert_eq!(as_researcher.status(), StatusCode::FORBIDDEN);
}

/// A PLY whose second vertex has a word for a coordinate.
const BROKEN_PLY: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\n\
end_header\n0 0 0\n1 0 banana\n0 1 0\n3 0 1 2\n";

const BOUNDARY: &str = "vitrine-test-boundary";

/// A multipart body written by hand, for the raw-socket client.
fn form_bytes(file_name: &str, file: &[u8], slug: &str) -> Vec<u8> {
    let mut body = Vec::new();
    for (name, value) in [
        ("slug", slug),
        ("title", "Uploaded vase"),
        ("description", "Sent through the API"),
        ("policy", "open"),
    ] {
        body.extend_from_slice(
            format!("--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"{name}\"\r\n\r\n{value}\r\n").as_bytes(),
        );
    }
    body.extend_from_slice(
        format!(
            "--{BOUNDARY}\r\nContent-Disposition: form-data; name=\"file\"; filename=\"{file_name}\"\r\n\
             Content-Type: application/octet-stream\r\n\r\n"
        )
        .as_bytes(),
    );
    body.extend_from_slice(file);
    body.extend_from_slice(format!("\r\n--{BOUNDARY}--\r\n").as_bytes());
    body
}

/// A stream of ready chunks: a body sent without a declared length.
fn futures_util_stream(
    chunks: Vec<Result<Vec<u8>, std::io::Error>>,
) -> impl futures_util::Stream<Item = Result<Vec<u8>, std::io::Error>> + Send + Sync + 'static {
    futures_util::stream::iter(chunks)
}

/// A Z-up sample: a sphere three times taller along z than across.
fn z_up_sample() -> vitrine_codec::IndexedMesh {
    let mut mesh = vitrine_samples::icosphere(3);
    for p in &mut mesh.positions {
        p[2] *= 3.0;
    }
    mesh
}

pub async fn curation_in_manifest_and_thumbnail(db: TestDb) {
    // Given --up z and a unit.
    let mut meta = ModelMeta::new("stele", "Stele");
    meta.up = Some(UpAxis::Z);
    meta.unit = Some("mm".into());
    meta.policy = "open".into();
    let report = ingest_mesh(&*db.storage, z_up_sample(), meta, &IngestOptions::default())
        .await
        .unwrap();
    // Detected: a PLY taller along z than y is Z-up; a GLB is Y-up by its spec.
    let mut detected = ModelMeta::new("stele-ply", "Stele (detected)");
    detected.source = Some(SourceInfo {
        name: "stele.ply".into(),
        vertices: 0,
        faces: 0,
        repair: None,
    });
    ingest_mesh(
        &*db.storage,
        z_up_sample(),
        detected,
        &IngestOptions::default(),
    )
    .await
    .unwrap();
    let mut glb = ModelMeta::new("stele-glb", "Stele (glb)");
    glb.source = Some(SourceInfo {
        name: "stele.glb".into(),
        vertices: 0,
        faces: 0,
        repair: None,
    });
    ingest_mesh(&*db.storage, z_up_sample(), glb, &IngestOptions::default())
        .await
        .unwrap();
    // Bad units never reach the database.
    let mut bad = ModelMeta::new("bad-unit", "Bad");
    bad.unit = Some("furlong".into());
    let error = ingest_mesh(&*db.storage, z_up_sample(), bad, &IngestOptions::default())
        .await
        .unwrap_err();
    assert!(format!("{error:#}").contains("unit"), "{error:#}");

    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let get = |path: &str| http.get(server.url(path)).send();
    let m: Value = get("/api/models/stele")
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(m["up"], "z");
    assert_eq!(m["unit"], "mm");
    let d: Value = get("/api/models/stele-ply")
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(d["up"], "z");
    assert_eq!(d["unit"], Value::Null);
    let g: Value = get("/api/models/stele-glb")
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(g["up"], "y");

    // Bounds are the decoded positions' (model coordinates of the stream).
    let stream = db
        .storage
        .base_payload(report.stored.compression_id)
        .await
        .unwrap()
        .unwrap();
    let mut decoder = Decoder::new(&stream, Limits::default()).unwrap();
    for k in 1..m["levels"].as_array().unwrap().len() {
        let batch = db
            .storage
            .batch_payload(report.stored.compression_id, k as u32)
            .await
            .unwrap()
            .unwrap();
        decoder.apply_batch(&batch).unwrap();
    }
    let full = decoder.to_mesh();
    for axis in 0..3 {
        let lo = full
            .positions
            .iter()
            .map(|p| f64::from(p[axis]))
            .fold(f64::INFINITY, f64::min);
        let hi = full
            .positions
            .iter()
            .map(|p| f64::from(p[axis]))
            .fold(f64::NEG_INFINITY, f64::max);
        assert_eq!(
            m["bounds"]["min"][axis].as_f64().unwrap().to_bits(),
            lo.to_bits()
        );
        assert_eq!(
            m["bounds"]["max"][axis].as_f64().unwrap().to_bits(),
            hi.to_bits()
        );
    }
    assert!(
        (m["bounds"]["max"][2].as_f64().unwrap() - 3.0).abs() < 0.01,
        "{}",
        m["bounds"]
    );

    // Every level has its Hausdorff distance without --quality, falling
    // toward the quantization error at the last level.
    let levels = m["levels"].as_array().unwrap();
    let h: Vec<f64> = levels
        .iter()
        .map(|l| l["hausdorff"].as_f64().expect("measured"))
        .collect();
    assert!(h[0] > 10.0 * h[h.len() - 1], "{h:?}");
    assert!(h[h.len() - 1] < 1e-3, "{h:?}");
    assert!(m.get("quality").is_none(), "the full curve needs --quality");

    // Thumbnail: listed, a PNG with a strong ETag, 304 on If-None-Match.
    let list: Value = get("/api/models").await.unwrap().json().await.unwrap();
    let listed = list["models"]
        .as_array()
        .unwrap()
        .iter()
        .find(|x| x["slug"] == "stele")
        .unwrap()
        .clone();
    assert_eq!(listed["thumbnail"], "/api/models/stele/thumbnail?v=1");
    assert_eq!(m["thumbnail"], listed["thumbnail"]);
    let png = get(listed["thumbnail"].as_str().unwrap()).await.unwrap();
    assert_eq!(png.status(), StatusCode::OK);
    assert_eq!(png.headers()["content-type"], "image/png");
    let etag = png.headers()["etag"].to_str().unwrap().to_owned();
    let bytes = png.bytes().await.unwrap();
    assert_eq!(etag, format!("\"{}\"", sha256_hex(&bytes)));
    let image = image::load_from_memory(&bytes).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (512, 512));
    let again = http
        .get(server.url("/api/models/stele/thumbnail"))
        .header("if-none-match", &etag)
        .send()
        .await
        .unwrap();
    assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
    assert_eq!(again.headers()["etag"].to_str().unwrap(), etag);

    // The model page shares it: og:image is absolute, from the Host.
    let page = get("/m/stele").await.unwrap().text().await.unwrap();
    let host = server.base.trim_start_matches("http://");
    assert!(
        page.contains(&format!(
            "<meta property=\"og:image\" content=\"http://{host}/api/models/stele/thumbnail?v=1\">"
        )),
        "{page}"
    );
    assert!(
        page.contains("<meta property=\"og:title\" content=\"Stele\">"),
        "{page}"
    );
}
