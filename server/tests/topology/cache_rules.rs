//! Every route's `Cache-Control` and `Vary`, asked without and with a token,
//! over real HTTP: immutable payloads, short-lived shared manifests for the
//! public, nothing personal ever `public` (see `service/cache_headers.rs`).

use crate::harness::{ingest_sample, test_config, Backend, TestDb, TestServer};
use reqwest::header::{CACHE_CONTROL, VARY};
use reqwest::Client;
use vitrine::new_token;
use vitrine::storage::{sha256_hex, NewToken, TokenScope};

struct Answer {
    status: u16,
    cache_control: String,
    vary: Vec<String>,
    etag: String,
    allow_origin: String,
    body: String,
}

async fn get(client: &Client, url: &str, token: Option<&str>) -> Answer {
    let mut request = client.get(url);
    if let Some(t) = token {
        request = request.bearer_auth(t);
    }
    answer(request.send().await.unwrap()).await
}

async fn answer(response: reqwest::Response) -> Answer {
    let h = response.headers().clone();
    Answer {
        status: response.status().as_u16(),
        cache_control: h
            .get(CACHE_CONTROL)
            .map(|v| v.to_str().unwrap().to_owned())
            .unwrap_or_default(),
        vary: h
            .get_all(VARY)
            .iter()
            .map(|v| v.to_str().unwrap().to_owned())
            .collect(),
        etag: header(&h, "etag"),
        allow_origin: header(&h, "access-control-allow-origin"),
        body: response.text().await.unwrap(),
    }
}

fn header(headers: &reqwest::header::HeaderMap, name: &str) -> String {
    headers
        .get(name)
        .map(|v| v.to_str().unwrap().to_owned())
        .unwrap_or_default()
}

fn varies_on(a: &Answer, name: &str) -> bool {
    // One line, whatever the layers added (nginx 1.22 reads one).
    assert!(a.vary.len() <= 1, "several Vary lines: {:?}", a.vary);
    a.vary
        .first()
        .is_some_and(|v| v.split(',').any(|n| n.trim().eq_ignore_ascii_case(name)))
}

