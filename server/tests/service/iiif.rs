//! IIIF over real HTTP (issue 44): each public model's Presentation 4
//! Manifest checked against the shapes of the specification's 3D draft
//! (IIIF/api `source/presentation/4.0/`: a Scene whose painting
//! AnnotationPage paints a Model, cameras and lights; commenting
//! annotations with a PointSelector; language maps, `rights`,
//! `requiredStatement`), the levels it names, its points against the GLB's
//! node matrix, CORS and caching; the Collection; and the annotations'
//! round trip out as IIIF and back in, with malformed imports and limits
//! refused and nothing stored.
//!
//! The Presentation 4 JSON-LD context is not published yet (the draft's
//! `context.json` is an empty object), so no JSON-LD expansion is checked
//! here: the shapes are.

use super::curators::token;
use super::harness::{test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::{Rights, TokenScope, UpAxis};

const CONTEXT: &str = "http://iiif.io/api/presentation/4/context.json";
const MEDIA_TYPE: &str =
    "application/ld+json;profile=\"http://iiif.io/api/presentation/4/context.json\"";
const CREDIT: &str = "Scan: Museo de Prueba, 2019";

/// A Z-up ellipsoid in millimetres: 40 wide (x), 20 deep (y), 120 tall (z).
fn stele() -> vitrine_codec::IndexedMesh {
    let mut mesh = vitrine_samples::icosphere(3);
    for p in &mut mesh.positions {
        p[0] *= 20.0;
        p[1] *= 10.0;
        p[2] *= 60.0;
    }
    mesh
}

async fn ingest(db: &TestDb, slug: &str, policy: &str, rights: Rights) {
    let mut meta = ModelMeta::new(slug, format!("Stele {slug}"));
    meta.description = format!("A test stele ({slug}).");
    meta.policy = policy.into();
    meta.up = Some(UpAxis::Z);
    meta.unit = Some("mm".into());
    meta.rights = rights;
    ingest_mesh(&*db.storage, stele(), meta, &IngestOptions::default())
        .await
        .expect("ingest");
}

async fn get(http: &reqwest::Client, url: &str) -> (StatusCode, reqwest::header::HeaderMap, Value) {
    let reply = http.get(url).send().await.unwrap();
    let status = reply.status();
    let headers = reply.headers().clone();
    let body = reply.bytes().await.unwrap();
    (
        status,
        headers,
        serde_json::from_slice(&body).unwrap_or(Value::Null),
    )
}

/// `{ tag: [string, …] }` with at least one entry.
fn assert_language_map(value: &Value, what: &str) {
    let map = value
        .as_object()
        .unwrap_or_else(|| panic!("{what}: {value}"));
    assert!(!map.is_empty(), "{what}: empty language map");
    for (tag, texts) in map {
        assert!(!tag.is_empty(), "{what}");
        let texts = texts
            .as_array()
            .unwrap_or_else(|| panic!("{what}: {value}"));
        assert!(texts.iter().all(Value::is_string), "{what}: {value}");
    }
}

fn assert_label_value(entry: &Value, what: &str) {
    assert_language_map(&entry["label"], what);
    assert_language_map(&entry["value"], what);
}

/// The id of a resource reference, and that it has its type.
fn reference<'a>(value: &'a Value, kind: &str, what: &str) -> &'a str {
    assert_eq!(value["type"], kind, "{what}: {value}");
    value["id"]
        .as_str()
        .unwrap_or_else(|| panic!("{what}: no id"))
}

/// A PointSelector's x, y, z.
fn point(selector: &Value) -> [f64; 3] {
    assert_eq!(selector["type"], "PointSelector", "{selector}");
    ["x", "y", "z"].map(|axis| selector[axis].as_f64().unwrap())
}

/// A target that places something at a point in the Scene.
fn placed_at(target: &Value, scene: &str) -> [f64; 3] {
    assert_eq!(target["type"], "SpecificResource", "{target}");
    assert_eq!(reference(&target["source"], "Scene", "source"), scene);
    point(&target["selector"][0])
}

