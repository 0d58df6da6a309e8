//! Publishing over real HTTP. Credit line and licence: recorded at ingest
//! or upload, served in the manifest, stated on the model page (`<link
//! rel="license">`, schema.org JSON-LD), carried by GLB downloads (with the
//! up axis and unit applied), changed by a curator without ingesting again;
//! bad values refused. oEmbed for a pasted link; the sitemap and robots.txt.

use super::curators::token;
use super::harness::{test_config, TestDb, TestServer};
use reqwest::StatusCode;
use serde_json::{json, Value};
use vitrine::ingest::{ingest_mesh, IngestOptions, ModelMeta};
use vitrine::storage::{Rights, TokenScope, UpAxis};
use vitrine_codec::{Decoder, Limits};
use vitrine_mesh::import::{import_bytes, ImportOptions, MeshFormat};

const CREDIT: &str = "Scan: Museo de Prueba </script><b>, 2019";
const CC_BY: &str = "https://creativecommons.org/licenses/by/4.0/";

/// A Z-up stele in millimetres: 40 wide (x), 20 deep (y), 120 tall (z).
fn stele() -> vitrine_codec::IndexedMesh {
    let mut mesh = vitrine_samples::icosphere(3);
    for p in &mut mesh.positions {
        p[0] *= 20.0;
        p[1] *= 10.0;
        p[2] *= 60.0;
    }
    mesh
}

/// The JSON chunk of a GLB.
fn glb_json(glb: &[u8]) -> Value {
    let len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    assert_eq!(&glb[16..20], b"JSON");
    serde_json::from_slice(&glb[20..20 + len]).unwrap()
}

/// The body of `GET url` as text.
async fn text(http: &reqwest::Client, url: &str) -> String {
    http.get(url).send().await.unwrap().text().await.unwrap()
}

/// The body of `GET url` as JSON, with a token when given.
pub(crate) async fn json_of(
    http: &reqwest::Client,
    url: impl AsRef<str>,
    token: Option<&str>,
) -> Value {
    let mut request = http.get(url.as_ref());
    if let Some(token) = token {
        request = request.bearer_auth(token);
    }
    request.send().await.unwrap().json().await.unwrap()
}

/// `PUT url` with a curator's JSON body.
async fn put(http: &reqwest::Client, url: &str, token: &str, body: &Value) -> reqwest::Response {
    http.put(url)
        .bearer_auth(token)
        .json(body)
        .send()
        .await
        .unwrap()
}

fn extent(mesh: &vitrine_codec::IndexedMesh, axis: usize) -> f64 {
    let values = mesh.positions.iter().map(|p| f64::from(p[axis]));
    values.clone().fold(f64::MIN, f64::max) - values.fold(f64::MAX, f64::min)
}

