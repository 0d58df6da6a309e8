//! `GET /api/models/{slug}/download.glb` (issue 19): a level within the
//! visitor's cap as GLB, where the policy allows downloads; the file holds
//! exactly the decoder's mesh of that level.

use super::harness::{ingest_sample, sample_encoded, test_config, TestDb};
use super::story::get;
use axum::http::{header, StatusCode};
use vitrine::{app, AppState};
use vitrine_codec::{decode, Limits};
use vitrine_mesh::import::{import_bytes, ImportOptions, MeshFormat};

pub async fn glb_download_of_a_level(db: TestDb) {
    ingest_sample(&*db.storage, "shared", "open-download").await;
    ingest_sample(&*db.storage, "expo", "exhibition-download").await;
    ingest_sample(&*db.storage, "kept", "open").await;
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let encoded = sample_encoded();
    let last = decode(&encoded.bytes, None, Limits::default())
        .unwrap()
        .header()
        .batch_count();

    for level in [0, 2, last] {
        let reply = get(
            &app,
            &format!("/api/models/shared/download.glb?level={level}"),
            &[],
        )
        .await;
        assert_eq!(reply.status, StatusCode::OK, "level {level}");
        assert_eq!(reply.header(header::CONTENT_TYPE), "model/gltf-binary");
        assert_eq!(
            reply.header(header::CONTENT_DISPOSITION),
            format!("attachment; filename=\"shared-level-{level}.glb\"")
        );
        assert!(reply.header(header::CACHE_CONTROL).starts_with("public"));
        // Exactly the decoder's level: positions bit for bit, the same faces.
        let expected = decode(&encoded.bytes, Some(level), Limits::default())
            .unwrap()
            .to_mesh();
        let options = ImportOptions::default();
        let got = import_bytes(&reply.body, MeshFormat::Glb, &options).unwrap();
        assert_eq!(got.positions.len(), expected.positions.len());
        let bits = |m: &vitrine_codec::IndexedMesh| -> Vec<[u32; 3]> {
            m.positions.iter().map(|p| p.map(f32::to_bits)).collect()
        };
        assert_eq!(bits(&got), bits(&expected), "level {level}");
        assert_eq!(got.triangles, expected.triangles);
        assert_valid_glb(&reply.body);
        // Revalidation without decoding again.
        let etag = reply.header(header::ETAG).to_owned();
        let again = get(
            &app,
            &format!("/api/models/shared/download.glb?level={level}"),
            &[("if-none-match", &etag)],
        )
        .await;
        assert_eq!(again.status, StatusCode::NOT_MODIFIED);
    }
    // Without ?level=, the visitor's cap: the exhibition's public visitor
    // gets the level below the full one, and not the full one.
    let capped = get(&app, "/api/models/expo/download.glb", &[]).await;
    assert_eq!(capped.status, StatusCode::OK);
    assert_eq!(
        capped.header(header::CONTENT_DISPOSITION),
        format!("attachment; filename=\"expo-level-{}.glb\"", last - 1)
    );
    let refused = get(
        &app,
        &format!("/api/models/expo/download.glb?level={last}"),
        &[],
    )
    .await;
    assert_eq!(refused.status, StatusCode::FORBIDDEN);
    assert_eq!(refused.json()["error"], "level_capped");
    // A policy without downloads; bad levels.
    let off = get(&app, "/api/models/kept/download.glb", &[]).await;
    assert_eq!(off.status, StatusCode::FORBIDDEN);
    assert_eq!(off.json()["error"], "not_allowed");
    let past = get(
        &app,
        &format!("/api/models/shared/download.glb?level={}", last + 1),
        &[],
    )
    .await;
    assert_eq!(past.status, StatusCode::NOT_FOUND);
    let bad = get(&app, "/api/models/shared/download.glb?level=two", &[]).await;
    assert_eq!(bad.status, StatusCode::BAD_REQUEST);
}

/// The Khronos glTF validator (npm `gltf-validator`, through
/// web/scripts/validate-gltf.mjs) finds no error in `glb`.
pub fn assert_valid_glb(glb: &[u8]) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    assert!(
        root.join("web/node_modules/gltf-validator").exists(),
        "web/node_modules/gltf-validator is missing: run `npm ci` in web/ (scripts/setup.sh does)"
    );
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("level.glb");
    std::fs::write(&file, glb).unwrap();
    let out = std::process::Command::new("node")
        .arg(root.join("web/scripts/validate-gltf.mjs"))
        .arg(&file)
        .output()
        .expect("node runs (needed for the glTF validator)");
    let report = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "glTF validator: {report}");
    let line: serde_json::Value = serde_json::from_str(report.trim()).unwrap();
    assert_eq!(line["errors"], 0, "{line}");
}
