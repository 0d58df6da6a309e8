//! The shared suite, continued: level caps and malformed requests.

use super::harness::{ingest_sample, ingest_sample_with, sample_encoded, test_config, TestDb};
use super::story::{get, token_for};
use axum::http::{header, StatusCode};
use serde_json::Value;
use vitrine::{app, AppState};
use vitrine_codec::StreamIndex;

/// Expected device cap: the highest level within the vertex budget.
fn within(index: &StreamIndex, budget: u32) -> usize {
    index
        .header
        .levels
        .iter()
        .rposition(|l| l.vertices <= budget)
        .unwrap_or(0)
}

pub async fn caps_by_audience_and_device(db: TestDb) {
    let expo = ingest_sample(&*db.storage, "expo", "exhibition")
        .await
        .stored
        .compression_id;
    let secret = ingest_sample(&*db.storage, "secret", "researchers")
        .await
        .stored
        .compression_id;
    let everywhere = token_for(&db, None).await;
    let expo_only = token_for(&db, Some("expo")).await;
    // Budgets between levels, whatever the codec's layering: a phone gets
    // level 1, a tablet the third-last level.
    let sample = StreamIndex::parse(&sample_encoded().bytes).unwrap();
    let n = sample.batches.len();
    assert!(n >= 4, "the sample needs at least 4 batches");
    let mut config = test_config();
    config.caps.phone_max_vertices = sample.header.levels[1].vertices;
    config.caps.tablet_max_vertices = sample.header.levels[n - 2].vertices;
    let (phone_budget, tablet_budget) = (
        config.caps.phone_max_vertices,
        config.caps.tablet_max_vertices,
    );
    let app = app(AppState::new(db.storage.clone(), config));
    let index = StreamIndex::parse(&sample_encoded().bytes).unwrap();
    let last = index.batches.len();
    let bearer = format!("Bearer {everywhere}");
    let batch = |id: i64, k: usize| format!("/api/compressions/{id}/batches/{k}");

    // Public exhibition: everything but the full-resolution level.
    let m = get(&app, "/api/models/expo", &[]).await.json();
    assert_eq!(
        (m["cap"]["level"].as_u64(), m["cap"]["reason"].as_str()),
        (Some(last as u64 - 1), Some("audience"))
    );
    assert_eq!(m["visitor"]["audience"], "public");
    assert_eq!(m["levels"][last]["allowed"], false);
    let refused = get(&app, &batch(expo, last), &[]).await;
    assert_eq!(refused.status, StatusCode::FORBIDDEN);
    let body = refused.json();
    assert_eq!(
        (body["error"].as_str(), body["reason"].as_str()),
        (Some("level_capped"), Some("audience"))
    );
    assert_eq!(body["cap"], last - 1);
    assert!(refused.headers.get(header::RETRY_AFTER).is_none());
    assert_eq!(
        get(&app, &batch(expo, last - 1), &[]).await.status,
        StatusCode::OK
    );

    // A researcher gets the full level, cacheable only privately.
    let m = get(&app, "/api/models/expo", &[("authorization", &bearer)])
        .await
        .json();
    assert_eq!(
        (m["cap"]["level"].as_u64(), &m["cap"]["reason"]),
        (Some(last as u64), &Value::Null)
    );
    assert_eq!(m["visitor"]["audience"], "researcher");
    let full = get(&app, &batch(expo, last), &[("authorization", &bearer)]).await;
    assert_eq!(full.status, StatusCode::OK);
    assert_eq!(
        full.header(header::CACHE_CONTROL),
        "private, max-age=31536000, immutable"
    );
    let by_query = get(
        &app,
        &format!("{}?token={expo_only}", batch(expo, last)),
        &[],
    )
    .await;
    assert_eq!(by_query.status, StatusCode::OK);
    let bad = get(
        &app,
        "/api/models/expo",
        &[("authorization", "Bearer vtr_nonsense")],
    )
    .await;
    assert_eq!(bad.status, StatusCode::UNAUTHORIZED);
    assert_eq!(bad.json()["error"], "invalid_token");

    // A researchers-only model does not exist for the public.
    assert_eq!(
        get(&app, "/api/models/secret", &[]).await.status,
        StatusCode::NOT_FOUND
    );
    assert_eq!(
        get(&app, &format!("/api/compressions/{secret}/base"), &[])
            .await
            .status,
        StatusCode::NOT_FOUND
    );
    let token_q = format!("/api/models/secret?token={expo_only}");
    assert_eq!(get(&app, &token_q, &[]).await.status, StatusCode::NOT_FOUND);
    assert_eq!(
        get(&app, "/api/models/secret", &[("authorization", &bearer)])
            .await
            .status,
        StatusCode::OK
    );
    let public_list = get(&app, "/api/models", &[]).await.json();
    assert_eq!(public_list["models"].as_array().unwrap().len(), 1);
    let researcher_list = get(&app, "/api/models", &[("authorization", &bearer)])
        .await
        .json();
    assert_eq!(researcher_list["models"].as_array().unwrap().len(), 2);

    // Device classes: explicit, from User-Agent, from the client hint.
    let phone_cap = within(&index, phone_budget);
    let tablet_cap = within(&index, tablet_budget);
    let vertices: Vec<u32> = index.header.levels.iter().map(|l| l.vertices).collect();
    assert!(
        phone_cap < tablet_cap && tablet_cap < last - 1,
        "sample levels must straddle the budgets: {vertices:?}"
    );
    let iphone = "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) Mobile/15E148";
    for (uri, headers, device, cap) in [
        ("/api/models/expo?device=phone", vec![], "phone", phone_cap),
        (
            "/api/models/expo?device=tablet",
            vec![],
            "tablet",
            tablet_cap,
        ),
        (
            "/api/models/expo",
            vec![("user-agent", iphone)],
            "phone",
            phone_cap,
        ),
        (
            "/api/models/expo",
            vec![("sec-ch-ua-mobile", "?1")],
            "phone",
            phone_cap,
        ),
        (
            "/api/models/expo?device=desktop",
            vec![("user-agent", iphone)],
            "desktop",
            last - 1,
        ),
    ] {
        let m = get(&app, uri, &headers).await.json();
        assert_eq!(m["visitor"]["device"], device, "{uri} {headers:?}");
        assert_eq!(m["cap"]["level"], cap, "{uri} {headers:?}");
    }
    let m = get(
        &app,
        "/api/models/expo?device=phone",
        &[("authorization", &bearer)],
    )
    .await
    .json();
    assert_eq!(
        (
            m["cap"]["reason"].as_str(),
            m["cap"]["limits"]["audience"].as_u64()
        ),
        (Some("device"), Some(last as u64))
    );
    let refused = get(
        &app,
        &format!("{}?device=phone", batch(expo, phone_cap + 1)),
        &[],
    )
    .await;
    assert_eq!(refused.status, StatusCode::FORBIDDEN);
    assert_eq!(refused.json()["reason"], "device");
    let allowed = get(
        &app,
        &format!("{}?device=phone", batch(expo, phone_cap)),
        &[],
    )
    .await;
    assert_eq!(allowed.status, StatusCode::OK);
}