fn shared_short(a: &Answer) -> bool {
    a.cache_control.starts_with("public, max-age=2,")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_route_says_what_may_be_cached() {
    let db = TestDb::new(Backend::Sqlite).await.unwrap();
    let report = ingest_sample(&*db.storage, "vase", "exhibition-download").await;
    let id = report.stored.compression_id;
    let token = new_token();
    db.storage
        .insert_token(&NewToken {
            token_sha256: sha256_hex(token.as_bytes()),
            label: "cache rules".into(),
            scope: TokenScope::Researcher,
            model_slug: None,
            expires_at_ms: None,
        })
        .await
        .unwrap();
    let server = TestServer::start(db.storage.clone(), test_config()).await;
    let c = Client::new();
    let url = |p: &str| server.url(p);

    // Manifest: shared for the public, varying on the token and on the
    // device hints it was guessed from …
    let public = get(&c, &url("/api/models/vase"), None).await;
    assert_eq!(public.status, 200);
    assert!(shared_short(&public), "{}", public.cache_control);
    assert!(varies_on(&public, "Authorization"));
    assert!(varies_on(&public, "User-Agent") && varies_on(&public, "Sec-CH-UA-Mobile"));
    assert!(public.body.contains("\"audience\":\"public\""));
    // … only on the token when ?device= says the class.
    let explicit = get(&c, &url("/api/models/vase?device=desktop"), None).await;
    assert!(shared_short(&explicit));
    assert!(varies_on(&explicit, "Authorization") && !varies_on(&explicit, "User-Agent"));
    // A researcher's manifest is never shared, by header or by query.
    let researcher = get(&c, &url("/api/models/vase?device=desktop"), Some(&token)).await;
    assert_eq!(researcher.status, 200);
    assert!(researcher.body.contains("\"audience\":\"researcher\""));
    assert_eq!(researcher.cache_control, "private, no-store");
    assert!(varies_on(&researcher, "Authorization"));
    let by_query = get(&c, &url(&format!("/api/models/vase?token={token}")), None).await;
    assert_eq!(by_query.cache_control, "private, no-store");

    // The model list alike.
    let list = get(&c, &url("/api/models"), None).await;
    assert!(shared_short(&list) && varies_on(&list, "Authorization"));
    let list = get(&c, &url("/api/models"), Some(&token)).await;
    assert_eq!(list.cache_control, "private, no-store");

    // Payloads: immutable; public where the public may have them.
    let immutable = "public, max-age=31536000, immutable";
    for token in [None, Some(token.as_str())] {
        let base = get(&c, &url(&format!("/api/compressions/{id}/base")), token).await;
        assert_eq!((base.status, base.cache_control.as_str()), (200, immutable));
        let batch = get(
            &c,
            &url(&format!("/api/compressions/{id}/batches/1")),
            token,
        )
        .await;
        assert_eq!(
            (batch.status, batch.cache_control.as_str()),
            (200, immutable)
        );
    }
    // The last level of an exhibition is the researchers' only.
    let manifest: serde_json::Value = serde_json::from_str(&public.body).unwrap();
    let last = manifest["last_level"].as_u64().unwrap();
    let path = format!("/api/compressions/{id}/batches/{last}");
    let theirs = get(&c, &url(&path), Some(&token)).await;
    assert_eq!(theirs.status, 200);
    assert_eq!(theirs.cache_control, "private, max-age=31536000, immutable");
    let refused = get(&c, &url(&path), None).await;
    assert_eq!(
        (refused.status, refused.cache_control.as_str()),
        (403, "no-store")
    );

    // Downloads are named by slug: never immutable; personal when the
    // level is the visitor's cap or a token was sent.
    let d = get(&c, &url("/api/models/vase/download.glb?level=1"), None).await;
    assert_eq!(d.status, 200);
    assert!(shared_short(&d), "{}", d.cache_control);
    let d = get(&c, &url("/api/models/vase/download.glb"), None).await;
    assert_eq!(
        (d.status, d.cache_control.as_str()),
        (200, "private, no-cache")
    );
    let d = get(
        &c,
        &url("/api/models/vase/download.glb?level=1"),
        Some(&token),
    )
    .await;
    assert_eq!(d.cache_control, "private, no-cache");

    // What every visitor gets alike, token or not: shared for minutes; the
    // licence list for an hour.
    for token in [None, Some(token.as_str())] {
        for p in [
            "/api/oembed?url=http://example.org/m/vase",
            "/sitemap.xml",
            "/robots.txt",
        ] {
            let a = get(&c, &url(p), token).await;
            assert_eq!(
                (a.status, a.cache_control.as_str()),
                (200, "public, max-age=300"),
                "{p}"
            );
        }
        // IIIF: answered as to an anonymous visitor, with a strong ETag and
        // CORS for any origin.
        for p in [
            "/iiif/vase/manifest",
            "/iiif/vase/annotations",
            "/iiif/collection",
        ] {
            let a = get(&c, &url(p), token).await;
            assert_eq!(
                (a.status, a.cache_control.as_str()),
                (200, "public, max-age=300"),
                "{p}"
            );
            assert!(
                a.etag.starts_with('"'),
                "{p}: a strong ETag, not {:?}",
                a.etag
            );
            assert_eq!(a.allow_origin, "*", "{p}");
        }
        let licences = get(&c, &url("/api/licences"), token).await;
        assert_eq!(
            (licences.status, licences.cache_control.as_str()),
            (200, "public, max-age=3600")
        );
    }

    // Errors and health are never cached.
    let missing = get(&c, &url("/api/models/nothing"), None).await;
    assert_eq!(
        (missing.status, missing.cache_control.as_str()),
        (404, "no-store")
    );
    let bad = get(&c, &url("/api/models/vase"), Some("vtr_unknown")).await;
    assert_eq!((bad.status, bad.cache_control.as_str()), (401, "no-store"));
    for p in ["/healthz", "/readyz"] {
        let a = get(&c, &url(p), None).await;
        assert_eq!(a.status, 200);
        assert!(
            !a.cache_control.contains("public"),
            "{p}: {}",
            a.cache_control
        );
    }
    server.shut_down().await;
}

/// The viewer's pages: `no-cache`, their `<html lang dir>` from `?lang=` or
/// `Accept-Language`, and `Vary: Accept-Language` exactly when the header
/// chose it, so a shared cache never hands one visitor's language to another.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn pages_vary_on_the_language_they_negotiated() {
    let db = TestDb::new(Backend::Sqlite).await.unwrap();
    ingest_sample(&*db.storage, "vase", "open").await;
    let web = tempfile::tempdir().unwrap();
    std::fs::write(
        web.path().join("index.html"),
        "<!doctype html>\n<html>\n<head><title>Vitrine</title></head><body></body></html>\n",
    )
    .unwrap();
    let mut config = test_config();
    config.web_dir = web.path().to_owned();
    let server = TestServer::start(db.storage.clone(), config).await;
    let c = Client::new();
    let page = |path: &str, accept: Option<&str>| {
        let mut request = c.get(server.url(path));
        if let Some(a) = accept {
            request = request.header("accept-language", a);
        }
        async move { answer(request.send().await.unwrap()).await }
    };
    for path in ["/", "/m/vase", "/embed/vase", "/study/vase", "/admin"] {
        let asked = page(path, Some("pt-BR,pt;q=0.9,en;q=0.5")).await;
        assert_eq!(
            (asked.status, asked.cache_control.as_str()),
            (200, "no-cache"),
            "{path}"
        );
        assert!(
            asked.body.contains("<html lang=\"pt\" dir=\"ltr\">"),
            "{path}: {}",
            asked.body
        );
        assert!(varies_on(&asked, "Accept-Language"), "{path}");
        let chosen = page(&format!("{path}?lang=ar"), Some("pt")).await;
        assert!(
            chosen.body.contains("<html lang=\"ar\" dir=\"rtl\">"),
            "{path}"
        );
        assert!(!varies_on(&chosen, "Accept-Language"), "{path}");
        let default = page(path, None).await;
        assert!(
            default.body.contains("<html lang=\"en\" dir=\"ltr\">"),
            "{path}"
        );
    }
    server.shut_down().await;
}
