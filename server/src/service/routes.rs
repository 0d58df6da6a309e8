//! Every route, listed once: the router serves this list, and the OpenAPI
//! description served at `/api/openapi.json` is generated from it (each
//! handler's `#[utoipa::path]` and its types' `ToSchema`).

use super::curator::{admin, annotations, jobs, thumbnail, upload};
use super::error::AppError;
use super::web::{self, Viewer};
use super::{
    api, crawl, download, guard, iiif, oembed, ops, parts, payload, study, texts, tours, AppState,
    ServiceConfig,
};
use axum::http::{header, HeaderValue};
use axum::response::{IntoResponse, Response};
use axum::routing::any;
use bytes::Bytes;
use std::sync::OnceLock;
use utoipa::openapi::security::{HttpAuthScheme, HttpBuilder, SecurityScheme};
use utoipa::openapi::OpenApi as Description;
use utoipa::{Modify, OpenApi};
use utoipa_axum::router::OpenApiRouter;
use utoipa_axum::router::UtoipaMethodRouterExt;
use utoipa_axum::routes;

#[derive(OpenApi)]
#[openapi(
    info(
        title = "Vitrine",
        version = "1",
        description = "Progressive 3D scans for museum websites. A viewer fetches a model's \
            manifest, then the base mesh, then refinement batches 1, 2, … up to the level cap the \
            manifest states. Payloads are immutable: strong ETags, `Cache-Control: immutable`, \
            304 on `If-None-Match`.\n\nLevel cap: the lowest of the audience policy's cap \
            (public exhibition vs. researcher token; the full-resolution level only where the \
            policy allows it), the device class's vertex budget, and the load cap (falls toward \
            the model's good-enough level as server load rises, rises again when it falls). A \
            batch above the cap is refused with 403 (reason `audience` or `device`) or 429 with \
            `Retry-After` (reason `load`).\n\nEvery route may also answer 413 \
            (`payload_too_large`: a body over 64 KiB, an annotation import over 4 MiB, or an upload over `--upload-limit-mb`), 431 (request headers over the limit), \
            500 (`internal`), 503 (`overloaded`: the concurrency limit is full; `Retry-After`) \
            and 504 (`timeout`). Any other path under `/api/` answers 404 (`not_found`)."
    ),
    security((), ("bearer" = [])),
    modifiers(&BearerToken)
)]
struct Api;

struct BearerToken;

impl Modify for BearerToken {
    fn modify(&self, openapi: &mut Description) {
        let scheme = HttpBuilder::new()
            .scheme(HttpAuthScheme::Bearer)
            .description(Some(
                "Access token (`vitrine token create --scope researcher|curator`): a researcher \
                 token opens researcher-only levels; a curator token uploads, annotates and \
                 changes versions. Only ever sent in this header: no cookies, so no CSRF.",
            ))
            .build();
        openapi
            .components
            .get_or_insert_with(Default::default)
            .add_security_scheme("bearer", SecurityScheme::Http(scheme));
    }
}

/// The whole service's routes; the viewer's build serves the pages when
/// `web_dir` has one.
pub fn all(config: &ServiceConfig) -> axum::Router<AppState> {
    let viewer = Viewer::find(&config.web_dir, &config.ui_strings);
    let (router, _) = list(viewer.as_ref()).split_for_parts();
    match viewer {
        Some(viewer) => router.fallback_service(viewer.files()),
        None => router,
    }
}

/// Only `/healthz`, `/readyz`, `/metrics` and the OpenAPI description.
pub fn ops_only() -> axum::Router<AppState> {
    ops_list().split_for_parts().0
}

