//! Issue 22: uploads as background jobs over real HTTP: scopes, the size
//! limit, file names that are never paths, a corrupt file, a client that
//! leaves after the 202, versions withdrawn and levels set.

use super::curators::token;
use super::harness::{eventually, test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use std::time::Duration;
use tokio::io::{AsyncReadExt, AsyncWriteExt};
use vitrine::storage::TokenScope;
use vitrine::ServiceConfig;

/// A PLY of the sample torus, as a file a curator would upload.
pub fn sample_ply() -> Vec<u8> {
    let mut bytes = Vec::new();
    vitrine_mesh::export::write_ply(&super::harness::sample_mesh(), &mut bytes).unwrap();
    bytes
}

pub fn form(file_name: &str, bytes: Vec<u8>, slug: &str) -> reqwest::multipart::Form {
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

pub fn upload_config(dir: &std::path::Path) -> ServiceConfig {
    let mut config = test_config();
    config.uploads.dir = dir.to_owned();
    config.uploads.limit_bytes = 512 * 1024;
    config
}

pub async fn job_until_finished(http: &reqwest::Client, url: &str, token: &str) -> Value {
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
    // No pooled connections: the server closes a connection whose upload it
    // refused (413) without reading it, and a reused one would fail the
    // next request with a reset rather than an answer.
    let http = reqwest::Client::builder()
        .pool_max_idle_per_host(0)
        .build()
        .unwrap();
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
    // A declared length over the limit is refused from the headers alone
    // (a raw socket: a client still writing the body could see the reset
    // of the early answer instead of the answer).
    let addr = server.base.trim_start_matches("http://").to_owned();
    let mut socket = tokio::net::TcpStream::connect(&addr).await.unwrap();
    let head = format!(
        "POST /api/models HTTP/1.1\r\nHost: {addr}\r\nAuthorization: Bearer {curator}\r\n\
         Content-Type: multipart/form-data; boundary={BOUNDARY}\r\nContent-Length: {}\r\n\r\n",
        10 << 20
    );
    socket.write_all(head.as_bytes()).await.unwrap();
    let mut first = [0u8; 12];
    socket.read_exact(&mut first).await.unwrap();
    assert_eq!(&first, b"HTTP/1.1 413");
    drop(socket);
    let big = vec![b'x'; 600 * 1024];
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
    // The model is committed (and served) a moment before its job is marked
    // done, so wait on the job itself, then check the model is there.
    let job_list = || async {
        let jobs: Value = http
            .get(server.url("/api/jobs"))
            .bearer_auth(&curator)
            .send()
            .await
            .unwrap()
            .json()
            .await
            .unwrap();
        jobs
    };
    eventually(
        Duration::from_secs(60),
        "the upload job to finish",
        || async {
            let jobs = job_list().await;
            matches!(jobs["jobs"][0]["state"].as_str(), Some("done" | "failed"))
        },
    )
    .await;
    assert_eq!(
        http.get(server.url("/api/models/vase"))
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::OK
    );
    let jobs = job_list().await;
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

    interrupted_jobs_are_said_to_be(&db, &server, &http, &curator).await;
}

/// A job whose instance stopped (no heartbeat for a minute) is served as
/// failed by any instance; a live one is not, and a heartbeat keeps it so.
async fn interrupted_jobs_are_said_to_be(
    db: &TestDb,
    server: &TestServer,
    http: &reqwest::Client,
    curator: &str,
) {
    use vitrine::storage::{JobState, NewJob};
    let new = |slug: &str| NewJob {
        slug: slug.into(),
        title: slug.into(),
        source_name: format!("{slug}.ply"),
        token_id: None,
    };
    let (dead, live, done) = (
        db.storage.insert_job(&new("dead")).await.unwrap(),
        db.storage.insert_job(&new("live")).await.unwrap(),
        db.storage.insert_job(&new("done")).await.unwrap(),
    );
    for id in [dead.id, live.id] {
        db.storage
            .update_job(id, JobState::Running, 0.4, "encoding", None, None)
            .await
            .unwrap();
    }
    db.storage
        .update_job(done.id, JobState::Done, 1.0, "done", None, Some(1))
        .await
        .unwrap();
    // Every row's clock two minutes back, as if no instance had touched them.
    let backdate =
        "UPDATE ingest_job SET updated_at = updated_at - 120000 WHERE id IN ($1, $2, $3)";
    if db.url.starts_with("sqlite:") {
        let pool = sqlx::SqlitePool::connect(&db.url).await.unwrap();
        sqlx::query(backdate)
            .bind(dead.id)
            .bind(live.id)
            .bind(done.id)
            .execute(&pool)
            .await
            .unwrap();
    } else {
        let pool = sqlx::PgPool::connect(&db.url).await.unwrap();
        sqlx::query(backdate)
            .bind(dead.id)
            .bind(live.id)
            .bind(done.id)
            .execute(&pool)
            .await
            .unwrap();
    }
    // The live job's instance beats; the others' do not (a done job's
    // row does not change).
    db.storage.touch_job(live.id).await.unwrap();
    db.storage.touch_job(done.id).await.unwrap();
    let get = |id: i64| {
        let url = server.url(&format!("/api/jobs/{id}"));
        async move {
            http.get(&url)
                .bearer_auth(curator)
                .send()
                .await
                .unwrap()
                .json::<Value>()
                .await
                .unwrap()
        }
    };
    let dead_now = get(dead.id).await;
    assert_eq!(dead_now["state"], "failed", "{dead_now}");
    assert!(
        dead_now["error"]
            .as_str()
            .unwrap()
            .starts_with("interrupted"),
        "{dead_now}"
    );
    let live_now = get(live.id).await;
    assert_eq!(live_now["state"], "running", "{live_now}");
    assert_eq!(live_now["stage"], "encoding");
    let done_now = get(done.id).await;
    assert_eq!(done_now["state"], "done", "{done_now}");
    assert_eq!(done_now["error"], Value::Null);
    let list: Value = http
        .get(server.url("/api/jobs"))
        .bearer_auth(curator)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    let listed = |id: i64| {
        list["jobs"]
            .as_array()
            .unwrap()
            .iter()
            .find(|j| j["id"] == id)
            .cloned()
            .unwrap()
    };
    assert_eq!(listed(dead.id)["state"], "failed");
    assert_eq!(listed(live.id)["state"], "running");
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
