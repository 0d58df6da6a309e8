//! A version's texts in other languages (issue 43) over real HTTP on both
//! backends: the curator's editor route (auth, validation, replacement),
//! then every place a visitor meets them in the language asked for with a
//! fallback to the version's own: the manifest and the gallery (all
//! languages, the viewer picks), the model page's head and JSON-LD, oEmbed
//! and the IIIF Manifest's language maps. A new version starts without
//! the old one's translations.

use super::curators::token;
use super::harness::{sample_mesh, test_config, TestDb, TestServer};
use super::publishing::json_of;
use reqwest::StatusCode;
use serde_json::{json, Value};
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::{OnExisting, TokenScope};

async fn ingest(db: &TestDb, on_existing: OnExisting) {
    let mut meta = ModelMeta::new("daniel", "The prophet Daniel");
    meta.policy = "open".into();
    meta.description = "Soapstone, 1800–1805.".into();
    meta.rights.credit = Some("Scan: Museum of the Inconfidência".into());
    meta.language = Some("en".into());
    meta.on_existing = on_existing;
    ingest_mesh(&*db.storage, sample_mesh(), meta, &IngestOptions::default())
        .await
        .expect("ingest");
}

fn translations() -> Value {
    json!({
        "language": "en",
        "translations": {
            "pt-BR": {
                "title": "O profeta Daniel",
                "description": "Pedra-sabão, 1800–1805.",
                "credit": "Digitalização: Museu da Inconfidência",
            },
            "es": { "title": "El profeta Daniel" },
        }
    })
}

