//! What search engines read: `/sitemap.xml` lists every public model's page
//! (with the date its visible version was ingested), and `/robots.txt`
//! points to it and keeps crawlers out of the curators' page, the quality
//! study and the API. Together with the model page's schema.org JSON-LD
//! (`web.rs`), a museum's scans are found as its collection pages are.

use super::api::visible_models;
use super::cache_headers;
use super::error::ErrorBody;
use super::visitor::VisitorHints;
use super::web::{escape, page_url, public_base};
use super::AppState;
use crate::service::error::AppError;
use axum::extract::State;
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};

/// Every public model's page.
#[utoipa::path(
    get,
    path = "/sitemap.xml",
    responses(
        (status = 200, description = "Sitemap protocol 0.9 (`Cache-Control: public, max-age=300`)",
            body = String, content_type = "application/xml"),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn sitemap(
    State(state): State<AppState>,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let base = public_base(&state, &headers);
    // As a visitor without a token: a crawler is one.
    let public = VisitorHints::anonymous();
    let mut xml = String::from(
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n\
         <urlset xmlns=\"http://www.sitemaps.org/schemas/sitemap/0.9\">\n",
    );
    for model in visible_models(&state, &public).await? {
        xml.push_str(&format!(
            "  <url><loc>{}</loc>",
            escape(&page_url(&base, &model.slug))
        ));
        if let Some(day) = chrono::DateTime::from_timestamp_millis(model.created_at_ms) {
            xml.push_str(&format!("<lastmod>{}</lastmod>", day.format("%Y-%m-%d")));
        }
        xml.push_str("</url>\n");
    }
    xml.push_str("</urlset>\n");
    Ok(text(xml, "application/xml"))
}

/// Where crawlers may go, and the sitemap.
#[utoipa::path(
    get,
    path = "/robots.txt",
    responses((status = 200, description = "robots.txt (`Cache-Control: public, max-age=300`)",
        body = String, content_type = "text/plain"))
)]
pub async fn robots(State(state): State<AppState>, headers: HeaderMap) -> Response {
    let base = public_base(&state, &headers);
    text(
        format!(
            "User-agent: *\nDisallow: /admin\nDisallow: /study/\nDisallow: /api/\n\
             Allow: /api/models/\nSitemap: {base}/sitemap.xml\n"
        ),
        "text/plain; charset=utf-8",
    )
}

fn text(body: String, media_type: &'static str) -> Response {
    let mut response = body.into_response();
    response
        .headers_mut()
        .insert(header::CONTENT_TYPE, HeaderValue::from_static(media_type));
    cache_headers::anonymous(&mut response, cache_headers::ANONYMOUS);
    response
}