/// The Manifest's shape, as the draft's examples draw it; answers the
/// painted Model's URL, if any.
fn check_manifest(m: &Value, slug: &str) -> Option<String> {
    assert_eq!(m["@context"], CONTEXT);
    assert_eq!(m["type"], "Manifest");
    assert!(m["id"]
        .as_str()
        .unwrap()
        .ends_with(&format!("/iiif/{slug}/manifest")));
    assert_language_map(&m["label"], "label");
    assert_language_map(&m["summary"], "summary");
    for entry in m["metadata"].as_array().unwrap() {
        assert_label_value(entry, "metadata");
    }
    let homepage = &m["homepage"][0];
    assert!(reference(homepage, "Text", "homepage").ends_with(&format!("/m/{slug}")));
    assert_eq!(homepage["format"], "text/html");
    let stream = format!("/api/models/{slug}");
    assert!(reference(&m["seeAlso"][0], "Dataset", "seeAlso").ends_with(&stream));
    assert!(m["service"][0]["id"].as_str().unwrap().ends_with(&stream));
    assert!(m["service"][0]["profile"].is_string());
    let thumbnail = &m["thumbnail"][0];
    assert!(reference(thumbnail, "Image", "thumbnail")
        .contains(&format!("/api/models/{slug}/thumbnail")));

    let items = m["items"].as_array().unwrap();
    assert_eq!(items.len(), 1, "one Scene");
    let scene = reference(&items[0], "Scene", "items[0]");
    assert!(scene.ends_with(&format!("/iiif/{slug}/scene")));
    assert_language_map(&items[0]["label"], "scene label");
    let mut model = None;
    let mut kinds = Vec::new();
    for page in items[0]["items"].as_array().unwrap() {
        reference(page, "AnnotationPage", "painting page");
        for a in page["items"].as_array().unwrap() {
            reference(a, "Annotation", "painting annotation");
            assert_eq!(a["motivation"], json!(["painting"]));
            let body = &a["body"];
            let kind = body["type"].as_str().unwrap().to_owned();
            match kind.as_str() {
                "Model" => {
                    assert_eq!(body["format"], "model/gltf-binary");
                    assert_eq!(reference(&a["target"], "Scene", "model target"), scene);
                    model = Some(body["id"].as_str().unwrap().to_owned());
                }
                "PerspectiveCamera" => {
                    assert!(body["fieldOfView"].as_f64().unwrap() > 0.0);
                    let (near, far) = (
                        body["near"].as_f64().unwrap(),
                        body["far"].as_f64().unwrap(),
                    );
                    assert!(0.0 < near && near < far, "{body}");
                    point(&body["lookAt"]);
                    placed_at(&a["target"], scene);
                }
                "DirectionalLight" => {
                    point(&body["lookAt"]);
                    placed_at(&a["target"], scene);
                }
                "AmbientLight" => {}
                other => panic!("unexpected painted {other}"),
            }
            if kind.ends_with("Light") {
                let intensity = &body["intensity"];
                assert_eq!(intensity["type"], "Quantity");
                assert_eq!(intensity["unit"], "relative");
                let v = intensity["quantityValue"].as_f64().unwrap();
                assert!((0.0..=1.0).contains(&v));
            }
            kinds.push(kind);
        }
    }
    assert!(kinds.iter().any(|k| k == "PerspectiveCamera"), "{kinds:?}");
    assert!(kinds.iter().any(|k| k.ends_with("Light")), "{kinds:?}");

    let pages = m["annotations"].as_array().unwrap();
    assert_eq!(pages.len(), 1);
    check_comment_page(&pages[0], scene);
    model
}

fn check_comment_page(page: &Value, scene: &str) {
    reference(page, "AnnotationPage", "annotations");
    for a in page["items"].as_array().unwrap() {
        reference(a, "Annotation", "comment");
        assert_eq!(a["motivation"], json!(["commenting"]));
        assert_language_map(&a["label"], "comment label");
        if let Some(body) = a.get("body") {
            assert_eq!(body["type"], "TextualBody");
            assert!(body["value"].is_string());
        }
        placed_at(&a["target"], scene);
    }
}

/// `node matrix · p` (column-major), as a glTF client places a point.
fn through_matrix(m: &[f64], p: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|r| (0..3).map(|c| m[4 * c + r] * p[c]).sum::<f64>() + m[12 + r])
}

