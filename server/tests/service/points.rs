//! Issue 21: point clouds as a model kind, over real HTTP. A generated
//! cloud is ingested as a point stream; its manifest says `points` with
//! per-level counts; the header and levels, fetched on the mesh batches'
//! URLs and concatenated, decode bit for bit as the encoder's own stream;
//! caps limit the levels as they do a mesh's; GLB downloads refuse it; a
//! mesh's manifest still says `mesh`; an upload of a cloud is ingested and
//! a corrupt one fails with the importer's message and stores nothing.

use super::curators::token;
use super::harness::{ingest_sample, test_config, TestDb, TestServer};
use super::story::token_for;
use super::uploads::{form, job_until_finished, upload_config};
use reqwest::StatusCode;
use serde_json::Value;
use vitrine::commands::sample::{cloud, write_cloud_ply};
use vitrine::ingest::points::ingest_points;
use vitrine::ingest::{IngestOptions, ModelMeta};
use vitrine::storage::TokenScope;
use vitrine::AppState;
use vitrine_points::stream::{self, EncodeOptions, Limits};
use vitrine_points::PointCloud;

/// Small first level, so that the 3,000 points make several levels.
fn point_options() -> IngestOptions {
    IngestOptions {
        points: EncodeOptions {
            base_points: 64,
            ..EncodeOptions::default()
        },
        ..IngestOptions::default()
    }
}

fn sample_cloud() -> PointCloud {
    cloud(3000, true, 0.0)
}

async fn ingest_cloud(db: &TestDb, slug: &str, policy: &str, cloud: PointCloud) -> i64 {
    let mut meta = ModelMeta::new(slug, format!("Cloud {slug}"));
    meta.policy = policy.into();
    ingest_points(&*db.storage, cloud, meta, &point_options())
        .await
        .expect("ingest the cloud")
        .stored
        .compression_id
}

async fn get(
    http: &reqwest::Client,
    url: &str,
    token: Option<&str>,
) -> (StatusCode, reqwest::header::HeaderMap, Vec<u8>) {
    let mut request = http.get(url);
    if let Some(t) = token {
        request = request.bearer_auth(t);
    }
    let reply = request.send().await.unwrap();
    let (status, headers) = (reply.status(), reply.headers().clone());
    (status, headers, reply.bytes().await.unwrap().to_vec())
}

async fn json(http: &reqwest::Client, url: &str, token: Option<&str>) -> Value {
    let (status, _, body) = get(http, url, token).await;
    assert_eq!(
        status,
        StatusCode::OK,
        "{url}: {}",
        String::from_utf8_lossy(&body)
    );
    serde_json::from_slice(&body).unwrap()
}

/// Positions and normals as bit patterns, and colours.
type CloudBits = (Vec<[u32; 3]>, Vec<[u32; 3]>, Option<Vec<[u8; 3]>>);

/// Bit patterns, so that equal means bit-exact (and NaN would not hide).
fn bits(cloud: &PointCloud) -> CloudBits {
    let f = |v: &[[f32; 3]]| v.iter().map(|p| p.map(f32::to_bits)).collect::<Vec<_>>();
    (
        f(&cloud.positions),
        f(cloud.normals.as_deref().unwrap_or(&[])),
        cloud.colours.clone(),
    )
}

