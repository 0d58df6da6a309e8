//! Issue 22 over real HTTP: token scopes and annotations (sanitised
//! Markdown). Uploads are in `uploads.rs`, what ingest records in
//! `curation.rs`.

use super::harness::{ingest_sample, test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use vitrine::commands::token::new_token;
use vitrine::storage::{sha256_hex, NewToken, TokenScope};

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