pub async fn texts_in_the_visitors_language(db: TestDb) {
    ingest(&db, OnExisting::Refuse).await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let admin = server.url("/api/admin/models/daniel/versions/1/texts");

    // The editor's route: curators only, checked input, whole replacement.
    let put = |body: Value, t: Option<&str>| {
        let mut r = http.put(&admin).json(&body);
        if let Some(t) = t {
            r = r.bearer_auth(t);
        }
        r.send()
    };
    let status = |r: reqwest::Response| r.status();
    assert_eq!(
        status(put(translations(), None).await.unwrap()),
        StatusCode::UNAUTHORIZED
    );
    let as_researcher = put(translations(), Some(&researcher)).await.unwrap();
    assert_eq!(status(as_researcher), StatusCode::FORBIDDEN);
    let bad = json!({ "translations": { "pt": { "title": "a\nb" } } });
    let refused = put(bad, Some(&curator)).await.unwrap();
    assert_eq!(refused.status(), StatusCode::UNPROCESSABLE_ENTITY);
    let message = refused.json::<Value>().await.unwrap()["message"].clone();
    assert!(message.as_str().unwrap().contains("pt title"), "{message}");
    let saved = put(translations(), Some(&curator)).await.unwrap();
    assert_eq!(saved.status(), StatusCode::OK);
    let saved: Value = saved.json().await.unwrap();
    assert_eq!(saved["language"], "en");
    assert_eq!(saved["title"], "The prophet Daniel");
    assert_eq!(
        saved["translations"]["es"],
        json!({ "title": "El profeta Daniel" })
    );
    let missing = http
        .put(server.url("/api/admin/models/daniel/versions/9/texts"))
        .bearer_auth(&curator)
        .json(&translations())
        .send()
        .await
        .unwrap();
    assert_eq!(missing.status(), StatusCode::NOT_FOUND);
    let read: Value = json_of(&http, &admin, Some(&curator)).await;
    assert_eq!(read, saved);

    // The manifest and the gallery carry every language; the viewer picks.
    let manifest: Value = json_of(&http, server.url("/api/models/daniel"), None).await;
    assert_eq!(manifest["language"], "en");
    assert_eq!(
        manifest["translations"]["pt-BR"]["credit"],
        "Digitalização: Museu da Inconfidência"
    );
    let list: Value = json_of(&http, server.url("/api/models"), None).await;
    let listed = &list["models"][0];
    assert_eq!(listed["language"], "en");
    assert_eq!(listed["translations"]["es"]["title"], "El profeta Daniel");
    assert!(listed["translations"]["es"].get("description").is_none());

    // The page's head: ?lang= first, then Accept-Language, then the default.
    let head = |query: &'static str, accept: &'static str| {
        let http = http.clone();
        let url = server.url(&format!("/m/daniel{query}"));
        async move {
            let reply = http
                .get(url)
                .header("accept-language", accept)
                .send()
                .await
                .unwrap();
            assert_eq!(reply.status(), StatusCode::OK);
            reply.text().await.unwrap()
        }
    };
    let pt = head("?lang=pt", "de").await;
    assert!(
        pt.contains("og:title\" content=\"O profeta Daniel\""),
        "{pt}"
    );
    assert!(pt.contains("og:locale\" content=\"pt_BR\""), "{pt}");
    assert!(pt.contains("Pedra-sabão"), "{pt}");
    let ld = json_ld(&pt);
    assert_eq!(
        ld["name"],
        json!({ "@value": "O profeta Daniel", "@language": "pt-BR" })
    );
    assert_eq!(
        ld["creditText"]["@value"],
        "Digitalização: Museu da Inconfidência"
    );
    // Spanish gives a title only: the description falls back, marked English.
    let es = head("", "es-MX, en;q=0.5").await;
    let ld = json_ld(&es);
    assert_eq!(ld["name"]["@value"], "El profeta Daniel");
    assert_eq!(
        ld["description"],
        json!({ "@value": "Soapstone, 1800–1805.", "@language": "en" })
    );
    let de = head("?lang=de", "").await;
    assert!(
        de.contains("og:title\" content=\"The prophet Daniel\""),
        "{de}"
    );

    // oEmbed: the title and credit in the language asked for; the embed
    // opens in it.
    let oembed = |lang: &'static str| {
        let http = http.clone();
        let page = server.url("/m/daniel");
        let url = server.url("/api/oembed");
        async move {
            let reply = http
                .get(url)
                .query(&[("url", page.as_str()), ("lang", lang)])
                .send();
            reply.await.unwrap().json::<Value>().await.unwrap()
        }
    };
    let pt = oembed("pt").await;
    assert_eq!(pt["title"], "O profeta Daniel");
    assert_eq!(pt["author_name"], "Digitalização: Museu da Inconfidência");
    assert!(pt["html"]
        .as_str()
        .unwrap()
        .contains("/embed/daniel?lang=pt"));
    assert_eq!(oembed("fr").await["title"], "The prophet Daniel");

    // IIIF: every language in the maps, keyed by its tag.
    let iiif: Value = json_of(&http, server.url("/iiif/daniel/manifest"), None).await;
    assert_eq!(
        iiif["label"],
        json!({ "en": ["The prophet Daniel"], "pt-BR": ["O profeta Daniel"], "es": ["El profeta Daniel"] })
    );
    assert_eq!(iiif["summary"]["pt-BR"], json!(["Pedra-sabão, 1800–1805."]));
    assert_eq!(
        iiif["requiredStatement"]["value"]["pt-BR"],
        json!(["Digitalização: Museu da Inconfidência"])
    );

    // Replacement drops what the new body leaves out.
    let fewer = json!({ "language": "en", "translations": { "es": { "title": "Daniel" } } });
    let now: Value = put(fewer, Some(&curator))
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert!(now["translations"].get("pt-BR").is_none());

    // A new version is a new scan: its texts start from what its ingest
    // gave.
    ingest(&db, OnExisting::NewVersion).await;
    let v2: Value = json_of(
        &http,
        server.url("/api/admin/models/daniel/versions/2/texts"),
        Some(&curator),
    )
    .await;
    assert_eq!(v2["translations"], json!({}));
}

/// The page's JSON-LD object.
fn json_ld(page: &str) -> Value {
    let start = page.find("application/ld+json\">").expect("JSON-LD") + 21;
    let end = start + page[start..].find("</script>").unwrap();
    serde_json::from_str(&page[start..end].replace("<\\/", "</")).unwrap()
}

