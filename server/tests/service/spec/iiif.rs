//! The IIIF routes (issue 44) against the description: Manifests, the
//! Collection, annotation pages, and the curators' import.

use super::{call, call_with, Spec};
use crate::curators::token;
use crate::harness::{TestDb, TestServer};
use serde_json::json;
use vitrine::storage::TokenScope;

pub(super) async fn iiif_calls(spec: &mut Spec, server: &TestServer, db: &TestDb) {
    let curator = token(db, TokenScope::Curator, None).await;
    let researcher = token(db, TokenScope::Researcher, None).await;
    let (c, r) = (Some(curator.as_str()), Some(researcher.as_str()));

    let manifest = spec.check(server, call("/iiif/open/manifest", 200)).await;
    let etag = manifest.header("etag");
    let revalidate: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(server, call_with("/iiif/open/manifest", revalidate, 304))
        .await;
    spec.check(server, call("/iiif/vault/manifest", 404)).await;
    spec.check(server, call("/iiif/missing/manifest", 404))
        .await;
    spec.check(server, call("/iiif/Not_A_Slug/manifest", 400))
        .await;
    spec.check(server, call("/iiif/stale/manifest", 409)).await;
    spec.check(server, call("/iiif/cloud/manifest", 200)).await;
    let page = spec
        .check(server, call("/iiif/open/annotations", 200))
        .await;
    let etag = page.header("etag");
    let revalidate: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(server, call_with("/iiif/open/annotations", revalidate, 304))
        .await;
    spec.check(server, call("/iiif/vault/annotations", 404))
        .await;
    spec.check(server, call("/iiif/Not_A_Slug/annotations", 400))
        .await;
    spec.check(server, call("/iiif/stale/annotations", 409))
        .await;
    let collection = spec.check(server, call("/iiif/collection", 200)).await;
    let etag = collection.header("etag");
    let revalidate: &[(&str, &str)] = &[("if-none-match", &etag)];
    spec.check(server, call_with("/iiif/collection", revalidate, 304))
        .await;

    let import = "/api/admin/models/open/annotations/import";
    let one = json!([{
        "type": "Annotation",
        "motivation": ["commenting"],
        "label": { "en": ["Mark"] },
        "target": {
            "type": "SpecificResource",
            "source": { "id": "http://x.example/iiif/open/scene", "type": "Scene" },
            "selector": [{ "type": "PointSelector", "x": 0, "y": 0, "z": 0 }]
        }
    }]);
    spec.send(server, "post", import, c, Some(one.clone()), 201)
        .await;
    spec.send(server, "post", import, None, Some(one.clone()), 401)
        .await;
    spec.send(server, "post", import, r, Some(one.clone()), 403)
        .await;
    spec.send(
        server,
        "post",
        import,
        c,
        Some(json!({"type": "Canvas"})),
        422,
    )
    .await;
    let missing = "/api/admin/models/missing/annotations/import";
    spec.send(server, "post", missing, c, Some(one.clone()), 404)
        .await;
    let bad_slug = "/api/admin/models/Not_A_Slug/annotations/import";
    spec.send(server, "post", bad_slug, c, Some(one.clone()), 400)
        .await;
    let many = json!(vec![one[0].clone(); 5_001]);
    spec.send(server, "post", import, c, Some(many), 413).await;
}