pub async fn load_caps_fall_and_recover(db: TestDb) {
    let index = StreamIndex::parse(&sample_encoded().bytes).unwrap();
    let last = index.batches.len();
    // As if a quality study had found a level three below the last sufficient.
    assert!(last >= 4, "the sample needs at least 4 batches");
    let good_enough = last - 3;
    let id = ingest_sample_with(&*db.storage, "busy", "open", Some(good_enough as u32))
        .await
        .stored
        .compression_id;
    let state = AppState::new(db.storage.clone(), test_config());
    let app = app(state.clone());
    let steps = state.load().config().steps;

    state.load().force_pressure(Some(steps));
    let m = get(&app, "/api/models/busy", &[]).await.json();
    assert_eq!(
        (m["cap"]["level"].as_u64(), m["cap"]["reason"].as_str()),
        (Some(good_enough as u64), Some("load"))
    );
    assert_eq!(m["good_enough_level"], good_enough);
    assert_eq!(m["cap"]["retry_after_s"], 10);
    let refused = get(
        &app,
        &format!("/api/compressions/{id}/batches/{}", good_enough + 1),
        &[],
    )
    .await;
    assert_eq!(refused.status, StatusCode::TOO_MANY_REQUESTS);
    assert_eq!(refused.header(header::RETRY_AFTER), "10");
    assert_eq!(
        (
            refused.json()["reason"].as_str(),
            refused.json()["cap"].as_u64()
        ),
        (Some("load"), Some(good_enough as u64))
    );
    let ok = get(
        &app,
        &format!("/api/compressions/{id}/batches/{good_enough}"),
        &[],
    )
    .await;
    assert_eq!(ok.status, StatusCode::OK);

    // Half pressure: halfway between the good-enough and the last level.
    state.load().force_pressure(Some(steps / 2));
    let m = get(&app, "/api/models/busy", &[]).await.json();
    let half = m["cap"]["level"].as_u64().unwrap() as usize;
    assert!(
        good_enough < half && half < last,
        "{good_enough} < {half} < {last}"
    );

    state.load().force_pressure(None);
    let m = get(&app, "/api/models/busy", &[]).await.json();
    assert_eq!(
        (m["cap"]["level"].as_u64(), &m["cap"]["reason"]),
        (Some(last as u64), &Value::Null)
    );
    let metrics = String::from_utf8(get(&app, "/metrics", &[]).await.body.to_vec()).unwrap();
    assert!(
        metrics.contains("vitrine_level_capped_total{reason=\"load\"} 1"),
        "{metrics}"
    );
    assert!(
        metrics.contains(&format!("vitrine_load_level_cap{{model=\"busy\"}} {last}")),
        "{metrics}"
    );
}

