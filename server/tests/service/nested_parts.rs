//! Nested streams (format 6, issue 41) served as charted ones are: every
//! part and split entry on its own, bit for bit the stream's, under its
//! batch's cap and cache rule; the index lists each part's phase, parent
//! and error and each split; a nested view fed from the served pieces
//! alone shows a leaf exactly as the full decoder does.

use super::harness::{test_config, TestDb};
use super::story::get;
use axum::http::{header, StatusCode};
use vitrine::ingest::{ingest_encoded, IngestOptions, ModelMeta};
use vitrine::{app, AppState};
use vitrine_codec::{
    decode, encode, nested_part_table, Charts, Decoder, EncodeOptions, Limits, NestedLayout,
    StreamIndex, NESTED_VERSION,
};
use vitrine_samples::{add_noise, torus};

pub async fn nested_parts_served_under_caps(db: TestDb) {
    let mut mesh = torus(160, 64, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 5);
    let options = EncodeOptions {
        charts: Charts::NestedShape {
            top: 2,
            fanout: 2,
            phases: 2,
        },
        ..EncodeOptions::default()
    };
    let encoded = encode(&mesh, &options).unwrap();
    assert_eq!(encoded.header.version, NESTED_VERSION);
    let stream = &encoded.bytes;
    let time = std::time::Duration::from_millis(1);
    for (slug, policy) in [("nest", "open"), ("nest-vault", "exhibition")] {
        let mut meta = ModelMeta::new(slug, format!("Sample {slug}"));
        meta.policy = policy.into();
        ingest_encoded(
            &*db.storage,
            &encoded,
            time,
            None,
            meta,
            &IngestOptions::default(),
        )
        .await
        .expect("ingest");
    }
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let (listing, stale) = vitrine::models_listing(&*db.storage).await.unwrap();
    assert_eq!(stale, 0, "{listing}");
    assert!(
        listing.ends_with(
            "; 0 charted without a part index; 0 with parts measured before their bulk error"
        ),
        "{listing}"
    );

    // The manifest leads to the index as nested_parts, not as parts (which
    // a viewer reads as flat charts).
    let manifest = get(&app, "/api/models/nest", &[]).await.json();
    assert_eq!(manifest["stream_format"], 6);
    assert!(manifest.get("parts").is_none());
    let url = manifest["nested_parts"].as_str().unwrap().to_owned();
    let id = manifest["compression_id"].as_i64().unwrap();
    let reply = get(&app, &url, &[]).await;
    assert_eq!(reply.status, StatusCode::OK);
    let index = reply.json();
    // Compressed once per coding, as the client asks: the same JSON once
    // decoded; nothing compressed for a client that asks for no coding.
    assert_eq!(reply.header(header::CONTENT_ENCODING), "");
    for (accept, coding) in [
        ("gzip, deflate, br, zstd", "br"),
        ("gzip;q=1, br;q=0", "gzip"),
    ] {
        let coded = get(&app, &url, &[("accept-encoding", accept)]).await;
        assert_eq!(coded.status, StatusCode::OK);
        assert_eq!(coded.header(header::CONTENT_ENCODING), coding, "{accept}");
        let vary = coded.header(header::VARY).to_ascii_lowercase();
        assert!(vary.contains("accept-encoding"), "{vary}");
        let mut plain = Vec::new();
        let read = if coding == "br" {
            std::io::Read::read_to_end(
                &mut brotli::Decompressor::new(&coded.body[..], 4096),
                &mut plain,
            )
        } else {
            std::io::Read::read_to_end(
                &mut flate2::read::GzDecoder::new(&coded.body[..]),
                &mut plain,
            )
        };
        read.unwrap();
        assert_eq!(plain, reply.body, "{accept}");
        assert!(coded.body.len() < reply.body.len() / 3, "{accept}");
    }
    let table = nested_part_table(stream, Limits::default()).unwrap();
    let step = f64::from(StreamIndex::parse(stream).unwrap().header.quantization.step);
    assert_eq!(
        (index["charts"].as_u64(), index["phases"].as_u64()),
        (Some(2), Some(2))
    );
    let entries = index["parts"].as_array().unwrap();
    assert_eq!(entries.len(), table.parts.len());
    for (entry, record) in entries.iter().zip(&table.parts) {
        assert_eq!(entry["level"], record.level);
        assert_eq!(entry["chart"], record.chart);
        assert_eq!(entry["phase"], record.phase);
        assert_eq!(entry["parent"].as_u64(), record.parent.map(|p| p as u64));
        assert_eq!(entry["bytes"], record.bytes.len());
        assert_eq!(entry["inserted"], record.inserted);
        let error = entry["error"].as_f64().unwrap();
        assert!((error - f64::from(record.error_steps) * step).abs() <= 1e-9 * error.max(1.0));
        let bulk = entry["bulk_error"].as_f64().unwrap();
        assert!((bulk - f64::from(record.bulk_error_steps) * step).abs() <= 1e-9 * bulk.max(1.0));
        assert!(bulk <= error, "{entry}");
    }
    let splits = index["splits"].as_array().unwrap();
    assert_eq!(splits.len(), table.splits.len());
    assert_eq!(splits.len(), 2);
    for (entry, record) in splits.iter().zip(&table.splits) {
        assert_eq!(entry["level"], record.level);
        assert_eq!(entry["parent"], record.parent);
        assert_eq!(entry["first_child"], record.children.start);
        assert_eq!(entry["children"], record.children.len());
        assert_eq!(entry["bytes"], record.bytes.len());
    }

    // Every part and split entry as served is the stream's bytes,
    // immutable, revalidated without them.
    let part_url = |level: usize, chart: usize| {
        format!("/api/compressions/{id}/batches/{level}/parts/{chart}")
    };
    let split_url = |level: usize, parent: usize| {
        format!("/api/compressions/{id}/batches/{level}/splits/{parent}")
    };
    let pieces = table
        .parts
        .iter()
        .map(|p| (part_url(p.level, p.chart), p.bytes.clone()))
        .chain(
            table
                .splits
                .iter()
                .map(|s| (split_url(s.level, s.parent), s.bytes.clone())),
        );
    for (uri, bytes) in pieces {
        let reply = get(&app, &uri, &[]).await;
        assert_eq!(reply.status, StatusCode::OK, "{uri}");
        assert_eq!(&reply.body[..], &stream[bytes], "{uri}");
        assert!(reply.header(header::CACHE_CONTROL).contains("immutable"));
        let etag = reply.header(header::ETAG).to_owned();
        assert!(etag.starts_with('"') && !etag.starts_with("W/"));
        let again = get(&app, &uri, &[("if-none-match", &etag)]).await;
        assert_eq!(again.status, StatusCode::NOT_MODIFIED, "{uri}");
    }

    // A nested view fed from the served pieces: top chart 1, split, and
    // its last child to the end, as the full decoder has that leaf.
    let first = index["first_level"].as_u64().unwrap() as usize;
    let base = get(&app, &format!("/api/compressions/{id}/base"), &[]).await;
    let mut d = Decoder::new(&base.body, Limits::default()).unwrap();
    let mut layouts: Vec<NestedLayout> = Vec::new();
    let last = d.header().batch_count();
    for level in 1..=last {
        let uri = format!("/api/compressions/{id}/batches/{level}");
        let batch = get(&app, &uri, &[]).await;
        match NestedLayout::parse(&batch.body, layouts.last()).unwrap() {
            Some(l) => layouts.push(l),
            None => d.apply_batch(&batch.body).unwrap(),
        }
    }
    assert_eq!(layouts[0].level, first);
    let head = get(&app, index["head_url"].as_str().unwrap(), &[]).await;
    assert_eq!(head.status, StatusCode::OK);
    let mut view = d.into_nested_view(&head.body, &layouts).unwrap();
    for l in layouts.iter().filter(|l| l.phase == 0) {
        let part = get(&app, &part_url(l.level, 1), &[]).await;
        view.apply_part(0, 1, &part.body).unwrap();
    }
    let split = table.splits.iter().find(|s| s.parent == 1).unwrap();
    let entry = get(&app, &split_url(split.level, 1), &[]).await;
    view.split(0, 1, &entry.body).unwrap();
    let leaf = split.children.end - 1;
    for l in layouts.iter().filter(|l| l.phase == 1) {
        let part = get(&app, &part_url(l.level, leaf), &[]).await;
        view.apply_part(1, leaf, &part.body).unwrap();
    }
    let full = decode(stream, None, Limits::default()).unwrap();
    let (ours, theirs) = (view.chart(1, leaf).unwrap(), full.chart(leaf).unwrap());
    assert!(ours.quantized == theirs.quantized && ours.indices == theirs.indices);

    // The batch's cap holds for its parts and split entries, whether or
    // not the address names one: nothing tells what a capped batch holds.
    let vault = get(&app, "/api/models/nest-vault", &[]).await.json();
    let vault_id = vault["compression_id"].as_i64().unwrap();
    for uri in [
        format!("/api/compressions/{vault_id}/batches/{last}/parts/0"),
        format!("/api/compressions/{vault_id}/batches/{last}/parts/999"),
        format!("/api/compressions/{vault_id}/batches/{last}/splits/0"),
        format!("/api/compressions/{vault_id}/batches/{last}/head"),
    ] {
        let capped = get(&app, &uri, &[]).await;
        assert_eq!(capped.status, StatusCode::FORBIDDEN, "{uri}");
        assert_eq!(capped.json()["error"], "level_capped");
    }
    let below = get(
        &app,
        &format!("/api/compressions/{vault_id}/batches/{first}/parts/0"),
        &[],
    )
    .await;
    assert_eq!(below.status, StatusCode::OK);

    // Bad addresses.
    let charts_last = table.parts.iter().filter(|p| p.level == last).count();
    for (uri, status) in [
        (part_url(last, charts_last), StatusCode::NOT_FOUND),
        (part_url(last + 1, 0), StatusCode::NOT_FOUND),
        (split_url(split.level, 2), StatusCode::NOT_FOUND),
        // The first parted batch begins phase 0: it splits nothing.
        (split_url(first, 0), StatusCode::NOT_FOUND),
        (
            format!("/api/compressions/{id}/batches/{first}/splits/x"),
            StatusCode::BAD_REQUEST,
        ),
    ] {
        let reply = get(&app, &uri, &[]).await;
        assert_eq!(reply.status, status, "{uri}");
    }
    if first > 1 {
        // A global batch has no parts and no split entries.
        assert_eq!(
            get(&app, &part_url(1, 0), &[]).await.status,
            StatusCode::NOT_FOUND
        );
        assert_eq!(
            get(&app, &split_url(1, 0), &[]).await.status,
            StatusCode::NOT_FOUND
        );
    }

    // Parts measured before their bulk error was (the column empty): the
    // listing names both models, and a service started afresh sends each
    // part's largest error as its bulk, so a viewer refines by it as then.
    db.execute("UPDATE stream_part SET bulk_error = NULL").await;
    let (listing, _) = vitrine::models_listing(&*db.storage).await.unwrap();
    assert!(
        listing.ends_with("; 2 with parts measured before their bulk error"),
        "{listing}"
    );
    assert!(listing.contains("parts without a bulk error"), "{listing}");
    let fresh = vitrine::app(AppState::new(db.storage.clone(), test_config()));
    let index = get(&fresh, &url, &[]).await.json();
    for entry in index["parts"].as_array().unwrap() {
        assert_eq!(entry["bulk_error"], entry["error"], "{entry}");
    }
}
