//! The fast path for cached public payloads (`vitrine::serving`) answers
//! exactly as the router does, header by header, and steps aside wherever
//! the router's answer could differ.

use super::harness::{ingest_sample, test_config, TestDb};
use super::story::{get, get_from, token_for, Reply};
use axum::http::StatusCode;
use vitrine::{app, serving, AppState};

/// The counter of fast answers, from the service's own `/metrics`.
async fn fast_answers(router: &axum::Router) -> u64 {
    let text = get(router, "/metrics", &[]).await.body;
    let text = String::from_utf8_lossy(&text);
    text.lines()
        .find_map(|l| l.strip_prefix("vitrine_fast_path_answers_total "))
        .map_or(0, |v| v.trim().parse().unwrap())
}

async fn through(
    service: &vitrine::service::FastPayload<axum::Router>,
    uri: &str,
    headers: &[(&str, &str)],
) -> Reply {
    get_from(service.clone(), uri, headers).await
}

fn same(fast: &Reply, router: &Reply, what: &str) {
    assert_eq!(fast.status, router.status, "{what}");
    let strip = |r: &Reply| {
        let mut h = r.headers.clone();
        h.remove("date");
        let mut v: Vec<_> = h
            .iter()
            .map(|(k, v)| (k.to_string(), v.to_str().unwrap().to_owned()))
            .collect();
        v.sort();
        v
    };
    assert_eq!(strip(fast), strip(router), "{what}");
    assert_eq!(fast.body, router.body, "{what}");
}

pub async fn fast_path_answers_as_the_router(db: TestDb) {
    let open = ingest_sample(&*db.storage, "open", "open").await;
    let expo = ingest_sample(&*db.storage, "expo", "exhibition").await;
    let secret = ingest_sample(&*db.storage, "secret", "researchers").await;
    let token = token_for(&db, None).await;
    let bearer = format!("Bearer {token}");
    let state = AppState::new(db.storage.clone(), test_config());
    let router = app(state.clone());
    let served = serving(state);
    let desktop = ("user-agent", "Mozilla/5.0 (X11; Linux x86_64) Chrome/120.0");
    let phone = (
        "user-agent",
        "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0) Mobile/15E148",
    );

    let mut fast = 0;
    for report in [&open, &expo, &secret] {
        let id = report.stored.compression_id;
        let last = report.levels - 1;
        let mut uris = vec![format!("/api/compressions/{id}/base")];
        uris.extend((1..=last + 1).map(|k| format!("/api/compressions/{id}/batches/{k}")));
        for uri in &uris {
            for agent in [desktop, phone] {
                // The first request fills the caches through the router;
                // the second may be the fast path's; the router's own
                // answer must be the same, whatever its status.
                let first = through(&served, uri, &[agent]).await;
                let before = fast_answers(&router).await;
                let second = through(&served, uri, &[agent]).await;
                let took = fast_answers(&router).await - before;
                let reference = get(&router, uri, &[agent]).await;
                same(&second, &reference, &format!("{uri} as {}", agent.1));
                same(&first, &reference, &format!("{uri} (cold) as {}", agent.1));
                if took == 1 {
                    assert_eq!(second.status, StatusCode::OK, "{uri}");
                    fast += 1;
                }
            }
        }
    }
    // Public payloads within the cap were answered fast; refusals (the
    // researchers' model, levels above a phone's or the public cap, a batch
    // past the last) went to the router.
    assert!(fast >= 4, "only {fast} fast answers");
    let id = open.stored.compression_id;
    let phone_cap = serde_json::from_slice::<serde_json::Value>(
        &get(&router, "/api/models/open", &[phone]).await.body,
    )
    .unwrap()["cap"]["level"]
        .as_u64()
        .unwrap();
    let above = format!("/api/compressions/{id}/batches/{}", phone_cap + 1);
    let before = fast_answers(&router).await;
    assert_ne!(
        through(&served, &above, &[phone]).await.status,
        StatusCode::OK
    );
    assert_eq!(fast_answers(&router).await, before, "a phone above its cap");

    // What the fast path leaves to the router, though the payload is cached.
    let uri = format!("/api/compressions/{id}/batches/1");
    let etag = through(&served, &uri, &[desktop]).await.headers["etag"]
        .to_str()
        .unwrap()
        .to_owned();
    let before = fast_answers(&router).await;
    for (uri, headers) in [
        (format!("{uri}?device=desktop"), vec![desktop]),
        (
            uri.clone(),
            vec![desktop, ("authorization", bearer.as_str())],
        ),
        (uri.clone(), vec![desktop, ("if-none-match", etag.as_str())]),
        (format!("/api/compressions/{id}/batches/01"), vec![desktop]),
    ] {
        let fast_reply = through(&served, &uri, &headers).await;
        same(&fast_reply, &get(&router, &uri, &headers).await, &uri);
    }
    assert_eq!(
        fast_answers(&router).await,
        before,
        "each went to the router"
    );
}