pub async fn bad_ids_and_slugs(db: TestDb) {
    let id = ingest_sample(&*db.storage, "torus", "exhibition")
        .await
        .stored
        .compression_id;
    let app = app(AppState::new(db.storage.clone(), test_config()));
    let cases: Vec<(String, StatusCode, &str)> = vec![
        (
            "/api/compressions/abc/base".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/compressions/-1/base".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/compressions/99999999999999999999/base".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/compressions/0/base".into(),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            format!("/api/compressions/{}/base", id + 100),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            format!("/api/compressions/{id}/batches/0"),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            format!("/api/compressions/{id}/batches/9999"),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            format!("/api/compressions/{id}/batches/1x"),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            format!("/api/compressions/{id}/batches/99999999999"),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            "/api/models/Torus".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/models/-torus".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/models/tor%20us".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            format!("/api/models/{}", "a".repeat(65)),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        (
            "/api/models/nope".into(),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
        (
            "/api/models/torus?device=fridge".into(),
            StatusCode::BAD_REQUEST,
            "bad_request",
        ),
        ("/api/textures/7".into(), StatusCode::NOT_FOUND, "not_found"),
        (
            "/api/nothing/here".into(),
            StatusCode::NOT_FOUND,
            "not_found",
        ),
    ];
    for (uri, status, code) in cases {
        let reply = get(&app, &uri, &[]).await;
        assert_eq!(reply.status, status, "{uri}");
        assert_eq!(reply.json()["error"], code, "{uri}");
        assert_eq!(reply.header(header::CACHE_CONTROL), "no-store", "{uri}");
    }
    let basic = get(
        &app,
        "/api/models/torus",
        &[("authorization", "Basic dXNlcjpwdw==")],
    )
    .await;
    assert_eq!(basic.status, StatusCode::BAD_REQUEST);
}