pub async fn points_streamed_under_caps(db: TestDb) {
    let id = ingest_cloud(&db, "cube", "exhibition", sample_cloud()).await;
    ingest_sample(&*db.storage, "torus", "open").await;
    // What the encoder itself makes of the same cloud with the same options.
    let own = stream::encode(&sample_cloud(), &point_options().points).unwrap();
    // Ingest codes attributes against the decoded neighbourhood (session 34).
    assert!(own.header.predicted_attributes);
    let counts = &own.level_points;
    let last = counts.len() - 1;
    assert!(last >= 3, "the sample needs at least 4 levels: {counts:?}");
    let mut config = test_config();
    config.caps.phone_max_vertices = counts[1];
    config.caps.tablet_max_vertices = counts[last - 1];
    let state = AppState::new(db.storage.clone(), config);
    let server = TestServer::serve(state.clone()).await;
    let http = reqwest::Client::new();
    let researcher = token_for(&db, None).await;

    // The manifest: kind, per-level counts, the mesh batches' URLs.
    let m = json(&http, &server.url("/api/models/cube"), Some(&researcher)).await;
    assert_eq!(m["kind"], "points");
    assert_eq!(m["last_level"], last);
    assert_eq!(m["quantization_bits"], own.header.bits);
    assert_eq!(m["has_colour"], true);
    assert_eq!(m["colour"]["mode"], "vertex");
    let levels = m["levels"].as_array().unwrap();
    assert_eq!(levels.len(), counts.len());
    for (k, level) in levels.iter().enumerate() {
        assert_eq!(level["level"], k);
        assert_eq!(level["points"], counts[k], "level {k}");
        assert_eq!(level["vertices"], counts[k], "level {k}");
        assert_eq!(level["faces"], 0);
        let url = if k == 0 {
            format!("/api/compressions/{id}/base")
        } else {
            format!("/api/compressions/{id}/batches/{k}")
        };
        assert_eq!(level["url"], url);
    }
    assert_eq!(
        m["cap"]["level"], last,
        "a researcher reaches the full cloud"
    );

    // A thumbnail rendered from the decoded points: a 512² PNG in which the
    // cube covers a good part of the picture, in the cloud's colours.
    let thumbnail = m["thumbnail"]
        .as_str()
        .expect("a point model has a thumbnail");
    let (status, headers, png) = get(&http, &server.url(thumbnail), Some(&researcher)).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(headers[reqwest::header::CONTENT_TYPE], "image/png");
    let image = image::load_from_memory(&png).unwrap().to_rgb8();
    assert_eq!(image.dimensions(), (512, 512));
    let covered: Vec<[u8; 3]> = image
        .pixels()
        .map(|p| p.0)
        .filter(|&p| p != [33, 36, 41])
        .collect();
    assert!(
        covered.len() > 512 * 512 / 10 && covered.len() < 512 * 512 * 9 / 10,
        "{} pixels covered",
        covered.len()
    );
    let grey = covered
        .iter()
        .filter(|p| p[0] == p[1] && p[1] == p[2])
        .count();
    assert!(grey * 2 < covered.len(), "coloured, not clay: {grey} grey");

    // Header + every level, concatenated: the encoder's stream, byte for byte,
    // and it decodes bit for bit as the encoder's own stream does.
    let mut fetched = Vec::new();
    for (k, level) in levels.iter().enumerate() {
        let url = server.url(level["url"].as_str().unwrap());
        let (status, headers, body) = get(&http, &url, Some(&researcher)).await;
        assert_eq!(status, StatusCode::OK, "level {k}");
        assert_eq!(body.len() as u64, level["bytes"].as_u64().unwrap());
        let etag = headers[reqwest::header::ETAG].to_str().unwrap().to_owned();
        assert!(etag.starts_with('"'), "a strong ETag: {etag}");
        assert!(
            headers[reqwest::header::CACHE_CONTROL]
                .to_str()
                .unwrap()
                .contains("immutable"),
            "level {k} is immutable"
        );
        let again = http
            .get(&url)
            .bearer_auth(&researcher)
            .header(reqwest::header::IF_NONE_MATCH, &etag)
            .send()
            .await
            .unwrap();
        assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
        fetched.extend_from_slice(&body);
        // Every prefix of levels is a stream of those levels.
        let prefix = stream::decode(&fetched, Some(k + 1), Limits::default()).unwrap();
        assert_eq!(prefix.point_count(), counts[k] as usize, "prefix {k}");
    }
    assert_eq!(fetched, own.bytes, "served levels are the encoder's stream");
    let served = stream::decode(&fetched, None, Limits::default()).unwrap();
    let expected = stream::decode(&own.bytes, None, Limits::default()).unwrap();
    assert!(served.is_complete());
    assert_eq!(bits(&served.to_cloud()), bits(&expected.to_cloud()));
    assert_eq!(served.quantized(), &own.quantized[..]);

    // Caps: the exhibition policy keeps the full level from the public, a
    // phone gets what its budget holds, as for a mesh.
    let batch = |k: usize| server.url(&format!("/api/compressions/{id}/batches/{k}"));
    let public = json(&http, &server.url("/api/models/cube"), None).await;
    assert_eq!(
        (
            public["cap"]["level"].as_u64(),
            public["cap"]["reason"].as_str()
        ),
        (Some(last as u64 - 1), Some("audience"))
    );
    assert_eq!(public["levels"][last]["allowed"], false);
    let (status, _, body) = get(&http, &batch(last), None).await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    let body: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(
        (body["error"].as_str(), body["reason"].as_str()),
        (Some("level_capped"), Some("audience"))
    );
    assert_eq!(get(&http, &batch(last - 1), None).await.0, StatusCode::OK);
    let phone = json(&http, &server.url("/api/models/cube?device=phone"), None).await;
    assert_eq!(
        (
            phone["cap"]["level"].as_u64(),
            phone["cap"]["reason"].as_str()
        ),
        (Some(1), Some("device"))
    );
    let (status, _, body) = get(&http, &format!("{}?device=phone", batch(2)), None).await;
    assert_eq!(status, StatusCode::FORBIDDEN);
    let body: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!(body["reason"], "device");
    let tablet = json(&http, &server.url("/api/models/cube?device=tablet"), None).await;
    assert_eq!(tablet["cap"]["level"], last - 1);
    // Load at its highest: the cap falls to the good-enough level (the
    // first with 20 % of the points), even for a researcher.
    state.load().force_pressure(Some(u8::MAX));
    let loaded = json(&http, &server.url("/api/models/cube"), Some(&researcher)).await;
    let good = counts
        .iter()
        .position(|&c| f64::from(c) >= 0.2 * f64::from(counts[last]))
        .unwrap();
    assert_eq!(loaded["good_enough_level"], good);
    assert_eq!(
        (
            loaded["cap"]["level"].as_u64(),
            loaded["cap"]["reason"].as_str()
        ),
        (Some(good as u64), Some("load"))
    );
    assert!(
        good < last,
        "the sample's good-enough level is below its last: {counts:?}"
    );
    let (status, headers, _) = get(&http, &batch(good + 1), Some(&researcher)).await;
    assert_eq!(status, StatusCode::TOO_MANY_REQUESTS);
    assert!(headers.contains_key(reqwest::header::RETRY_AFTER));
    state.load().force_pressure(None);

    // No GLB of a cloud, with a message that says why.
    let (status, _, body) = get(
        &http,
        &server.url("/api/models/cube/download.glb"),
        Some(&researcher),
    )
    .await;
    assert_eq!(status, StatusCode::CONFLICT);
    let body: Value = serde_json::from_slice(&body).unwrap();
    assert!(
        body["message"].as_str().unwrap().contains("point cloud"),
        "{body}"
    );

    // A mesh still says `mesh`, and its levels have no point counts.
    let mesh = json(&http, &server.url("/api/models/torus"), None).await;
    assert_eq!(mesh["kind"], "mesh");
    assert!(mesh["levels"][0].get("points").is_none());
    let list = json(&http, &server.url("/api/models"), None).await;
    let kinds: Vec<(&str, &str)> = list["models"]
        .as_array()
        .unwrap()
        .iter()
        .map(|m| (m["slug"].as_str().unwrap(), m["kind"].as_str().unwrap()))
        .collect();
    assert_eq!(kinds, [("cube", "points"), ("torus", "mesh")]);

    // A cloud without normals gets them at ingest, and they travel.
    let bare = PointCloud::from_positions(sample_cloud().positions);
    let bare_id = ingest_cloud(&db, "bare", "open", bare).await;
    let m = json(&http, &server.url("/api/models/bare"), None).await;
    let mut fetched = Vec::new();
    for level in m["levels"].as_array().unwrap() {
        let (status, _, body) = get(&http, &server.url(level["url"].as_str().unwrap()), None).await;
        assert_eq!(status, StatusCode::OK);
        fetched.extend_from_slice(&body);
    }
    let decoded = stream::decode(&fetched, None, Limits::default()).unwrap();
    assert!(
        decoded.header().has_normals(),
        "normals estimated at ingest"
    );
    assert!(!decoded.header().has_colours);
    assert_eq!(decoded.point_count(), 3000);
    assert_eq!(m["compression_id"], bare_id);
    server.shut_down().await;
}