fn list(viewer: Option<&Viewer>) -> OpenApiRouter<AppState> {
    OpenApiRouter::with_openapi(Api::openapi())
        .routes(routes!(api::list, upload::upload))
        .routes(routes!(api::manifest))
        .routes(routes!(api::licences))
        .routes(routes!(oembed::oembed))
        .routes(routes!(thumbnail::thumbnail))
        .routes(routes!(annotations::list, annotations::create))
        .routes(routes!(annotations::update, annotations::delete))
        .routes(routes!(tours::list))
        .routes(routes!(tours::all, tours::create))
        .routes(routes!(tours::update, tours::delete))
        .routes(routes!(jobs::list))
        .routes(routes!(jobs::job))
        .routes(routes!(admin::versions))
        .routes(routes!(admin::change))
        .routes(routes!(texts::get, texts::put))
        .routes(routes!(payload::base))
        .routes(routes!(payload::batch))
        .routes(routes!(parts::index))
        .routes(routes!(parts::head))
        .routes(routes!(parts::part))
        .routes(routes!(parts::split))
        .routes(routes!(payload::texture))
        .routes(routes!(download::download))
        .routes(routes!(iiif::import::import))
        .routes(routes!(study::info))
        .routes(routes!(study::start, study::plan))
        .routes(routes!(study::answer))
        .routes(routes!(study::views))
        .routes(routes!(study::finish))
        .routes(routes!(study::results))
        // Never the viewer's files. Not described: OpenAPI has no template
        // for "any path below".
        .route(
            "/api/{*rest}",
            any(|| async { AppError::NotFound("route") }),
        )
        .merge(ops_list())
        .routes(web::or_viewer(
            routes!(web::gallery),
            viewer.map(Viewer::page),
        ))
        .routes(routes!(iiif::manifest))
        .routes(routes!(iiif::annotations))
        .routes(routes!(iiif::collection))
        .routes(routes!(crawl::sitemap))
        .routes(routes!(crawl::robots))
        // The model page is always this handler: it adds the Open Graph
        // tags to the viewer's index.html.
        .routes(routes!(web::model_page))
        .routes(web::or_viewer(
            routes!(web::embed_page),
            viewer.map(Viewer::page),
        ))
        .routes(web::or_viewer(
            routes!(web::study_page),
            viewer.map(Viewer::page),
        ))
        // The curators' page is never framed (a click-jacked "withdraw");
        // `/embed/{slug}` is the page other sites frame.
        .routes(
            web::or_viewer(routes!(web::admin_page), viewer.map(Viewer::page))
                .map(|page| page.layer(axum::middleware::map_response(web::not_framed))),
        )
}

fn ops_list() -> OpenApiRouter<AppState> {
    OpenApiRouter::new()
        .routes(routes!(ops::healthz))
        .routes(routes!(ops::readyz))
        .routes(routes!(ops::prometheus))
        .routes(routes!(serve_openapi))
}

/// The OpenAPI description of [`all`]'s routes (which do not depend on the
/// configuration: the viewer only changes who answers the pages).
pub fn openapi() -> &'static Description {
    static DESCRIPTION: OnceLock<Description> = OnceLock::new();
    DESCRIPTION.get_or_init(|| {
        let mut description = list(None).into_openapi();
        guard::describe_refusals(&mut description);
        description
    })
}

// Beside the list it describes: in `ops` it would import that list back.
/// This description, generated from the routes' own types (OpenAPI 3.1).
#[utoipa::path(
    get,
    path = "/api/openapi.json",
    operation_id = "openapi",
    responses((status = 200, description = "OpenAPI 3.1", body = Object))
)]
pub(crate) async fn serve_openapi() -> Response {
    (
        [(
            header::CONTENT_TYPE,
            HeaderValue::from_static("application/json"),
        )],
        openapi_json(),
    )
        .into_response()
}

/// [`openapi`] as served: pretty JSON, built once.
pub fn openapi_json() -> Bytes {
    static JSON: OnceLock<Bytes> = OnceLock::new();
    JSON.get_or_init(|| {
        let mut text = openapi()
            .to_pretty_json()
            .expect("an OpenAPI description serialises");
        text.push('\n');
        Bytes::from(text)
    })
    .clone()
}
