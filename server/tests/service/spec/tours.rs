//! The guided tours' routes (issue 44) against the description.

use super::{call, Spec};
use crate::curators::token;
use crate::harness::{TestDb, TestServer};
use serde_json::{json, Value};
use vitrine::storage::TokenScope;

fn tour(steps: usize) -> Value {
    let step = json!({
        "view": "camera=0,0,0,3,0.5,0.4",
        "title": { "en": "A view" },
        "text": { "en": "Some *text*." },
    });
    json!({ "title": { "en": "A tour" }, "steps": vec![step; steps] })
}

pub(super) async fn tour_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    let curator = token(db, TokenScope::Curator, None).await;
    let researcher = token(db, TokenScope::Researcher, None).await;
    let (c, r) = (Some(curator.as_str()), Some(researcher.as_str()));
    let admin = "/api/admin/models/open/tours";

    let created = spec
        .send(server, "post", admin, c, Some(tour(2)), 201)
        .await;
    let id = created.json()["id"].as_i64().unwrap();
    spec.send(server, "post", admin, None, Some(tour(2)), 401)
        .await;
    spec.send(server, "post", admin, r, Some(tour(2)), 403)
        .await;
    spec.send(server, "post", admin, c, Some(tour(0)), 422)
        .await;
    let missing = "/api/admin/models/missing/tours";
    spec.send(server, "post", missing, c, Some(tour(1)), 404)
        .await;
    let bad_slug = "/api/admin/models/Not_A_Slug/tours";
    spec.send(server, "post", bad_slug, c, Some(tour(1)), 400)
        .await;
    let mut huge = tour(1);
    huge["steps"][0]["text"]["en"] = json!("x".repeat(1 << 20));
    spec.send(server, "post", admin, c, Some(huge), 413).await;
    spec.send(server, "get", admin, c, None, 200).await;
    spec.send(server, "get", admin, None, None, 401).await;

    spec.check(server, call("/api/models/open/tours", 200))
        .await;
    spec.check(server, call("/api/models/missing/tours", 404))
        .await;

    let one = format!("{admin}/{id}");
    spec.send(server, "put", &one, c, Some(tour(3)), 200).await;
    spec.send(server, "put", &one, c, Some(tour(51)), 422).await;
    let nothing = format!("{admin}/999999");
    spec.send(server, "put", &nothing, c, Some(tour(1)), 404)
        .await;
    spec.send(server, "delete", &one, r, None, 403).await;
    spec.send(server, "delete", &one, c, None, 204).await;
    spec.send(server, "delete", &one, c, None, 404).await;
}