/// An annotation with a title and text in further languages: created,
/// kept by a replacement that does not name them, cleared by `{}`, checked;
/// served to the viewer with every language and in IIIF as a language map
/// and a `Choice` of texts, which an import reads back the same.
pub async fn annotations_in_several_languages(db: TestDb) {
    ingest(&db, OnExisting::Refuse).await;
    let curator = token(&db, TokenScope::Curator, None).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let list = server.url("/api/models/daniel/annotations");
    let note = |translations: Value| {
        json!({
            "title": "Chisel marks",
            "text": "Made with a *gradine*.",
            "position": [0.1, 0.2, 0.3],
            "normal": [0.0, 0.0, 1.0],
            "language": "en",
            "translations": translations,
        })
    };
    let pt = json!({ "pt": { "title": "Marcas de cinzel", "text": "Feitas com um *gradim*." } });
    let created = http
        .post(&list)
        .bearer_auth(&curator)
        .json(&note(pt.clone()))
        .send()
        .await
        .unwrap();
    assert_eq!(created.status(), StatusCode::CREATED);
    let created: Value = created.json().await.unwrap();
    let id = created["id"].as_i64().unwrap();
    assert_eq!(
        created["translations"]["pt"]["html"]
            .as_str()
            .unwrap()
            .trim(),
        "<p>Feitas com um <em>gradim</em>.</p>"
    );
    let one = server.url(&format!("/api/models/daniel/annotations/{id}"));

    for (bad, why) in [
        (json!({ "en": { "title": "Own language" } }), "own language"),
        (
            json!({ "pt": { "title": " " } }),
            "the pt title must not be empty",
        ),
        (json!({ "pt!": { "title": "x" } }), "BCP 47"),
    ] {
        let reply = http
            .put(&one)
            .bearer_auth(&curator)
            .json(&note(bad))
            .send()
            .await
            .unwrap();
        assert_eq!(reply.status(), StatusCode::UNPROCESSABLE_ENTITY);
        let message = reply.json::<Value>().await.unwrap()["message"].clone();
        assert!(message.as_str().unwrap().contains(why), "{why}: {message}");
    }
    // A replacement without `translations` keeps them.
    let mut kept = note(Value::Null);
    kept.as_object_mut().unwrap().remove("translations");
    let reply: Value = http
        .put(&one)
        .bearer_auth(&curator)
        .json(&kept)
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(reply["translations"]["pt"]["title"], "Marcas de cinzel");

    // IIIF: the label in both languages, the texts as a Choice.
    let page: Value = json_of(&http, server.url("/iiif/daniel/manifest"), None).await;
    let item = page["annotations"][0]["items"][0].clone();
    assert_eq!(
        item["label"],
        json!({ "en": ["Chisel marks"], "pt": ["Marcas de cinzel"] })
    );
    assert_eq!(item["body"]["type"], "Choice");
    assert_eq!(item["body"]["items"][1]["language"], "pt");

    // The same annotation imported again keeps both languages.
    let cleared: Value = http
        .put(&one)
        .bearer_auth(&curator)
        .json(&note(json!({})))
        .send()
        .await
        .unwrap()
        .json()
        .await
        .unwrap();
    assert_eq!(cleared["translations"], json!({}));
    let import = server.url("/api/admin/models/daniel/annotations/import");
    let reply = http
        .post(&import)
        .bearer_auth(&curator)
        .json(&json!([item]))
        .send()
        .await
        .unwrap();
    assert_eq!(reply.status(), StatusCode::CREATED);
    let all = json_of(&http, &list, None).await;
    let imported = all.as_array().unwrap().last().unwrap().clone();
    assert_eq!(imported["language"], "en");
    assert_eq!(imported["translations"]["pt"]["title"], "Marcas de cinzel");
    assert_eq!(
        imported["translations"]["pt"]["text"],
        "Feitas com um *gradim*."
    );
}
