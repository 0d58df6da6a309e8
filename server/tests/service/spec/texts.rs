//! The texts editor's routes (issue 43) against the description.

use super::Spec;
use crate::curators::token;
use crate::harness::{TestDb, TestServer};
use serde_json::json;
use vitrine::storage::TokenScope;

pub(super) async fn text_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    let curator = token(db, TokenScope::Curator, None).await;
    let researcher = token(db, TokenScope::Researcher, None).await;
    let (c, r) = (Some(curator.as_str()), Some(researcher.as_str()));
    let path = "/api/admin/models/open/versions/1/texts";
    let bad_slug = "/api/admin/models/Not_A_Slug/versions/1/texts";
    let missing = "/api/admin/models/open/versions/99/texts";
    let body = json!({ "language": "en", "translations": { "pt": { "title": "Aberto" } } });

    spec.send(server, "get", path, c, None, 200).await;
    spec.send(server, "get", path, None, None, 401).await;
    spec.send(server, "get", path, r, None, 403).await;
    spec.send(server, "get", missing, c, None, 404).await;
    spec.send(server, "get", bad_slug, c, None, 400).await;
    spec.send(server, "put", path, c, Some(body.clone()), 200)
        .await;
    spec.send(server, "put", path, None, Some(body.clone()), 401)
        .await;
    spec.send(server, "put", path, r, Some(body.clone()), 403)
        .await;
    spec.send(server, "put", missing, c, Some(body.clone()), 404)
        .await;
    spec.send(server, "put", bad_slug, c, Some(body), 400).await;
    let bad = json!({ "translations": { "pt": {} } });
    spec.send(server, "put", path, c, Some(bad), 422).await;
    // Back as it was for the calls that follow.
    let none = json!({ "language": null, "translations": {} });
    spec.send(server, "put", path, c, Some(none), 200).await;
}
