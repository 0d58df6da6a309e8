//! Issue 22: what ingest records beside the stream, as served: the up axis
//! (given and detected), the unit, the bounds, every level's sampled
//! Hausdorff distance, the thumbnail (ETag, 304) and the model page's
//! Open Graph tags.

use super::harness::{test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::Value;
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta, SourceInfo};
use vitrine::storage::{sha256_hex, UpAxis};
use vitrine_codec::{Decoder, Limits};

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
    // --no-hausdorff: bounds and thumbnail, no distances.
    let fast = IngestOptions {
        skip_hausdorff: true,
        ..IngestOptions::default()
    };
    ingest_mesh(
        &*db.storage,
        z_up_sample(),
        ModelMeta::new("stele-fast", "Fast"),
        &fast,
    )
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
