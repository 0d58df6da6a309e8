//! The viewer, served from the same binary: the built web app from
//! `web_dir` when it has an `index.html` (every model page gets that page;
//! the app reads the slug from the path), otherwise a minimal built-in
//! gallery so a fresh install shows something.

use super::api::visible_models;
use super::cache_headers;
use super::curator::thumbnail;
use super::error::{AppError, ErrorBody};
use super::language::{ContentLanguages, PageLanguage};
use super::servable::{PathParams, ServableModel, SlugParam};
use super::study::StudySlug;
use super::ui_strings::UiStrings;
use super::visitor::{HintQuery, VisitorHints};
use super::AppState;
use crate::storage::{valid_slug, Localized, ModelKind, ModelRecord};
use axum::extract::{Request, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, get_service, MethodRouter};
use serde_json::json;
use std::convert::Infallible;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tower::Service;
use tower_http::services::ServeDir;
use utoipa_axum::router::{UtoipaMethodRouter, UtoipaMethodRouterExt};

/// The built web app, when `web_dir` has an `index.html`.
pub struct Viewer {
    dir: PathBuf,
    index: PathBuf,
    /// The museum's own words, as each page carries them (`UiStrings::script`).
    strings: Arc<str>,
}

impl Viewer {
    pub fn find(dir: &Path, strings: &UiStrings) -> Option<Viewer> {
        let index = dir.join("index.html");
        index.is_file().then(|| Viewer {
            dir: dir.to_owned(),
            index,
            strings: strings.script().into(),
        })
    }

    /// The build's files, precompressed where it has `.br` or `.gz` beside them.
    pub fn files(&self) -> ServeDir {
        ServeDir::new(&self.dir)
            .precompressed_br()
            .precompressed_gzip()
    }

    /// The page every page route gets (the app reads the slug from the
    /// path), its `<html lang dir>` in the visitor's language.
    pub fn page(&self) -> MethodRouter {
        let index = self.index.clone();
        let strings = self.strings.clone();
        get(move |language: PageLanguage| {
            let index = index.clone();
            let strings = strings.clone();
            async move {
                let html = read_index(&index)
                    .await?
                    .ok_or_else(|| AppError::Internal(format!("{} is gone", index.display())))?;
                Ok::<_, AppError>(html_response(&html, language, &strings))
            }
        })
    }
}

/// The viewer's `index.html`, `None` when there is no build.
async fn read_index(index: &Path) -> Result<Option<String>, AppError> {
    match tokio::fs::read_to_string(index).await {
        Ok(html) => Ok(Some(html)),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => Ok(None),
        Err(e) => Err(AppError::Internal(format!(
            "reading {}: {e}",
            index.display()
        ))),
    }
}

/// A documented page route, served by the viewer's build when there is one
/// and by its built-in handler otherwise.
pub fn or_viewer<T>(
    route: UtoipaMethodRouter<AppState>,
    viewer: Option<T>,
) -> UtoipaMethodRouter<AppState>
where
    T: Service<Request, Error = Infallible> + Clone + Send + Sync + 'static,
    T::Response: IntoResponse + 'static,
    T::Future: Send + 'static,
{
    route.map(|handler| viewer.map_or(handler, get_service))
}

/// Refuses to be shown inside another site's frame.
pub async fn not_framed(mut response: Response) -> Response {
    let headers = response.headers_mut();
    headers.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    headers.insert(
        header::CONTENT_SECURITY_POLICY,
        HeaderValue::from_static("frame-ancestors 'none'"),
    );
    response
}

