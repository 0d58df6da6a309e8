//! Parts as the unit of streaming (issue 41): a charted stream's parts
//! served one by one, bit for bit the stream's, under the batch's cap and
//! cache rule, with the error each removes; a view decoder fed from the
//! served pieces alone shows a chart exactly as the full decoder does.

use super::harness::{test_config, TestDb};
use super::story::get;
use axum::http::{header, StatusCode};
use vitrine::ingest::{ingest_encoded, IngestOptions, ModelMeta};
use vitrine::{app, AppState};
use vitrine_codec::{
    decode, encode, part_table, Charts, Decoder, EncodeOptions, Limits, PartedLayout, StreamIndex,
};
use vitrine_samples::{add_noise, paint, torus};

pub async fn parts_served_under_caps(db: TestDb) {
    let mut mesh = torus(120, 50, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 5);
    paint(&mut mesh);
    let options = EncodeOptions {
        charts: Charts::Count(4),
        ..EncodeOptions::default()
    };
    let encoded = encode(&mesh, &options).unwrap();
    let plain = encode(&mesh, &EncodeOptions::default()).unwrap();
    let stream = &encoded.bytes;
    let time = std::time::Duration::from_millis(1);
    for (slug, policy, enc) in [
        ("portal", "open", &encoded),
        ("vault", "exhibition", &encoded),
        ("plain", "open", &plain),
    ] {
        let mut meta = ModelMeta::new(slug, format!("Sample {slug}"));
        meta.policy = policy.into();
        ingest_encoded(
            &*db.storage,
            enc,
            time,
            None,
            meta,
            &IngestOptions::default(),
        )
        .await
        .expect("ingest");
    }
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let (table, _) = vitrine::models_listing(&*db.storage).await.unwrap();
    assert!(
        table.ends_with(
            "; 0 charted without a part index; 0 with parts measured before their bulk error"
        ),
        "{table}"
    );

    // The manifest leads to the index; the plain stream has none.
    let manifest = get(&app, "/api/models/portal", &[]).await.json();
    let url = manifest["parts"]
        .as_str()
        .expect("a parts index")
        .to_owned();
    let plain_manifest = get(&app, "/api/models/plain", &[]).await.json();
    assert!(plain_manifest.get("parts").is_none());
    let plain_id = plain_manifest["compression_id"].as_i64().unwrap();
    let none = get(&app, &format!("/api/compressions/{plain_id}/parts"), &[]).await;
    assert_eq!(none.status, StatusCode::NOT_FOUND);

    let reply = get(&app, &url, &[]).await;
    assert_eq!(reply.status, StatusCode::OK);
    assert!(reply.header(header::CACHE_CONTROL).starts_with("public"));
    let index = reply.json();
    let id = manifest["compression_id"].as_i64().unwrap();
    let table = part_table(stream, Limits::default()).unwrap();
    let step = f64::from(StreamIndex::parse(stream).unwrap().header.quantization.step);
    let entries = index["parts"].as_array().unwrap();
    assert_eq!(index["charts"], 4);
    assert_eq!(entries.len(), table.len());
    for (entry, record) in entries.iter().zip(&table) {
        assert_eq!(entry["level"], record.level);
        assert_eq!(entry["chart"], record.chart);
        assert_eq!(entry["bytes"], record.bytes.len());
        assert_eq!(entry["inserted"], record.inserted);
        let error = entry["error"].as_f64().unwrap();
        assert!((error - f64::from(record.error_steps) * step).abs() <= 1e-9 * error.max(1.0));
        let bulk = entry["bulk_error"].as_f64().unwrap();
        assert!((bulk - f64::from(record.bulk_error_steps) * step).abs() <= 1e-9 * bulk.max(1.0));
        assert!(bulk <= error, "{entry}");
    }

    // Every part as served is the stream's bytes, revalidated without them.
    let part_url = |level: usize, chart: usize| {
        format!("/api/compressions/{id}/batches/{level}/parts/{chart}")
    };
    for record in &table {
        let reply = get(&app, &part_url(record.level, record.chart), &[]).await;
        assert_eq!(reply.status, StatusCode::OK, "{record:?}");
        assert_eq!(&reply.body[..], &stream[record.bytes.clone()]);
        assert!(reply.header(header::CACHE_CONTROL).contains("immutable"));
        let etag = reply.header(header::ETAG).to_owned();
        assert!(etag.starts_with('"') && !etag.starts_with("W/"));
        let again = get(
            &app,
            &part_url(record.level, record.chart),
            &[("if-none-match", &etag)],
        )
        .await;
        assert_eq!(again.status, StatusCode::NOT_MODIFIED);
    }

    // A view decoder fed from the served pieces: chart 2 to the end.
    let first = index["first_level"].as_u64().unwrap() as usize;
    let base = get(&app, &format!("/api/compressions/{id}/base"), &[]).await;
    let mut d = Decoder::new(&base.body, Limits::default()).unwrap();
    for level in 1..first {
        let batch = get(
            &app,
            &format!("/api/compressions/{id}/batches/{level}"),
            &[],
        )
        .await;
        d.apply_batch(&batch.body).unwrap();
    }
    let head = get(&app, index["head_url"].as_str().unwrap(), &[]).await;
    assert_eq!(head.status, StatusCode::OK);
    let mut view = d.into_view(&head.body).unwrap();
    let last = view.header().batch_count();
    for level in first..=last {
        let part = get(&app, &part_url(level, 2), &[]).await;
        view.apply_part(2, &part.body).unwrap();
    }
    let full = decode(stream, None, Limits::default()).unwrap();
    let (ours, theirs) = (view.chart(2).unwrap(), full.chart(2).unwrap());
    assert!(ours.quantized == theirs.quantized && ours.indices == theirs.indices);

    // The batch's cap holds for its parts: the exhibition's public visitor
    // gets the last level's parts refused, the level below served.
    let vault = get(&app, "/api/models/vault", &[]).await.json();
    let vault_id = vault["compression_id"].as_i64().unwrap();
    let capped = get(
        &app,
        &format!("/api/compressions/{vault_id}/batches/{last}/parts/0"),
        &[],
    )
    .await;
    assert_eq!(capped.status, StatusCode::FORBIDDEN);
    assert_eq!(capped.json()["error"], "level_capped");
    let below = get(
        &app,
        &format!("/api/compressions/{vault_id}/batches/{}/parts/0", last - 1),
        &[],
    )
    .await;
    assert_eq!(below.status, StatusCode::OK);

    // Bad addresses.
    for (uri, status) in [
        (part_url(first, 4), StatusCode::NOT_FOUND),
        (part_url(last + 1, 0), StatusCode::NOT_FOUND),
        (
            format!("/api/compressions/{id}/batches/{first}/parts/x"),
            StatusCode::BAD_REQUEST,
        ),
        (
            format!("/api/compressions/{id}/batches/{first}/parts/-1"),
            StatusCode::BAD_REQUEST,
        ),
        (
            format!("/api/compressions/{plain_id}/batches/1/parts/0"),
            StatusCode::NOT_FOUND,
        ),
    ] {
        let reply = get(&app, &uri, &[]).await;
        assert_eq!(reply.status, status, "{uri}");
    }
    if first > 1 {
        // A global batch has no parts.
        let reply = get(&app, &part_url(1, 0), &[]).await;
        assert_eq!(reply.status, StatusCode::NOT_FOUND);
    }
    assert!(PartedLayout::parse(
        &get(&app, &format!("/api/compressions/{id}/batches/{last}"), &[])
            .await
            .body
    )
    .unwrap()
    .is_some());
}