pub async fn rights_served_and_carried(db: TestDb) {
    let mut meta = ModelMeta::new("stele", "Stele of the test");
    meta.policy = "open-download".into();
    meta.up = Some(UpAxis::Z);
    meta.unit = Some("mm".into());
    meta.rights = Rights::parse(Some(CREDIT), Some("CC-BY-4.0")).unwrap();
    let report = ingest_mesh(&*db.storage, stele(), meta, &IngestOptions::default())
        .await
        .unwrap();
    // A model with neither.
    let mut plain = ModelMeta::new("plain", "Plain");
    plain.policy = "open".into();
    ingest_mesh(&*db.storage, stele(), plain, &IngestOptions::default())
        .await
        .unwrap();
    // `vitrine models`: the licence of each, and the public ones without.
    let (table, _) = vitrine::models_listing(&*db.storage).await.unwrap();
    let licence_of = |slug: &str| {
        let line = table.lines().find(|l| l.starts_with(slug)).unwrap();
        line.split_whitespace().nth(5).unwrap().to_owned()
    };
    assert_eq!(licence_of("stele"), "CC-BY-4.0", "{table}");
    assert_eq!(licence_of("plain"), "-", "{table}");
    assert!(
        table.contains("; 1 public without a stated licence;"),
        "{table}"
    );
    let curator = token(&db, TokenScope::Curator, None).await;
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let get_json = |path: &str| json_of(&http, server.url(path), None);

    // The manifest.
    let manifest = get_json("/api/models/stele").await;
    assert_eq!(manifest["rights"]["credit"], CREDIT);
    assert_eq!(
        manifest["rights"]["licence"],
        json!({ "id": "CC-BY-4.0", "name": "CC BY 4.0", "url": CC_BY })
    );
    let plain = get_json("/api/models/plain").await;
    assert_eq!(plain["rights"], json!({ "credit": null, "licence": null }));
    assert_eq!(plain["download"], Value::Null, "no downloads under `open`");
    let licences = get_json("/api/licences").await;
    let ids: Vec<&str> = licences["licences"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| l["id"].as_str().unwrap())
        .collect();
    assert!(ids.contains(&"CC0-1.0") && ids.contains(&"InC"), "{ids:?}");

    // The model page: a license link and schema.org JSON-LD whose strings
    // cannot close the script element.
    let page = text(&http, &server.url("/m/stele")).await;
    assert!(
        page.contains(&format!("<link rel=\"license\" href=\"{CC_BY}\">")),
        "{page}"
    );
    let start = page.find("<script type=\"application/ld+json\">").unwrap();
    let script = &page[start + 35..];
    let script = &script[..script.find("</script>").unwrap()];
    assert!(!script.contains("</"), "{script}");
    let data: Value = serde_json::from_str(script).unwrap();
    assert_eq!(data["@type"], "3DModel");
    assert_eq!(data["name"], "Stele of the test");
    assert_eq!(data["license"], CC_BY);
    assert_eq!(data["creditText"], CREDIT);
    assert!(data["url"].as_str().unwrap().ends_with("/m/stele"));
    assert!(data["encoding"][0]["contentUrl"]
        .as_str()
        .unwrap()
        .ends_with("/api/models/stele/download.glb"));
    let plain_page = text(&http, &server.url("/m/plain")).await;
    assert!(!plain_page.contains("rel=\"license\""));
    assert!(
        !plain_page.contains("\"encoding\""),
        "no downloads under `open`"
    );

    // The download: credit and deed in `asset.copyright` and the XMP
    // packet; a node that stands the stele up (+Y) in metres.
    // The manifest offers it: this visitor's cap, the last level here.
    let last = report.levels - 1;
    let offered = &manifest["download"];
    assert_eq!(offered["level"], last);
    let url = server.url(offered["url"].as_str().unwrap());
    assert_eq!(
        url,
        server.url(&format!("/api/models/stele/download.glb?level={last}"))
    );
    let reply = http.get(&url).send().await.unwrap();
    assert_eq!(reply.status(), StatusCode::OK);
    let etag = reply.headers()["etag"].to_str().unwrap().to_owned();
    let glb = reply.bytes().await.unwrap();
    let said = offered["bytes"].as_u64().unwrap();
    assert!(
        said >= glb.len() as u64 && said - (glb.len() as u64) < 2048,
        "{said} for {}",
        glb.len()
    );
    let doc = glb_json(&glb);
    let copyright = doc["asset"]["copyright"].as_str().unwrap();
    assert!(
        copyright.starts_with(CREDIT) && copyright.contains(CC_BY),
        "{copyright}"
    );
    assert_eq!(doc["nodes"][0]["name"], "Stele of the test");
    let packet = &doc["extensions"]["KHR_xmp_json_ld"]["packets"][0];
    assert_eq!(doc["asset"]["extensions"]["KHR_xmp_json_ld"]["packet"], 0);
    assert_eq!(packet["xmpRights:WebStatement"], CC_BY);
    assert_eq!(packet["dc:rights"]["rdf:_1"]["@value"], copyright);
    assert_eq!(packet["dc:title"]["rdf:_1"]["@value"], "Stele of the test");
    super::download::assert_valid_glb(&glb);
    // Read back through the node: the decoded level, turned z → y and
    // scaled mm → m (120 mm tall: 0.12 m along y).
    let compression = report.stored.compression_id;
    let decoded = {
        let base = db.storage.base_payload(compression).await.unwrap().unwrap();
        let mut decoder = Decoder::new(&base, Limits::default()).unwrap();
        for k in 1..=last as u32 {
            let batch = db
                .storage
                .batch_payload(compression, k)
                .await
                .unwrap()
                .unwrap();
            decoder.apply_batch(&batch).unwrap();
        }
        decoder.to_mesh()
    };
    let back = import_bytes(&glb, MeshFormat::Glb, &ImportOptions::default()).unwrap();
    assert_eq!(back.triangles, decoded.triangles);
    for (b, d) in back.positions.iter().zip(&decoded.positions) {
        let want = [
            d[0] as f64 * 0.001,
            d[2] as f64 * 0.001,
            -d[1] as f64 * 0.001,
        ];
        for k in 0..3 {
            assert!(
                (b[k] as f64 - want[k]).abs() < 1e-7,
                "{b:?} against {want:?}"
            );
        }
    }
    assert!((extent(&back, 1) - extent(&decoded, 2) * 0.001).abs() < 1e-6);

    // A curator changes the licence only: the credit stays, the manifest
    // and the download follow, and the download's ETag changes.
    let version = server.url("/api/admin/models/stele/versions/1");
    let changed: Value = put(&http, &version, &curator, &json!({ "licence": "CC0-1.0" }))
        .await
        .json()
        .await
        .unwrap();
    assert_eq!(changed["licence"], "CC0-1.0");
    assert_eq!(changed["credit"], CREDIT);
    let manifest = get_json("/api/models/stele").await;
    assert_eq!(manifest["rights"]["licence"]["id"], "CC0-1.0");
    let again = http
        .get(&url)
        .header("if-none-match", &etag)
        .send()
        .await
        .unwrap();
    assert_eq!(again.status(), StatusCode::OK, "new rights, new ETag");
    assert_ne!(again.headers()["etag"].to_str().unwrap(), etag);
    let doc = glb_json(&again.bytes().await.unwrap());
    assert!(doc["asset"]["copyright"]
        .as_str()
        .unwrap()
        .contains("publicdomain/zero/1.0"));
    // Clearing both: no copyright at all.
    let cleared: Value = put(
        &http,
        &version,
        &curator,
        &json!({ "licence": null, "credit": "" }),
    )
    .await
    .json()
    .await
    .unwrap();
    assert_eq!(cleared["licence"], Value::Null);
    assert_eq!(cleared["credit"], Value::Null);
    let doc = glb_json(&http.get(&url).send().await.unwrap().bytes().await.unwrap());
    assert!(doc["asset"].get("copyright").is_none(), "{doc}");

    // Bad values: an unknown licence, a credit of two lines, a researcher.
    for (body, status) in [
        (
            json!({ "licence": "CC-BY" }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "credit": "a\nb" }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
        (
            json!({ "credit": "x".repeat(301) }),
            StatusCode::UNPROCESSABLE_ENTITY,
        ),
    ] {
        let reply = put(&http, &version, &curator, &body).await;
        assert_eq!(reply.status(), status, "{body}");
    }
    let unknown: Value = put(&http, &version, &curator, &json!({ "licence": "CC-BY" }))
        .await
        .json()
        .await
        .unwrap();
    assert!(
        unknown["message"].as_str().unwrap().contains("CC-BY-4.0"),
        "{unknown}"
    );
    let researcher = token(&db, TokenScope::Researcher, None).await;
    let refused = put(&http, &version, &researcher, &json!({ "licence": "InC" })).await;
    assert_eq!(refused.status(), StatusCode::FORBIDDEN);
    let manifest = get_json("/api/models/stele").await;
    assert_eq!(
        manifest["rights"],
        json!({ "credit": null, "licence": null })
    );
}

/// The upload form's `unit`, `up`, `credit` and `licence`: recorded as
/// given; bad values refused before any job starts.
pub async fn rights_and_placement_through_uploads(db: TestDb) {
    use super::uploads::{form, job_until_finished, sample_ply, upload_config};
    let spool = tempfile::tempdir().unwrap();
    let curator = token(&db, TokenScope::Curator, None).await;
    let server = TestServer::start(db.storage.clone(), upload_config(spool.path())).await;
    let http = reqwest::Client::new();
    let upload = server.url("/api/models");
    let with = |fields: &[(&'static str, &'static str)]| {
        let mut form = form("vase.ply", sample_ply(), "vase");
        for &(name, value) in fields {
            form = form.text(name, value);
        }
        http.post(&upload)
            .bearer_auth(&curator)
            .multipart(form)
            .send()
    };
    for (fields, says) in [
        (
            &[("licence", "CC BY")][..],
            "licence \"CC BY\" must be one of",
        ),
        (&[("unit", "ft")][..], "unit \"ft\""),
        (&[("up", "w")][..], "up: \"w\""),
        (&[("credit", "one\ntwo")][..], "one line"),
    ] {
        let reply = with(fields).await.unwrap();
        assert_eq!(
            reply.status(),
            StatusCode::UNPROCESSABLE_ENTITY,
            "{fields:?}"
        );
        let body: Value = reply.json().await.unwrap();
        assert!(body["message"].as_str().unwrap().contains(says), "{body}");
    }
    let jobs: Value = json_of(&http, &server.url("/api/jobs"), Some(&curator)).await;
    assert_eq!(jobs["jobs"], json!([]), "refused forms start no job");

    let reply = with(&[
        ("unit", "cm"),
        ("up", "-z"),
        ("credit", "Photogrammetry: Vitrine test lab"),
        ("licence", "InC-EDU"),
    ])
    .await
    .unwrap();
    assert_eq!(reply.status(), StatusCode::ACCEPTED);
    let accepted: Value = reply.json().await.unwrap();
    let status = server.url(accepted["status_url"].as_str().unwrap());
    let done = job_until_finished(&http, &status, &curator).await;
    assert_eq!(done["state"], "done", "{done}");
    let manifest: Value = json_of(&http, &server.url("/api/models/vase"), None).await;
    assert_eq!(manifest["unit"], "cm");
    assert_eq!(manifest["up"], "-z");
    assert_eq!(
        manifest["rights"]["credit"],
        "Photogrammetry: Vitrine test lab"
    );
    assert_eq!(manifest["rights"]["licence"]["id"], "InC-EDU");
    assert_eq!(
        manifest["rights"]["licence"]["url"],
        "http://rightsstatements.org/vocab/InC-EDU/1.0/"
    );
}

/// oEmbed: a pasted model link becomes the embedded viewer, for public
/// models only; the model page announces the endpoint.
pub async fn oembed_for_pasted_links(db: TestDb) {
    let mut meta = ModelMeta::new("stele", "Stele \"A\" <1>");
    meta.policy = "open".into();
    meta.rights = Rights::parse(Some(CREDIT), Some("CC-BY-4.0")).unwrap();
    ingest_mesh(&*db.storage, stele(), meta, &IngestOptions::default())
        .await
        .unwrap();
    let mut hidden = ModelMeta::new("hidden", "Hidden");
    hidden.policy = "researchers".into();
    ingest_mesh(&*db.storage, stele(), hidden, &IngestOptions::default())
        .await
        .unwrap();
    // A viewer build whose page the model route fills in.
    let web = tempfile::tempdir().unwrap();
    std::fs::write(
        web.path().join("index.html"),
        "<!doctype html><html><head><title>Vitrine</title></head><body></body></html>",
    )
    .unwrap();
    let mut config = test_config();
    config.site_name = "Museo de Prueba".into();
    config.web_dir = web.path().to_owned();
    let server = TestServer::start(db.storage.clone(), config).await;
    let http = reqwest::Client::new();
    let ask = |query: &[(&str, &str)]| http.get(server.url("/api/oembed")).query(query).send();

    // Discovery: the page's link, followed as a CMS would.
    let page = text(&http, &server.url("/m/stele")).await;
    let marker = "type=\"application/json+oembed\" href=\"";
    let href = &page[page.find(marker).unwrap() + marker.len()..];
    let href = href[..href.find('"').unwrap()].replace("&amp;", "&");
    assert!(href.starts_with(&server.url("/api/oembed?url=")), "{href}");
    let reply = http.get(&href).send().await.unwrap();
    assert_eq!(reply.status(), StatusCode::OK);
    assert_eq!(reply.headers()["cache-control"], "public, max-age=300");
    let embed: Value = reply.json().await.unwrap();
    assert_eq!(embed["type"], "rich");
    assert_eq!(embed["version"], "1.0");
    assert_eq!(embed["title"], "Stele \"A\" <1>");
    assert_eq!(embed["author_name"], CREDIT);
    assert_eq!(embed["provider_name"], "Museo de Prueba", "--site-name");
    assert!(page.contains("<meta property=\"og:site_name\" content=\"Museo de Prueba\">"));
    // The page's title, description and canonical link before any script runs.
    assert!(
        page.contains("<title>Stele &quot;A&quot; &lt;1&gt; · Museo de Prueba</title>")
            && page.matches("<title>").count() == 1,
        "{page}"
    );
    assert!(page.contains(&format!(
        "<link rel=\"canonical\" href=\"{}\">",
        server.url("/m/stele")
    )));
    assert!(page.contains("<meta name=\"application-name\" content=\"Museo de Prueba\">"));
    assert_eq!(
        (embed["width"].as_u64(), embed["height"].as_u64()),
        (Some(800), Some(600))
    );
    let html = embed["html"].as_str().unwrap();
    assert!(
        html.starts_with(&format!("<iframe src=\"{}\"", server.url("/embed/stele"))),
        "{html}"
    );
    assert!(
        html.contains("title=\"Stele &quot;A&quot; &lt;1&gt;\""),
        "{html}"
    );
    assert!(embed["thumbnail_url"]
        .as_str()
        .unwrap()
        .contains("/api/models/stele/thumbnail?v=1"));
    // The embed the iframe opens is served.
    let frame = http.get(server.url("/embed/stele")).send().await.unwrap();
    assert_eq!(frame.status(), StatusCode::OK);
    assert!(frame.headers().get("x-frame-options").is_none());
    // The curators' page is never framed.
    let admin = http.get(server.url("/admin")).send().await.unwrap();
    assert_eq!(admin.headers()["x-frame-options"], "DENY");
    assert_eq!(
        admin.headers()["content-security-policy"],
        "frame-ancestors 'none'"
    );

    // Bounds, another host's name for the site, an embed link.
    let small: Value = ask(&[
        ("url", "https://museo.example/embed/stele?x=1"),
        ("maxwidth", "500"),
        ("maxheight", "300"),
    ])
    .await
    .unwrap()
    .json()
    .await
    .unwrap();
    assert_eq!(
        (small["width"].as_u64(), small["height"].as_u64()),
        (Some(400), Some(300))
    );
    // Restricted, unknown, not a model page, XML, no url.
    for (query, status) in [
        (
            vec![("url", "https://museo.example/m/hidden")],
            StatusCode::NOT_FOUND,
        ),
        (
            vec![("url", "https://museo.example/m/nowhere")],
            StatusCode::NOT_FOUND,
        ),
        (
            vec![("url", "https://museo.example/admin")],
            StatusCode::NOT_FOUND,
        ),
        (
            vec![("url", "https://museo.example/m/stele"), ("format", "xml")],
            StatusCode::NOT_IMPLEMENTED,
        ),
        (vec![], StatusCode::BAD_REQUEST),
    ] {
        let reply = ask(&query).await.unwrap();
        assert_eq!(reply.status(), status, "{query:?}");
    }
    // A restricted model's page is the bare viewer (which says it cannot
    // open it): no title, tags or oEmbed link of the model.
    let hidden_page = text(&http, &server.url("/m/hidden")).await;
    assert!(
        hidden_page.contains("<title>Vitrine</title>"),
        "{hidden_page}"
    );
    assert!(!hidden_page.contains("oembed") && !hidden_page.contains("Hidden"));
}

/// The sitemap lists public models' pages and nothing else; robots.txt
/// points to it and keeps crawlers out of the curators' page and studies.
pub async fn crawlers_find_public_models(db: TestDb) {
    for (slug, policy) in [
        ("stele", "open"),
        ("vase", "exhibition"),
        ("hidden", "researchers"),
    ] {
        let mut meta = ModelMeta::new(slug, slug);
        meta.policy = policy.into();
        ingest_mesh(&*db.storage, stele(), meta, &IngestOptions::default())
            .await
            .unwrap();
    }
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let http = reqwest::Client::new();
    let reply = http.get(server.url("/sitemap.xml")).send().await.unwrap();
    assert_eq!(reply.status(), StatusCode::OK);
    assert_eq!(reply.headers()["content-type"], "application/xml");
    let xml = reply.text().await.unwrap();
    assert!(xml.starts_with("<?xml") && xml.contains("sitemaps.org/schemas/sitemap/0.9"));
    let locs: Vec<&str> = xml
        .split("<loc>")
        .skip(1)
        .map(|s| &s[..s.find("</loc>").unwrap()])
        .collect();
    assert_eq!(
        locs,
        [server.url("/m/stele"), server.url("/m/vase")],
        "{xml}"
    );
    let today = chrono::Utc::now().format("%Y-%m-%d").to_string();
    assert_eq!(
        xml.matches(&format!("<lastmod>{today}</lastmod>")).count(),
        2,
        "{xml}"
    );
    let robots = text(&http, &server.url("/robots.txt")).await;
    for line in [
        "Disallow: /admin",
        "Disallow: /study/",
        "Disallow: /api/",
        "Allow: /api/models/",
    ] {
        assert!(robots.lines().any(|l| l == line), "{line}: {robots}");
    }
    assert!(robots.contains(&format!("Sitemap: {}", server.url("/sitemap.xml"))));
}
