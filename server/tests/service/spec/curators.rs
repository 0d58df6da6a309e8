//! The curators' routes (issue 22) against the description: thumbnails,
//! annotations, uploads and their jobs, versions, the admin page.

use super::{call, call_with, Spec};
use crate::curators::token;
use crate::harness::{TestDb, TestServer};
use serde_json::json;
use std::time::Duration;
use vitrine::storage::TokenScope;

pub(super) async fn curator_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    let curator = token(db, TokenScope::Curator, None).await;
    let researcher = token(db, TokenScope::Researcher, None).await;
    let (c, r) = (Some(curator.as_str()), Some(researcher.as_str()));

    let png = spec
        .check(server, call("/api/models/open/thumbnail", 200))
        .await;
    let etag = png.header("etag");
    let revalidate: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(
        server,
        call_with("/api/models/open/thumbnail", revalidate, 304),
    )
    .await;
    spec.check(server, call("/api/models/missing/thumbnail", 404))
        .await;
    spec.check(server, call("/api/models/Not_A_Slug/thumbnail", 400))
        .await;

    let list = "/api/models/open/annotations";
    spec.check(server, call(list, 200)).await;
    spec.check(server, call("/api/models/missing/annotations", 404))
        .await;
    let body = json!({"title": "Mark", "text": "*x*", "position": [0, 0, 0], "normal": [0, 1, 0]});
    let created = spec
        .send(server, "post", list, c, Some(body.clone()), 201)
        .await;
    let one = format!("{list}/{}", created.json()["id"]);
    spec.send(server, "post", list, None, Some(body.clone()), 401)
        .await;
    spec.send(server, "post", list, r, Some(body.clone()), 403)
        .await;
    spec.send(server, "post", list, c, Some(json!({"title": "x"})), 422)
        .await;
    spec.send(
        server,
        "post",
        "/api/models/missing/annotations",
        c,
        Some(body.clone()),
        404,
    )
    .await;
    spec.send(server, "put", &one, c, Some(body.clone()), 200)
        .await;
    spec.send(server, "put", &one, None, Some(body.clone()), 401)
        .await;
    spec.send(
        server,
        "put",
        &format!("{list}/999999"),
        c,
        Some(body.clone()),
        404,
    )
    .await;
    spec.send(server, "delete", &one, r, None, 403).await;
    spec.send(server, "delete", &one, c, None, 204).await;
    spec.send(server, "delete", &one, c, None, 404).await;

    let mut ply = Vec::new();
    vitrine_mesh::export::write_ply(&crate::harness::sample_mesh(), &mut ply).unwrap();
    let form = reqwest::multipart::Form::new()
        .text("slug", "uploaded")
        .text("title", "Uploaded")
        .part(
            "file",
            reqwest::multipart::Part::bytes(ply).file_name("u.ply"),
        );
    let request = spec
        .http
        .post(server.url("/api/models"))
        .bearer_auth(&curator)
        .multipart(form);
    let accepted = spec.judge("post", "/api/models", 202, request).await;
    let job = accepted.json()["status_url"].as_str().unwrap().to_owned();
    let without_file = reqwest::multipart::Form::new().text("slug", "x");
    let request = spec
        .http
        .post(server.url("/api/models"))
        .bearer_auth(&curator)
        .multipart(without_file);
    spec.judge("post", "/api/models", 422, request).await;
    spec.send(server, "post", "/api/models", None, None, 401)
        .await;
    spec.send(server, "post", "/api/models", r, None, 403).await;
    for _ in 0..1000 {
        let now = spec.send(server, "get", &job, c, None, 200).await;
        if now.json()["state"] == "done" {
            break;
        }
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
    spec.send(server, "get", "/api/jobs", c, None, 200).await;
    spec.send(server, "get", "/api/jobs", None, None, 401).await;
    spec.send(server, "get", "/api/jobs", r, None, 403).await;
    spec.send(server, "get", "/api/jobs/999999", c, None, 404)
        .await;
    spec.send(server, "get", "/api/jobs/x", c, None, 400).await;

    let versions = "/api/admin/models/open/versions";
    spec.send(server, "get", versions, c, None, 200).await;
    spec.send(server, "get", versions, None, None, 401).await;
    spec.send(server, "get", versions, r, None, 403).await;
    spec.send(
        server,
        "get",
        "/api/admin/models/missing/versions",
        c,
        None,
        404,
    )
    .await;
    let v1 = format!("{versions}/1");
    spec.send(
        server,
        "put",
        &v1,
        c,
        Some(json!({"good_enough_level": 2})),
        200,
    )
    .await;
    spec.send(server, "put", &v1, c, Some(json!({"status": "gone"})), 422)
        .await;
    spec.send(
        server,
        "put",
        &format!("{versions}/9"),
        c,
        Some(json!({})),
        404,
    )
    .await;

    spec.check(server, call("/admin", 200)).await;
}
