//! With the viewer's build in `web_dir`, its files answer the documented page
//! routes and everything outside `/api`; nothing there needs the database.

use super::broken::{BrokenStorage, Failure};
use super::harness::test_config;
use super::story::get;
use axum::http::{header, StatusCode};
use std::sync::Arc;
use vitrine::{app, AppState};

#[tokio::test]
async fn pages_come_from_the_viewer_build() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("index.html"), "<!doctype html>viewer").unwrap();
    std::fs::write(dir.path().join("app.js"), "export {};").unwrap();
    let mut config = test_config();
    config.web_dir = dir.path().to_owned();
    let storage = Arc::new(BrokenStorage(Failure::Unavailable));
    let app = app(AppState::new(storage, config));

    for uri in ["/", "/m/any-model", "/embed/any-model", "/m/Not_A_Slug"] {
        let r = get(&app, uri, &[]).await;
        assert_eq!(r.status, StatusCode::OK, "{uri}");
        assert_eq!(&r.body[..], b"<!doctype html>viewer", "{uri}");
        assert!(
            r.header(header::CONTENT_TYPE).starts_with("text/html"),
            "{uri}"
        );
    }
    let js = get(&app, "/app.js", &[]).await;
    assert_eq!(js.status, StatusCode::OK);
    assert_eq!(&js.body[..], b"export {};");
    assert_eq!(
        get(&app, "/missing.js", &[]).await.status,
        StatusCode::NOT_FOUND
    );
    // The API stays the API: JSON errors, never the viewer's files.
    let api = get(&app, "/api/no/such/route", &[]).await;
    assert_eq!(api.status, StatusCode::NOT_FOUND);
    assert_eq!(api.json()["error"], "not_found");
    let down = get(&app, "/api/models", &[]).await;
    assert_eq!(down.status, StatusCode::SERVICE_UNAVAILABLE);
}
