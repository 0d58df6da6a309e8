//! CCC colour mappings (issue #5): stored with the model in one transaction,
//! offered in the manifest, served as images with strong ETags.

use super::harness::{sample_encoded, sample_mesh, test_config, TestDb};
use super::story::{get, token_for};
use axum::http::{header, StatusCode};
use glam::Vec3;
use serde_json::Value;
use std::time::Duration;
use vitrine::ingest::{ingest_encoded, ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::sha256_hex;
use vitrine::{app, AppState};
use vitrine_codec::{Decoder, Limits};
use vitrine_colour::ccc::{
    AtlasLayout, CccParameters, CccReport, CellComplex, CellTextureLayout, TextureMapping,
};
use vitrine_colour::ColourMode;
use vitrine_samples::torus;

/// A two-cube complex with one cell and two tiles: small, but every size in
/// it is consistent, as ingest checks.
pub fn tiny_mapping() -> TextureMapping {
    let parameters = CccParameters {
        version: 1,
        origin: [-1.5, -1.5, -0.5],
        cell_size: 1.5,
        dims: [2, 2, 1],
        cells: 1,
        cell_texture: CellTextureLayout {
            width: 4,
            height: 2,
            cells_offset: 4,
        },
        tile_size: 2,
        gutter: 1,
        atlas: AtlasLayout {
            width: 8,
            height: 4,
            tiles_per_row: 2,
            tiles: 2,
        },
        low_res_factor: 4,
        fallback_colour: [200, 190, 180],
    };
    let mut cells = vec![0u8; 4 * 2 * 3];
    cells[0] = 1; // cube (0, 0, 0) is cell 0
    cells[4 * 3..4 * 3 + 3].copy_from_slice(&[128, 128, 128]); // centre of projection
    cells[6 * 3] = 0b11; // faces +x and −x carry tiles 0 and 1
    cells[7 * 3..7 * 3 + 3].copy_from_slice(&[10, 20, 30]); // mean colour
    TextureMapping {
        parameters,
        cell_png: png_rgb(4, 2, &cells),
        colour_jpeg: jpeg_header(8, 4),
        colour_low_jpeg: jpeg_header(2, 1),
        report: CccReport {
            cells: 1,
            tiles: 2,
            ..CccReport::default()
        },
    }
}

/// An 8-bit RGB PNG with stored (uncompressed) deflate blocks.
pub fn png_rgb(width: u32, height: u32, rgb: &[u8]) -> Vec<u8> {
    assert_eq!(rgb.len(), (width * height * 3) as usize);
    let mut raw = Vec::new();
    for row in rgb.chunks(width as usize * 3) {
        raw.push(0); // filter: none
        raw.extend_from_slice(row);
    }
    let mut zlib = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = raw.chunks(65535).collect();
    for (k, block) in blocks.iter().enumerate() {
        zlib.push(u8::from(k + 1 == blocks.len()));
        let len = block.len() as u16;
        zlib.extend_from_slice(&len.to_le_bytes());
        zlib.extend_from_slice(&(!len).to_le_bytes());
        zlib.extend_from_slice(block);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &byte in &raw {
        a = (a + u32::from(byte)) % 65521;
        b = (b + a) % 65521;
    }
    zlib.extend_from_slice(&((b << 16) | a).to_be_bytes());
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    for (kind, data) in [(b"IHDR", ihdr), (b"IDAT", zlib), (b"IEND", Vec::new())] {
        png.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let start = png.len();
        png.extend_from_slice(kind);
        png.extend_from_slice(&data);
        let crc = crc32(&png[start..]);
        png.extend_from_slice(&crc.to_be_bytes());
    }
    png
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &byte in bytes {
        crc ^= u32::from(byte);
        for _ in 0..8 {
            crc = if crc & 1 == 1 {
                (crc >> 1) ^ 0xedb8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// Start of image, a baseline frame header and end of image: enough for the
/// size check at ingest (the service never decodes images).
pub fn jpeg_header(width: u16, height: u16) -> Vec<u8> {
    let mut j = vec![0xff, 0xd8, 0xff, 0xe0, 0, 4, b'J', b'F'];
    j.extend_from_slice(&[0xff, 0xc0, 0, 17, 8]);
    j.extend_from_slice(&height.to_be_bytes());
    j.extend_from_slice(&width.to_be_bytes());
    j.extend_from_slice(&[3, 1, 0x22, 0, 2, 0x11, 1, 3, 0x11, 1]);
    j.extend_from_slice(&[0xff, 0xd9]);
    j
}

async fn ingest_with(
    db: &TestDb,
    slug: &str,
    policy: &str,
    mapping: TextureMapping,
) -> anyhow::Result<vitrine::ingest::IngestReport> {
    let mut meta = ModelMeta::new(slug, format!("Coloured {slug}"));
    meta.policy = policy.into();
    ingest_encoded(
        &*db.storage,
        &sample_encoded(),
        Duration::from_millis(1),
        Some(&mapping),
        meta,
        &IngestOptions::default(),
    )
    .await
}

pub async fn ccc_mapping_stored_and_served(db: TestDb) {
    let mapping = tiny_mapping();
    ingest_with(&db, "painted", "exhibition", mapping.clone())
        .await
        .expect("ingest with a mapping");
    let s = &*db.storage;
    let record = s.model_by_slug("painted").await.unwrap().unwrap();
    let stored = record.mapping.as_ref().expect("mapping");
    assert_eq!(
        serde_json::from_value::<CccParameters>(stored.parameters.clone()).unwrap(),
        mapping.parameters
    );
    let roles: Vec<_> = record
        .textures
        .iter()
        .map(|t| {
            (
                t.role.as_str(),
                t.kind.as_str(),
                t.media_type.as_str(),
                t.width,
                t.height,
            )
        })
        .collect();
    assert_eq!(
        roles,
        [
            ("cell", "cell", "image/png", Some(4), Some(2)),
            ("colour", "colour", "image/jpeg", Some(8), Some(4)),
            ("colour_low", "colour", "image/jpeg", Some(2), Some(1)),
        ]
    );
    for (t, bytes) in record.textures.iter().zip([
        &mapping.cell_png,
        &mapping.colour_jpeg,
        &mapping.colour_low_jpeg,
    ]) {
        let payload = s.texture(t.id).await.unwrap().unwrap();
        assert_eq!(&payload.bytes, bytes);
        assert_eq!(payload.sha256, sha256_hex(bytes));
        assert_eq!(t.bytes, bytes.len() as u64);
        assert_eq!(payload.model_slug, "painted");
    }

    let app = app(AppState::new(db.storage.clone(), test_config()));
    let m = get(&app, "/api/models/painted", &[]).await.json();
    let colour = &m["colour"];
    assert_eq!(colour["mode"], "ccc", "{m}");
    assert_eq!(
        colour["parameters"],
        serde_json::to_value(&mapping.parameters).unwrap()
    );
    for (key, bytes, media_type) in [
        ("cell_texture", &mapping.cell_png, "image/png"),
        ("colour_texture", &mapping.colour_jpeg, "image/jpeg"),
        ("colour_texture_low", &mapping.colour_low_jpeg, "image/jpeg"),
    ] {
        let t = &colour[key];
        assert_eq!(t["bytes"], bytes.len(), "{key}");
        assert_eq!(t["media_type"], media_type, "{key}");
        let url = t["url"].as_str().unwrap();
        let reply = get(&app, url, &[]).await;
        assert_eq!(reply.status, StatusCode::OK, "{key}");
        assert_eq!(&reply.body[..], &bytes[..], "{key}");
        assert_eq!(reply.header(header::CONTENT_TYPE), media_type);
        assert_eq!(
            reply.header(header::CACHE_CONTROL),
            "public, max-age=31536000, immutable"
        );
        let etag = reply.header(header::ETAG).to_owned();
        assert_eq!(etag, format!("\"{}\"", &sha256_hex(bytes)[..32]));
        let again = get(&app, url, &[("if-none-match", &etag)]).await;
        assert_eq!(again.status, StatusCode::NOT_MODIFIED, "{key}");
        assert!(again.body.is_empty());
    }
    assert_eq!(m["textures"].as_array().unwrap().len(), 3);

    // Without a mapping: colour in the stream, or none at all.
    ingest_mesh(
        s,
        sample_mesh(),
        ModelMeta::new("vertex", "Vertex"),
        &IngestOptions::default(),
    )
    .await
    .unwrap();
    ingest_mesh(
        s,
        torus(24, 12, 1.0, 0.3),
        ModelMeta::new("clay", "Clay"),
        &IngestOptions::default(),
    )
    .await
    .unwrap();
    let metric = IngestOptions {
        colour: Some(ColourMode::VertexMetric),
        ..IngestOptions::default()
    };
    ingest_mesh(
        s,
        sample_mesh(),
        ModelMeta::new("metric", "Metric"),
        &metric,
    )
    .await
    .unwrap();
    for (slug, mode) in [("vertex", "vertex"), ("metric", "vertex"), ("clay", "none")] {
        let m = get(&app, &format!("/api/models/{slug}"), &[]).await.json();
        assert_eq!(m["colour"], serde_json::json!({ "mode": mode }), "{slug}");
        assert_eq!(m["textures"], Value::Array(vec![]));
    }
}

pub async fn restricted_textures_need_a_token(db: TestDb) {
    ingest_with(&db, "secret", "researchers", tiny_mapping())
        .await
        .unwrap();
    let record = db.storage.model_by_slug("secret").await.unwrap().unwrap();
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let url = format!("/api/textures/{}", record.textures[0].id);
    assert_eq!(get(&app, &url, &[]).await.status, StatusCode::NOT_FOUND);
    let token = token_for(&db, Some("secret")).await;
    let bearer = format!("Bearer {token}");
    let reply = get(&app, &url, &[("authorization", &bearer)]).await;
    assert_eq!(reply.status, StatusCode::OK);
    assert_eq!(
        reply.header(header::CACHE_CONTROL),
        "private, max-age=31536000, immutable"
    );
    assert_eq!(
        get(&app, "/api/textures/999999", &[]).await.status,
        StatusCode::NOT_FOUND
    );
}

pub async fn inconsistent_mappings_are_refused(db: TestDb) {
    let mut cases = Vec::new();
    let mut m = tiny_mapping();
    m.colour_low_jpeg = jpeg_header(4, 2);
    cases.push(("low-resolution colour texture is 4×2", m));
    let mut m = tiny_mapping();
    m.cell_png = png_rgb(2, 4, &[0; 24]);
    cases.push(("cell texture is 2×4", m));
    let mut m = tiny_mapping();
    m.parameters.cells = 2;
    cases.push(("cannot hold", m));
    let mut m = tiny_mapping();
    m.colour_jpeg = b"not a jpeg".to_vec();
    cases.push(("not a JPEG", m));
    let mut m = tiny_mapping();
    m.parameters.version = 2;
    cases.push(("version 2", m));
    for (want, mapping) in cases {
        let err = ingest_with(&db, "bad", "open", mapping).await.unwrap_err();
        assert!(format!("{err:#}").contains(want), "{want}: {err:#}");
    }
    // Nothing of the refused ingests is stored.
    assert!(db.storage.model_by_slug("bad").await.unwrap().is_none());
    assert!(db.storage.list_models().await.unwrap().is_empty());
}

/// `ccc` mode end to end on the painted torus: the complex is built from the
/// per-vertex colour, the stream carries none, and the colour the viewer's
/// lookup finds on the decoded surface (read back from the served images)
/// is the painted one.
pub async fn ccc_ingest_from_vertex_colour(db: TestDb) {
    let mesh = sample_mesh();
    let options = IngestOptions {
        colour: Some(ColourMode::Ccc),
        ..IngestOptions::default()
    };
    let mut meta = ModelMeta::new("ccc", "CCC");
    meta.policy = "open".into();
    let report = ingest_mesh(&*db.storage, mesh.clone(), meta, &options)
        .await
        .expect("ccc ingest");
    let ccc = report.ccc.expect("ccc report");
    assert!(ccc.cells > 0 && ccc.tiles > 0, "{ccc:?}");
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let m = get(&app, "/api/models/ccc", &[]).await.json();
    assert_eq!(m["colour"]["mode"], "ccc", "{m}");
    assert_eq!(m["has_colour"], false, "the stream carries geometry only");
    let body = |url: Value| {
        let app = app.clone();
        async move {
            let reply = get(&app, url.as_str().unwrap(), &[]).await;
            assert_eq!(reply.status, StatusCode::OK);
            reply.body.to_vec()
        }
    };
    let parameters: CccParameters =
        serde_json::from_value(m["colour"]["parameters"].clone()).unwrap();
    let cell = body(m["colour"]["cell_texture"]["url"].clone()).await;
    let colour = body(m["colour"]["colour_texture"]["url"].clone()).await;
    let low = body(m["colour"]["colour_texture_low"]["url"].clone()).await;
    let levels = m["levels"].as_array().unwrap();
    let mut decoder =
        Decoder::new(&body(levels[0]["url"].clone()).await, Limits::default()).unwrap();
    for level in &levels[1..] {
        decoder
            .apply_batch(&body(level["url"].clone()).await)
            .unwrap();
    }
    let painted = mesh.colors.as_ref().unwrap();
    for (atlas, tolerance) in [(&colour, 4.0), (&low, 20.0)] {
        let complex = CellComplex::from_images(&parameters, &cell, atlas).unwrap();
        let mut error = 0.0;
        let positions = decoder.positions();
        for p in positions.chunks(3) {
            let p = Vec3::from_slice(p);
            let found = complex.colour_at(p);
            // The painted colour of the nearest source vertex.
            let nearest = (0..mesh.positions.len())
                .min_by(|&a, &b| {
                    let d = |i: usize| Vec3::from(mesh.positions[i]).distance_squared(p);
                    d(a).total_cmp(&d(b))
                })
                .unwrap();
            error += (0..3)
                .map(|k| (found[k] * 255.0 - f32::from(painted[nearest][k])).abs())
                .sum::<f32>()
                / 3.0;
        }
        let mean = error / (positions.len() / 3) as f32;
        eprintln!(
            "mean colour error {mean:.2} of 255 ({} atlas bytes)",
            atlas.len()
        );
        assert!(mean < tolerance, "mean colour error {mean:.1} (of 255)");
    }
}