fn close(a: [f64; 3], b: [f64; 3], tolerance: f64) -> bool {
    (0..3).all(|i| (a[i] - b[i]).abs() <= tolerance * (1.0 + b[i].abs()))
}

fn glb_json(glb: &[u8]) -> Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

async fn annotate(
    http: &reqwest::Client,
    server: &TestServer,
    slug: &str,
    curator: &str,
    a: Value,
) {
    let url = server.url(&format!("/api/models/{slug}/annotations"));
    let reply = http
        .post(url)
        .bearer_auth(curator)
        .json(&a)
        .send()
        .await
        .unwrap();
    assert_eq!(
        reply.status(),
        StatusCode::CREATED,
        "{}",
        reply.text().await.unwrap()
    );
}

pub async fn manifests_for_public_models(db: TestDb) {
    let rights = Rights::parse(Some(CREDIT), Some("CC-BY-4.0")).unwrap();
    ingest(&db, "stele", "exhibition-download", rights).await;
    ingest(&db, "plain", "open", Rights::default()).await;
    ingest(&db, "vault", "researchers", Rights::default()).await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let mark = [10.0, -20.0, 30.0];
    annotate(
        &http,
        &server,
        "stele",
        &curator,
        json!({
            "title": "Tool mark", "text": "Chisel *marks*", "language": "en",
            "position": mark, "normal": [0, -1, 0]
        }),
    )
    .await;

    let url = server.url("/iiif/stele/manifest");
    let reply = http
        .get(&url)
        .header("origin", "https://viewer.example")
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::OK);
    let headers = reply.headers().clone();
    assert_eq!(headers["content-type"], MEDIA_TYPE);
    assert_eq!(headers["access-control-allow-origin"], "*");
    assert_eq!(headers["cache-control"], "public, max-age=300");
    let etag = headers["etag"].to_str().unwrap().to_owned();
    assert!(etag.starts_with('"'), "a strong ETag: {etag}");
    let manifest: Value = reply.json().await.unwrap();
    let model = check_manifest(&manifest, "stele").expect("the Scene paints the Model");

    // Credit and licence.
    assert_eq!(
        manifest["requiredStatement"]["value"],
        json!({ "none": [CREDIT] })
    );
    assert_eq!(
        manifest["rights"],
        "http://creativecommons.org/licenses/by/4.0/"
    );

    // The Model is a level every anonymous visitor may download; the
    // exhibition's last level (the researchers') is never named.
    let api: Value = http
        .get(server.url("/api/models/stele"))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    let last = api["last_level"].as_u64().unwrap();
    let public_cap = api["cap"]["limits"]["audience"].as_u64().unwrap();
    assert!(public_cap < last, "the exhibition keeps a level back");
    let level: u64 = model.rsplit("level=").next().unwrap().parse().unwrap();
    assert!(
        level <= public_cap,
        "level {level} over the public cap {public_cap}"
    );
    let text = manifest.to_string();
    for restricted in public_cap + 1..=last {
        assert!(
            !text.contains(&format!("download.glb?level={restricted}")),
            "{text}"
        );
    }
    let glb = http.get(&model).send().await.unwrap();
    assert_eq!(
        glb.status(),
        StatusCode::OK,
        "the Model downloads anonymously"
    );
    let glb = glb.bytes().await.unwrap();
    super::download::assert_valid_glb(&glb);

    // The annotation's point is where the GLB's node puts the model point:
    // Z up in millimetres becomes +Y up in metres.
    let comment = &manifest["annotations"][0]["items"][0];
    assert_eq!(comment["label"], json!({ "en": ["Tool mark"] }));
    assert_eq!(comment["body"]["language"], "en");
    assert_eq!(comment["body"]["value"], "Chisel *marks*");
    let scene_point = point(&comment["target"]["selector"][0]);
    assert!(
        close(scene_point, [0.010, 0.030, 0.020], 1e-9),
        "{scene_point:?}"
    );
    let gltf = glb_json(&glb);
    let matrix: Vec<f64> = gltf["nodes"][0]["matrix"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    assert!(close(through_matrix(&matrix, mark), scene_point, 1e-6));

    // Revalidation.
    let again = http
        .get(&url)
        .header("if-none-match", &etag)
        .send()
        .await
        .unwrap();
    assert_eq!(again.status(), StatusCode::NOT_MODIFIED);
    assert_eq!(again.headers()["etag"], etag.as_str());

    // A policy without downloads paints no Model and names no GLB.
    let (status, _, plain) = get(&http, &server.url("/iiif/plain/manifest")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(check_manifest(&plain, "plain"), None);
    assert!(!plain.to_string().contains("download.glb"));
    assert!(plain.get("rights").is_none() && plain.get("requiredStatement").is_none());

    // A restricted model is as unknown as a missing one, token or not.
    let (status, headers, vault) = get(&http, &server.url("/iiif/vault/manifest")).await;
    let (_, _, missing) = get(&http, &server.url("/iiif/nothing/manifest")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);
    assert_eq!(headers["cache-control"], "no-store");
    assert_eq!(vault, missing);
    let with_token = http
        .get(server.url("/iiif/vault/manifest"))
        .bearer_auth(&researcher)
        .send()
        .await
        .unwrap();
    assert_eq!(with_token.status(), StatusCode::NOT_FOUND);
    let (status, _, _) = get(&http, &server.url("/iiif/vault/annotations")).await;
    assert_eq!(status, StatusCode::NOT_FOUND);

    // The Collection: the public models' Manifests.
    let (status, headers, collection) = get(&http, &server.url("/iiif/collection")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(headers["access-control-allow-origin"], "*");
    assert_eq!(collection["@context"], CONTEXT);
    assert_eq!(collection["type"], "Collection");
    assert_language_map(&collection["label"], "collection label");
    let mut listed: Vec<&str> = collection["items"]
        .as_array()
        .unwrap()
        .iter()
        .map(|item| {
            assert_language_map(&item["label"], "item label");
            reference(item, "Manifest", "collection item")
        })
        .collect();
    listed.sort();
    assert_eq!(listed.len(), 2, "{listed:?}");
    assert!(
        listed[0].ends_with("/iiif/plain/manifest") && listed[1].ends_with("/iiif/stele/manifest")
    );
    server.shut_down().await;

    // CORS for any origin even where the service's own routes name theirs.
    let mut config = test_config();
    config.cors_origins = vec!["https://museum.example".into()];
    let server = TestServer::start(db.storage.clone(), config).await;
    let reply = http
        .get(server.url("/iiif/stele/manifest"))
        .header("origin", "https://aggregator.example")
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::OK);
    assert_eq!(reply.headers()["access-control-allow-origin"], "*");
    server.shut_down().await;
}

/// The stored annotations as compared across the round trip.
fn comparable(list: &Value) -> Vec<(String, String, Value, [f64; 3])> {
    list.as_array()
        .unwrap()
        .iter()
        .map(|a| {
            let p = a["position"].as_array().unwrap();
            (
                a["title"].as_str().unwrap().to_owned(),
                a["text"].as_str().unwrap().to_owned(),
                a["language"].clone(),
                [0, 1, 2].map(|i| p[i].as_f64().unwrap()),
            )
        })
        .collect()
}

pub async fn annotations_round_trip(db: TestDb) {
    ingest(&db, "stele", "open", Rights::default()).await;
    ingest(&db, "other", "open", Rights::default()).await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    for (title, text, language, position) in [
        (
            "Marque d'outil",
            "Un *trait* de ciseau.\n\nDeuxième paragraphe.",
            json!("fr"),
            [10.0, -20.0, 30.0],
        ),
        ("Crack", "", json!("en-GB"), [-3.3, 7.7, 59.1]),
        (
            "Inscription",
            "ΑΒΓ — no language stated",
            Value::Null,
            [0.125, 0.0, -12.0],
        ),
    ] {
        annotate(
            &http,
            &server,
            "stele",
            &curator,
            json!({
                "title": title, "text": text, "language": language,
                "position": position, "normal": [1, 0, 0]
            }),
        )
        .await;
    }
    let list_url = server.url("/api/models/stele/annotations");
    let list = |http: &reqwest::Client| {
        let request = http.get(&list_url);
        async move { request.send().await.unwrap().json::<Value>().await.unwrap() }
    };
    let before = list(&http).await;
    assert_eq!(before.as_array().unwrap().len(), 3);

    // Out as IIIF.
    let (status, headers, page) = get(&http, &server.url("/iiif/stele/annotations")).await;
    assert_eq!(status, StatusCode::OK);
    assert_eq!(headers["content-type"], MEDIA_TYPE);
    assert_eq!(headers["access-control-allow-origin"], "*");
    assert_eq!(page["@context"], CONTEXT);
    // The same page the Manifest holds.
    let (_, _, manifest) = get(&http, &server.url("/iiif/stele/manifest")).await;
    let mut held = manifest["annotations"][0].clone();
    held["@context"] = CONTEXT.into();
    assert_eq!(held, page);
    let scene = page["items"][0]["target"]["source"]["id"]
        .as_str()
        .unwrap()
        .to_owned();
    check_comment_page(&page, &scene);

    // Deleted, then the page imported back: the same annotations.
    for a in before.as_array().unwrap() {
        let url = format!("{list_url}/{}", a["id"]);
        let reply = http.delete(url).bearer_auth(&curator).send().await.unwrap();
        assert_eq!(reply.status(), StatusCode::NO_CONTENT);
    }
    assert_eq!(list(&http).await, json!([]));
    let import_url = server.url("/api/admin/models/stele/annotations/import");
    let import = |token: Option<&str>, body: Vec<u8>| {
        let mut request = http
            .post(&import_url)
            .header("content-type", "application/json")
            .body(body);
        if let Some(token) = token {
            request = request.bearer_auth(token);
        }
        request.send()
    };
    let page_bytes = serde_json::to_vec(&page).unwrap();
    let reply = import(Some(&curator), page_bytes.clone()).await.unwrap();
    assert_eq!(reply.status(), StatusCode::CREATED);
    assert_eq!(
        reply.json::<Value>().await.unwrap(),
        json!({ "imported": 3 })
    );
    let after = list(&http).await;
    let (was, now) = (comparable(&before), comparable(&after));
    assert_eq!(was.len(), now.len());
    for (a, b) in was.iter().zip(&now) {
        assert_eq!(
            (&a.0, &a.1, &a.2),
            (&b.0, &b.1, &b.2),
            "title, text, language"
        );
        assert!(
            close(b.3, a.3, 1e-9),
            "position {:?} came back as {:?}",
            a.3,
            b.3
        );
    }

    // Who may import.
    assert_eq!(
        import(None, page_bytes.clone()).await.unwrap().status(),
        StatusCode::UNAUTHORIZED
    );
    assert_eq!(
        import(Some(&researcher), page_bytes.clone())
            .await
            .unwrap()
            .status(),
        StatusCode::FORBIDDEN
    );

    // Malformed: refused with the item and the reason, nothing stored.
    let stored = after.as_array().unwrap().len();
    let mut bad = page.clone();
    bad["items"][1]["target"]["source"]["id"] = scene.replace("/stele/", "/other/").into();
    bad["items"][2]["target"]["selector"][0]["z"] = "deep".into();
    let reply = import(Some(&curator), serde_json::to_vec(&bad).unwrap())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let message = reply.json::<Value>().await.unwrap()["message"]
        .as_str()
        .unwrap()
        .to_owned();
    assert!(
        message.contains("2 of 3") && message.contains("nothing imported"),
        "{message}"
    );
    assert!(
        message.contains("items[1]") && message.contains("not this model's Scene"),
        "{message}"
    );
    assert!(
        message.contains("items[2]") && message.contains("z is missing"),
        "{message}"
    );
    let mut long = page.clone();
    long["items"][0]["label"] = json!({ "fr": ["x".repeat(201)] });
    let reply = import(Some(&curator), serde_json::to_vec(&long).unwrap())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let mut language = page.clone();
    language["items"][0]["body"]["language"] = "not a tag!".into();
    let reply = import(Some(&curator), serde_json::to_vec(&language).unwrap())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let reply = import(Some(&curator), b"{\"type\": \"AnnotationPage\", ".to_vec())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::BAD_REQUEST);
    let reply = import(Some(&curator), br#"{"type": "Manifest"}"#.to_vec())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);
    assert_eq!(list(&http).await.as_array().unwrap().len(), stored);

    // Limits: 10,000 annotations (a bare list of small ones, within the
    // byte limit), and a body declared as 20 MB, refused before it is sent.
    let small = json!({
        "type": "Annotation",
        "label": { "en": ["x"] },
        "target": { "source": scene, "selector": { "type": "PointSelector", "x": 0, "y": 0, "z": 0 } }
    });
    let many = serde_json::to_vec(&Value::Array(vec![small; 10_000])).unwrap();
    assert!(many.len() < 4 << 20, "{} bytes", many.len());
    let reply = import(Some(&curator), many).await.unwrap();
    assert_eq!(reply.status(), StatusCode::PAYLOAD_TOO_LARGE);
    let message = reply.json::<Value>().await.unwrap()["message"]
        .as_str()
        .unwrap()
        .to_owned();
    assert!(
        message.contains("10000 annotations") && message.contains("at most 5000"),
        "{message}"
    );
    let status = declared_only(
        &server,
        "/api/admin/models/stele/annotations/import",
        &curator,
        20 << 20,
    )
    .await;
    assert_eq!(status, 413);
    assert_eq!(list(&http).await.as_array().unwrap().len(), stored);

    // A list of annotations from elsewhere imports too.
    let foreign = json!([{
        "type": "Annotation",
        "motivation": "commenting",
        "body": { "type": "TextualBody", "value": "Restored in 1950", "format": "text/plain" },
        "target": {
            "type": "SpecificResource",
            "source": scene,
            "selector": { "type": "PointSelector", "x": 0.0, "y": 0.06, "z": 0.0 }
        }
    }]);
    let reply = import(Some(&curator), serde_json::to_vec(&foreign).unwrap())
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::CREATED);
    let added = list(&http).await;
    let last = added.as_array().unwrap().last().unwrap().clone();
    assert_eq!(last["title"], "Restored in 1950");
    let p: Vec<f64> = last["position"]
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap())
        .collect();
    // 6 cm up the Scene's +Y is 60 mm along the model's +Z.
    assert!(close([p[0], p[1], p[2]], [0.0, 0.0, 60.0], 1e-9), "{p:?}");

    // Editing an annotation without naming its language keeps it; null clears it.
    let french = &added.as_array().unwrap()[0];
    assert_eq!(french["language"], "fr");
    let url = format!("{list_url}/{}", french["id"]);
    let edit = |body: Value| http.put(&url).bearer_auth(&curator).json(&body).send();
    let mut body = json!({
        "title": "Marque", "text": "", "position": [0, 0, 0], "normal": [0, 1, 0]
    });
    let kept: Value = edit(body.clone()).await.unwrap().json().await.unwrap();
    assert_eq!(kept["language"], "fr");
    body["language"] = Value::Null;
    let cleared: Value = edit(body).await.unwrap().json().await.unwrap();
    assert_eq!(cleared["language"], Value::Null);
    server.shut_down().await;
}

