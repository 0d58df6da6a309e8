//! The viewer, served from the same binary: the built web app from
//! `web_dir` when it has an `index.html` (every model page gets that page;
//! the app reads the slug from the path), otherwise a minimal built-in
//! gallery so a fresh install shows something.

use super::api::visible_models;
use super::error::AppError;
use super::visitor::VisitorHints;
use super::AppState;
use crate::storage::valid_slug;
use axum::extract::{Path, State};
use axum::http::{header, HeaderValue};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::get;
use axum::Router;
use std::path::Path as FsPath;
use tower_http::services::{ServeDir, ServeFile};

pub fn routes(config: &super::ServiceConfig) -> Router<AppState> {
    let dir: &FsPath = &config.web_dir;
    let index = dir.join("index.html");
    if index.is_file() {
        Router::new()
            .route_service("/m/{slug}", ServeFile::new(&index))
            .route_service("/embed/{slug}", ServeFile::new(&index))
            .fallback_service(ServeDir::new(dir).precompressed_br().precompressed_gzip())
    } else {
        Router::new()
            .route("/", get(gallery))
            .route("/m/{slug}", get(model_page))
            .route("/embed/{slug}", get(model_page))
    }
}

async fn gallery(State(state): State<AppState>, hints: VisitorHints) -> Result<Response, AppError> {
    let mut items = String::new();
    for m in visible_models(&state, &hints).await? {
        items.push_str(&format!(
            "<li><a href=\"/m/{slug}\">{title}</a> <small>({levels} levels)</small></li>\n",
            slug = escape(&m.slug),
            title = escape(&m.title),
            levels = m.batch_count + 1,
        ));
    }
    if items.is_empty() {
        items.push_str("<li>No models yet: <code>vitrine ingest</code> adds one.</li>\n");
    }
    Ok(page(
        "Vitrine",
        &format!("<h1>Vitrine</h1>\n<ul>\n{items}</ul>"),
    ))
}

async fn model_page(
    State(state): State<AppState>,
    Path(slug): Path<String>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
    if !valid_slug(&slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    let record = state.record_by_slug(&slug).await?;
    let visitor = state.visitor(&hints, &record.slug).await?;
    state.ensure_servable(&record, &visitor)?;
    let body = format!(
        "<h1>{title}</h1>\n<p>{description}</p>\n<p>The viewer is not installed on this server; \
         the <a href=\"/api/models/{slug}\">manifest</a> lists the levels it would load.</p>",
        title = escape(&record.title),
        description = escape(&record.description),
        slug = escape(&record.slug),
    );
    Ok(page(&record.title, &body))
}

fn page(title: &str, body: &str) -> Response {
    let html = format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{}</title></head>\n<body>\n{body}\n</body></html>\n",
        escape(title)
    );
    let mut response = Html(html).into_response();
    let headers = response.headers_mut();
    // Ask browsers for the mobile hint on the API calls that follow.
    headers.insert(
        header::HeaderName::from_static("accept-ch"),
        HeaderValue::from_static("Sec-CH-UA-Mobile"),
    );
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    response
}

fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c => out.push(c),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn escapes_markup() {
        assert_eq!(
            super::escape("<b>\"Tom\" & 'Jerry'</b>"),
            "&lt;b&gt;&quot;Tom&quot; &amp; &#39;Jerry&#39;&lt;/b&gt;"
        );
    }
}