/// Gallery (the viewer's index.html, or a built-in list).
#[utoipa::path(
    get,
    path = "/",
    params(HintQuery),
    responses(
        (status = 200, description = "HTML", body = String, content_type = "text/html"),
        (status = 400, description = "Malformed query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn gallery(
    State(state): State<AppState>,
    hints: VisitorHints,
) -> Result<Response, AppError> {
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

/// Model page (the viewer's index.html), with Open Graph tags (`og:title`,
/// `og:description`, `og:image`: the thumbnail) so shared links preview.
#[utoipa::path(
    get,
    path = "/m/{slug}",
    params(SlugParam, HintQuery),
    responses(
        (status = 200, description = "HTML", body = String, content_type = "text/html"),
        (status = 400, description = "Malformed slug, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode",
            body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn model_page(
    State(state): State<AppState>,
    headers: HeaderMap,
    language: PageLanguage,
    languages: ContentLanguages,
    model: Result<ServableModel, AppError>,
) -> Result<Response, AppError> {
    let viewer = read_index(&state.config().web_dir.join("index.html")).await?;
    let strings = state.config().ui_strings.script();
    match (viewer, model) {
        (Some(html), Ok(model)) => {
            let record = &model.record;
            let texts = localized(record, &languages);
            let tags = open_graph(&state, &headers, record, &texts);
            // The page's own title, as search results and tabs show it
            // before any script runs.
            let title = format!(
                "<title>{} · {}</title>",
                escape(texts.title.text),
                escape(&state.config().site_name)
            );
            let html = match (html.find("<title>"), html.find("</title>")) {
                (Some(start), Some(end)) if start < end => {
                    format!(
                        "{}{title}{}",
                        &html[..start],
                        &html[end + "</title>".len()..]
                    )
                }
                _ => html,
            };
            let html = match html.find("</head>") {
                Some(at) => format!("{}{tags}{}", &html[..at], &html[at..]),
                None => format!("{tags}{html}"),
            };
            Ok(html_response(&html, language, &strings))
        }
        // The viewer shows its own message for a model it cannot open.
        (Some(html), Err(_)) => Ok(html_response(&html, language, &strings)),
        (None, Ok(model)) => {
            let texts = localized(&model.record, &languages);
            let tags = open_graph(&state, &headers, &model.record, &texts);
            Ok(built_in_page(model, &tags))
        }
        (None, Err(e)) => Err(e),
    }
}

/// The absolute base of links in the page: `--public-base-url`, else the
/// request's `Host` (with `X-Forwarded-Proto`'s scheme behind a proxy).
pub(super) fn public_base(state: &AppState, headers: &HeaderMap) -> String {
    if let Some(base) = &state.config().uploads.public_base_url {
        return base.trim_end_matches('/').to_owned();
    }
    let host = headers
        .get(header::HOST)
        .and_then(|h| h.to_str().ok())
        .filter(|h| {
            h.bytes()
                .all(|b| b.is_ascii_alphanumeric() || b".-:[]".contains(&b))
        })
        .unwrap_or("localhost");
    let scheme = match headers
        .get("x-forwarded-proto")
        .and_then(|h| h.to_str().ok())
    {
        Some("https") => "https",
        _ => "http",
    };
    format!("{scheme}://{host}")
}

/// The absolute URL of a model's page.
pub(super) fn page_url(base: &str, slug: &str) -> String {
    format!("{base}/m/{slug}")
}

/// A version's texts in the visitor's languages.
pub(super) fn localized<'a>(
    record: &'a ModelRecord,
    languages: &ContentLanguages,
) -> Localized<'a> {
    record.texts.localize(
        &record.title,
        &record.description,
        record.curation.rights.credit.as_deref(),
        &languages.wanted,
    )
}

/// `og:` meta tags of a model, its texts in the visitor's language.
fn open_graph(
    state: &AppState,
    headers: &HeaderMap,
    record: &ModelRecord,
    texts: &Localized,
) -> String {
    let base = public_base(state, headers);
    let page = page_url(&base, &record.slug);
    let mut tags = format!(
        "<meta name=\"application-name\" content=\"{site}\">\n\
         <meta name=\"description\" content=\"{description}\">\n\
         <link rel=\"canonical\" href=\"{page}\">\n\
         <meta property=\"og:site_name\" content=\"{}\">\n\
         <meta property=\"og:type\" content=\"website\">\n\
         <meta property=\"og:title\" content=\"{}\">\n\
         <meta property=\"og:description\" content=\"{}\">\n\
         <meta property=\"og:url\" content=\"{}\">\n",
        escape(&state.config().site_name),
        escape(texts.title.text),
        escape(texts.description.text),
        escape(&page),
        site = escape(&state.config().site_name),
        description = escape(texts.description.text.trim()),
        page = escape(&page),
    );
    if let Some(language) = texts.title.language {
        // Open Graph writes a locale as ll_CC.
        tags.push_str(&format!(
            "<meta property=\"og:locale\" content=\"{}\">\n",
            escape(&language.replace('-', "_"))
        ));
    }
    if record.curation.thumbnail_sha256.is_some() {
        tags.push_str(&format!(
            "<meta property=\"og:image\" content=\"{}\">\n\
             <meta property=\"og:image:type\" content=\"image/png\">\n",
            escape(&format!(
                "{base}{}",
                thumbnail::url(&record.slug, record.version)
            ))
        ));
    }
    // oEmbed discovery: a CMS given this page's link embeds the viewer
    // (public models only: a CMS asks without a token).
    if record.policy.public_access {
        tags.push_str(&format!(
            "<link rel=\"alternate\" type=\"application/json+oembed\" href=\"{}\" title=\"{}\">\n",
            escape(&format!(
                "{base}/api/oembed?{}",
                serde_urlencoded::to_string([("url", page.as_str())]).unwrap_or_default()
            )),
            escape(texts.title.text)
        ));
    }
    if let Some(licence) = record.curation.rights.licence {
        tags.push_str(&format!(
            "<link rel=\"license\" href=\"{}\">\n",
            escape(licence.url)
        ));
    }
    tags.push_str(&structured_data(record, texts, &base));
    tags
}

/// The model as schema.org's `3DModel` (JSON-LD), with its credit and
/// licence, so search engines can show them (and the GLB download, where
/// every visitor may take it).
fn structured_data(record: &ModelRecord, texts: &Localized, base: &str) -> String {
    let mut model = json!({
        "@context": "https://schema.org",
        "@type": "3DModel",
        "name": tagged(texts.title.text, texts.title.language),
        "url": page_url(base, &record.slug),
    });
    let description = texts.description.text.trim();
    if !description.is_empty() {
        model["description"] = tagged(description, texts.description.language);
    }
    if record.curation.thumbnail_sha256.is_some() {
        model["image"] = format!("{base}{}", thumbnail::url(&record.slug, record.version)).into();
    }
    let rights = &record.curation.rights;
    if let Some(credit) = texts.credit {
        model["creditText"] = tagged(credit.text, credit.language);
    }
    if let Some(licence) = rights.licence {
        model["license"] = licence.url.into();
    }
    if let Some(notice) = rights.notice() {
        model["copyrightNotice"] = notice.into();
    }
    if record.policy.downloads && record.policy.public_access && record.kind == ModelKind::Mesh {
        model["encoding"] = json!([{
            "@type": "MediaObject",
            "contentUrl": format!("{base}/api/models/{}/download.glb", record.slug),
            "encodingFormat": "model/gltf-binary",
        }]);
    }
    // `</script>` in a title must not end the element: JSON allows `<\/`.
    let text = model.to_string().replace("</", "<\\/");
    format!("<script type=\"application/ld+json\">{text}</script>\n")
}

/// A JSON-LD string value marked with its language where it is known
/// (`{"@value", "@language"}`), so a search engine knows which language
/// each text of the page is in.
fn tagged(text: &str, language: Option<&str>) -> serde_json::Value {
    match language {
        Some(language) => json!({ "@value": text, "@language": language }),
        None => text.into(),
    }
}

/// The viewer's page in `language` (its `<html lang dir>`), the museum's
/// own words (`strings`, a script element or nothing) before `</head>`,
/// with the headers every page has.
fn html_response(html: &str, language: PageLanguage, strings: &str) -> Response {
    let html = match html.find("</head>") {
        Some(at) if !strings.is_empty() => format!("{}{strings}{}", &html[..at], &html[at..]),
        _ => html.to_owned(),
    };
    let mut response = Html(language.apply(&html)).into_response();
    response.headers_mut().insert(
        header::HeaderName::from_static("accept-ch"),
        HeaderValue::from_static("Sec-CH-UA-Mobile"),
    );
    cache_headers::page(&mut response, language);
    response
}

/// The curators' page (the viewer's index.html, which opens `web/src/admin/`
/// at this path). Without the viewer's build, a page that says so.
#[utoipa::path(
    get,
    path = "/admin",
    responses((status = 200, description = "HTML", body = String, content_type = "text/html"))
)]
pub async fn admin_page() -> Response {
    page(
        "Vitrine admin",
        "<h1>Vitrine admin</h1>\n<p>The admin page needs the viewer's build, which is not \
         installed on this server; the API it uses is described at \
         <a href=\"/api/openapi.json\">/api/openapi.json</a>.</p>",
    )
}