/// The status of a POST whose head declares `length` bytes of body, none of
/// which is sent: a limit must answer from the head alone.
async fn declared_only(server: &TestServer, path: &str, token: &str, length: usize) -> u16 {
    use tokio::io::{AsyncReadExt, AsyncWriteExt};
    let address = server.base.trim_start_matches("http://").to_owned();
    let mut stream = tokio::net::TcpStream::connect(&address).await.unwrap();
    let head = format!(
        "POST {path} HTTP/1.1\r\nHost: {address}\r\nAuthorization: Bearer {token}\r\n\
         Content-Type: application/json\r\nContent-Length: {length}\r\n\r\n"
    );
    stream.write_all(head.as_bytes()).await.unwrap();
    let mut answer = Vec::new();
    let mut chunk = [0u8; 1024];
    while !answer.windows(4).any(|w| w == b"\r\n\r\n") {
        let n = tokio::time::timeout(std::time::Duration::from_secs(10), stream.read(&mut chunk))
            .await
            .expect("an answer before the body is sent")
            .unwrap();
        assert!(n > 0, "closed without an answer");
        answer.extend_from_slice(&chunk[..n]);
    }
    let line = String::from_utf8_lossy(&answer);
    line.split_whitespace().nth(1).unwrap().parse().unwrap()
}
