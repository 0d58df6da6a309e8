//! Guided tours (issue 44) over real HTTP on both backends: curator-only
//! writes, validation with the step and field named, the body and step
//! limits, reordering by replacement, versioning with the model (a tour
//! recorded on version 1 is not served with version 2, curators still see
//! it), and the tour as a IIIF Range in the Manifest.

use super::curators::token;
use super::harness::{ingest_sample, sample_mesh, test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::{OnExisting, TokenScope};

fn step(n: usize) -> Value {
    json!({
        "view": format!("camera=0,0.1,0,{}.5,0.{n},0.2&section=y,0.5,0", n + 2),
        "title": { "en": format!("Step {n}"), "pt": format!("Etapa {n}") },
        "text": { "en": format!("The *{n}th* view <script>alert(1)</script>"), "pt": format!("A vista {n}") },
    })
}

fn tour(steps: usize) -> Value {
    json!({
        "title": { "en": "Around the ring", "pt": "À volta do anel" },
        "steps": (1..=steps).map(step).collect::<Vec<_>>(),
    })
}

async fn status_and_body(reply: reqwest::Response) -> (StatusCode, Value) {
    let status = reply.status();
    (status, reply.json().await.unwrap_or(Value::Null))
}

pub async fn tours_stored_versioned_and_in_the_manifest(db: TestDb) {
    ingest_sample(&*db.storage, "torus", "open").await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let other_model = token(&db, TokenScope::Curator, Some("elsewhere")).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let public = server.url("/api/models/torus/tours");
    let admin = server.url("/api/admin/models/torus/tours");

    let (status, empty) = status_and_body(http.get(&public).send().await.unwrap()).await;
    assert_eq!((status, empty), (StatusCode::OK, json!([])));

    // Auth as the other admin routes.
    let post = |body: &Value, t: Option<&str>| {
        let mut r = http.post(&admin).json(body);
        if let Some(t) = t {
            r = r.bearer_auth(t);
        }
        r.send()
    };
    let body = tour(3);
    assert_eq!(
        post(&body, None).await.unwrap().status(),
        StatusCode::UNAUTHORIZED
    );
    assert_eq!(
        post(&body, Some(&researcher)).await.unwrap().status(),
        StatusCode::FORBIDDEN
    );
    assert_eq!(
        post(&body, Some(&other_model)).await.unwrap().status(),
        StatusCode::FORBIDDEN
    );
    assert_eq!(
        http.get(&admin).send().await.unwrap().status(),
        StatusCode::UNAUTHORIZED
    );

    let (status, created) = status_and_body(post(&body, Some(&curator)).await.unwrap()).await;
    assert_eq!(status, StatusCode::CREATED, "{created}");
    assert_eq!(created["version"], 1);
    assert_eq!(created["title"]["pt"], "À volta do anel");
    let steps = created["steps"].as_array().unwrap();
    assert_eq!(steps.len(), 3);
    assert_eq!(steps[1]["title"]["en"], "Step 2");
    let html = steps[0]["html"]["en"].as_str().unwrap();
    assert!(
        html.contains("<em>1th</em>") && !html.contains("<script"),
        "{html}"
    );
    let id = created["id"].as_i64().unwrap();

    // Validation: each refusal names what is wrong, nothing is stored.
    let mut no_camera = tour(3);
    no_camera["steps"][1]["view"] = json!("light=0,0,1,1");
    let mut bad_language = tour(1);
    bad_language["steps"][0]["title"] = json!({ "not a tag!": "x" });
    let mut empty_title = tour(1);
    empty_title["title"] = json!({ "en": "  " });
    let mut long_text = tour(1);
    long_text["steps"][0]["text"] = json!({ "en": "x".repeat(10_001) });
    let mut unknown_version = tour(1);
    unknown_version["version"] = json!(9);
    for (bad, needle) in [
        (tour(0), "at least one step"),
        (tour(51), "at most 50 steps"),
        (no_camera, "step 2: view has no camera"),
        (bad_language, "BCP 47"),
        (empty_title, "title needs a text"),
        (long_text, "10000 characters"),
        (unknown_version, "no version 9"),
        (
            json!({ "title": { "en": "x" }, "steps": [], "extra": 1 }),
            "unknown field",
        ),
    ] {
        let (status, message) = status_and_body(post(&bad, Some(&curator)).await.unwrap()).await;
        assert_eq!(
            status,
            StatusCode::UNPROCESSABLE_ENTITY,
            "{needle}: {message}"
        );
        let text = message["message"].as_str().unwrap_or_default();
        assert!(text.contains(needle), "{needle}: {message}");
    }

    // Limits: a tour in seven languages passes the usual 64 KiB body limit
    // (tours have 1 MiB); past 1 MiB it is refused before it is read.
    let mut wide = tour(12);
    for step in wide["steps"].as_array_mut().unwrap() {
        for tag in ["en", "pt", "es", "fr", "de", "it", "ar"] {
            step["text"][tag] = json!("Lorem ipsum dolor sit amet. ".repeat(40));
        }
    }
    assert!(wide.to_string().len() > 64 * 1024);
    let (status, wide_created) = status_and_body(post(&wide, Some(&curator)).await.unwrap()).await;
    assert_eq!(status, StatusCode::CREATED, "{wide_created}");
    let huge = format!(
        "{{\"title\":{{\"en\":\"x\"}},\"steps\":[],\"pad\":\"{}\"}}",
        "x".repeat(1 << 20)
    );
    let refused = http
        .post(&admin)
        .bearer_auth(&curator)
        .header("content-type", "application/json")
        .body(huge)
        .send()
        .await
        .unwrap();
    assert_eq!(refused.status(), StatusCode::PAYLOAD_TOO_LARGE);
    let wide_id = wide_created["id"].as_i64().unwrap();
    let deleted = http
        .delete(server.url(&format!("/api/admin/models/torus/tours/{wide_id}")))
        .bearer_auth(&curator)
        .send()
        .await
        .unwrap();
    assert_eq!(deleted.status(), StatusCode::NO_CONTENT);

    // Reorder: the steps in a new order, by replacement.
    let one = server.url(&format!("/api/admin/models/torus/tours/{id}"));
    let mut reordered = tour(3);
    reordered["steps"].as_array_mut().unwrap().reverse();
    let (status, replaced) = status_and_body(
        http.put(one)
            .bearer_auth(&curator)
            .json(&reordered)
            .send()
            .await
            .unwrap(),
    )
    .await;
    assert_eq!(status, StatusCode::OK, "{replaced}");
    let (_, served) = status_and_body(http.get(&public).send().await.unwrap()).await;
    let titles: Vec<&str> = served[0]["steps"]
        .as_array()
        .unwrap()
        .iter()
        .map(|s| s["title"]["en"].as_str().unwrap())
        .collect();
    assert_eq!(titles, ["Step 3", "Step 2", "Step 1"]);
    let missing = server.url("/api/admin/models/torus/tours/999999");
    let put_missing = http
        .put(missing)
        .bearer_auth(&curator)
        .json(&reordered)
        .send()
        .await
        .unwrap();
    assert_eq!(put_missing.status(), StatusCode::NOT_FOUND);

    // The Manifest lists the tour as a Range, its steps in order.
    let manifest: Value = http
        .get(server.url("/iiif/torus/manifest"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    let ranges = manifest["structures"].as_array().expect("structures");
    assert_eq!(ranges.len(), 1);
    let range = &ranges[0];
    assert_eq!(range["type"], "Range");
    assert!(range["id"]
        .as_str()
        .unwrap()
        .ends_with(&format!("/iiif/torus/tours/{id}")));
    assert_eq!(range["label"]["pt"], json!(["À volta do anel"]));
    let items = range["items"].as_array().unwrap();
    assert_eq!(items.len(), 3);
    assert_eq!(items[0]["type"], "SpecificResource");
    assert_eq!(items[0]["source"]["type"], "Scene");
    assert_eq!(items[0]["label"]["en"], json!(["Step 3"]));
    assert_eq!(items[0]["selector"][0]["type"], "PointSelector");
    assert!(items[2]["homepage"][0]["id"]
        .as_str()
        .unwrap()
        .ends_with(&format!("/m/torus?tour={id}&step=3")));

    // Storage: the same rows through the trait.
    let stored = db.storage.tours("torus", None).await.unwrap();
    assert_eq!(stored.len(), 1);
    assert_eq!(stored[0].steps[0].title["en"], "Step 3");
    drop(server);

    // A new version of the scan: version 1's tour is no longer served, nor in
    // the Manifest; curators still see it, and may record on version 1.
    let mut meta = ModelMeta::new("torus", "Sample torus, rescanned");
    meta.policy = "open".into();
    meta.on_existing = OnExisting::NewVersion;
    ingest_mesh(&*db.storage, sample_mesh(), meta, &IngestOptions::default())
        .await
        .expect("a second version");
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let public = server.url("/api/models/torus/tours");
    let admin = server.url("/api/admin/models/torus/tours");
    let (_, served) = status_and_body(http.get(&public).send().await.unwrap()).await;
    assert_eq!(served, json!([]));
    let manifest: Value = http
        .get(server.url("/iiif/torus/manifest"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert!(
        manifest.get("structures").is_none(),
        "{}",
        manifest["structures"]
    );
    let (_, all) =
        status_and_body(http.get(&admin).bearer_auth(&curator).send().await.unwrap()).await;
    assert_eq!(all.as_array().unwrap().len(), 1);
    assert_eq!(all[0]["version"], 1);
    let mut on_first = tour(1);
    on_first["version"] = json!(1);
    let (status, older) = status_and_body(
        http.post(&admin)
            .bearer_auth(&curator)
            .json(&on_first)
            .send()
            .await
            .unwrap(),
    )
    .await;
    assert_eq!(
        (status, older["version"].clone()),
        (StatusCode::CREATED, json!(1))
    );
    let (status, newer) = status_and_body(
        http.post(&admin)
            .bearer_auth(&curator)
            .json(&tour(2))
            .send()
            .await
            .unwrap(),
    )
    .await;
    assert_eq!(
        (status, newer["version"].clone()),
        (StatusCode::CREATED, json!(2))
    );
    let (_, served) = status_and_body(http.get(&public).send().await.unwrap()).await;
    assert_eq!(served.as_array().unwrap().len(), 1);
    assert_eq!(served[0]["id"], newer["id"]);

    // Delete: gone once, then 404.
    let one = server.url(&format!("/api/admin/models/torus/tours/{id}"));
    assert_eq!(
        http.delete(&one)
            .bearer_auth(&curator)
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::NO_CONTENT
    );
    assert_eq!(
        http.delete(&one)
            .bearer_auth(&curator)
            .send()
            .await
            .unwrap()
            .status(),
        StatusCode::NOT_FOUND
    );
}