/// A faceless PLY whose second point is not a number.
const BROKEN_CLOUD: &[u8] = b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\n\
property float y\nproperty float z\nend_header\n0 0 0\n1 0 banana\n0 1 0\n";

pub async fn cloud_uploads(db: TestDb) {
    let spool = tempfile::tempdir().unwrap();
    let curator = token(&db, TokenScope::Curator, None).await;
    let server = TestServer::start(db.storage.clone(), upload_config(spool.path())).await;
    let http = reqwest::Client::new();
    let upload = server.url("/api/models");
    let mut ply = Vec::new();
    write_cloud_ply(&sample_cloud(), &mut ply).unwrap();

    // A cloud PLY is ingested as a point stream.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("cube.ply", ply.clone(), "cube"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::ACCEPTED);
    let accepted: Value = reply.json().await.unwrap();
    let status_url = server.url(accepted["status_url"].as_str().unwrap());
    let done = job_until_finished(&http, &status_url, &curator).await;
    assert_eq!(done["state"], "done", "{done}");
    let m = json(&http, &server.url("/api/models/cube"), None).await;
    assert_eq!(m["kind"], "points");
    let last = m["levels"].as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["points"], 3000);

    // Sent as a mesh, it fails with a message that says what it is.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("cube.ply", ply, "forced").text("kind", "mesh"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::ACCEPTED);
    let accepted: Value = reply.json().await.unwrap();
    let failed = job_until_finished(
        &http,
        &server.url(accepted["status_url"].as_str().unwrap()),
        &curator,
    )
    .await;
    assert_eq!(failed["state"], "failed", "{failed}");
    assert!(
        failed["error"].as_str().unwrap().contains("point cloud"),
        "{failed}"
    );
    assert!(db.storage.versions("forced").await.unwrap().is_empty());

    // A corrupt cloud: a failed job with the importer's message, nothing stored.
    let reply = http
        .post(&upload)
        .bearer_auth(&curator)
        .multipart(form("broken-cloud.ply", BROKEN_CLOUD.to_vec(), "broken"))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::ACCEPTED);
    let accepted: Value = reply.json().await.unwrap();
    let failed = job_until_finished(
        &http,
        &server.url(accepted["status_url"].as_str().unwrap()),
        &curator,
    )
    .await;
    assert_eq!(failed["state"], "failed", "{failed}");
    let error = failed["error"].as_str().unwrap();
    assert!(
        error.contains("banana") && error.contains("broken-cloud.ply"),
        "not the importer's message: {error}"
    );
    assert!(
        !error.contains("vitrine-upload-"),
        "the spool file is not named: {error}"
    );
    assert!(
        db.storage.versions("broken").await.unwrap().is_empty(),
        "nothing stored"
    );
    assert_eq!(
        get(&http, &server.url("/api/models/broken"), None).await.0,
        StatusCode::NOT_FOUND
    );
    server.shut_down().await;
}