/// Embeddable model view (the viewer's index.html).
#[utoipa::path(
    get,
    path = "/embed/{slug}",
    params(SlugParam, HintQuery),
    responses(
        (status = 200, description = "HTML", body = String, content_type = "text/html"),
        (status = 400, description = "Malformed slug, query or `Authorization`", body = ErrorBody),
        (status = 401, description = "The token is unknown, revoked or expired", body = ErrorBody),
        (status = 404, description = "No such model", body = ErrorBody),
        (status = 409, description = "Stored in a stream format this build cannot decode",
            body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn embed_page(model: ServableModel) -> Response {
    built_in_page(model, "")
}

/// Quality study page (the viewer's index.html; the invitation is in its
/// `?invitation=`). Without the viewer's build, a page that says so.
#[utoipa::path(
    get,
    path = "/study/{slug}",
    params(StudySlug),
    responses(
        (status = 200, description = "HTML", body = String, content_type = "text/html"),
        (status = 400, description = "Malformed slug", body = ErrorBody),
    )
)]
pub async fn study_page(
    PathParams(StudySlug { slug }): PathParams<StudySlug>,
) -> Result<Response, AppError> {
    if !valid_slug(&slug) {
        return Err(AppError::BadRequest(format!(
            "{slug:?} is not a model slug"
        )));
    }
    Ok(page(
        "Quality study",
        "<h1>Quality study</h1>\n<p>The study needs the viewer, which is not installed on this \
         server.</p>",
    ))
}

fn built_in_page(ServableModel { record, .. }: ServableModel, head: &str) -> Response {
    let body = format!(
        "<h1>{title}</h1>\n<p>{description}</p>\n<p>The viewer is not installed on this server; \
         the <a href=\"/api/models/{slug}\">manifest</a> lists the levels it would load.</p>",
        title = escape(&record.title),
        description = escape(&record.description),
        slug = escape(&record.slug),
    );
    page_with_head(&record.title, head, &body)
}

fn page(title: &str, body: &str) -> Response {
    page_with_head(title, "", body)
}

fn page_with_head(title: &str, head: &str, body: &str) -> Response {
    let html = format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\
         <title>{}</title>\n{head}</head>\n<body>\n{body}\n</body></html>\n",
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

/// Text for HTML (and XML) content and double- or single-quoted attributes.
pub(super) fn escape(text: &str) -> String {
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
