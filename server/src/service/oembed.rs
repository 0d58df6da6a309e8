//! `GET /api/oembed?url=…` (oEmbed 1.0, <https://oembed.com>): a museum's
//! CMS (WordPress, Drupal, Omeka…) turns a pasted model link into the
//! embedded viewer. The model page announces the endpoint with a
//! `<link rel="alternate" type="application/json+oembed">`. Only models any
//! visitor may see are embedded: a CMS asks without a token, and what it
//! gets is published on pages everyone reads.

use super::cache_headers;
use super::error::{AppError, ErrorBody};
use super::language::ContentLanguages;
use super::servable::ServableModel;
use super::visitor::VisitorHints;
use super::web::{escape, localized, public_base};
use super::AppState;
use crate::storage::{valid_slug, ModelRecord};
use axum::extract::{RawQuery, State};
use axum::http::{header, HeaderMap, HeaderValue};
use axum::response::{IntoResponse, Response};
use axum::Json;
use serde::{Deserialize, Serialize};
use utoipa::{IntoParams, ToSchema};

/// The embed's width when the consumer states no bounds (4:3: 600 tall).
const WIDTH: u32 = 800;
/// The smallest embed worth drawing a viewer in.
const MIN_SIDE: u32 = 120;

#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct OembedQuery {
    /// A model page (`…/m/{slug}`) or embed (`…/embed/{slug}`) URL.
    url: String,
    /// Widest embed the consumer has room for, in CSS pixels.
    maxwidth: Option<u32>,
    /// Tallest embed the consumer has room for, in CSS pixels.
    maxheight: Option<u32>,
    /// `json` (the default); `xml` answers 501.
    format: Option<String>,
    /// The language of the title and credit (a BCP 47 tag), with a
    /// fallback to the model's own; absent: `Accept-Language`. The embed
    /// opens in it too.
    lang: Option<String>,
}

/// An oEmbed `rich` response: an `<iframe>` of `/embed/{slug}`.
#[derive(Serialize, ToSchema)]
pub struct Oembed {
    /// `rich`.
    r#type: &'static str,
    /// `1.0`.
    version: &'static str,
    title: String,
    /// The version's credit line, when recorded.
    #[serde(skip_serializing_if = "Option::is_none")]
    author_name: Option<String>,
    /// `--site-name`.
    provider_name: String,
    provider_url: String,
    /// Seconds a consumer may keep this answer.
    cache_age: u32,
    html: String,
    width: u32,
    height: u32,
    #[serde(skip_serializing_if = "Option::is_none")]
    thumbnail_url: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    thumbnail_width: Option<u32>,
    #[serde(skip_serializing_if = "Option::is_none")]
    thumbnail_height: Option<u32>,
}

/// The embedded viewer for a pasted model link.
#[utoipa::path(
    get,
    path = "/api/oembed",
    params(OembedQuery),
    responses(
        (status = 200, description = "oEmbed 1.0 `rich` response (`Cache-Control: public, max-age=300`)", body = Oembed),
        (status = 400, description = "No `url`, or a malformed query", body = ErrorBody),
        (status = 404, description = "The URL is not a model page here, or not a public model", body = ErrorBody),
        (status = 501, description = "`format` other than json", body = ErrorBody),
        (status = 503, description = "Database unavailable or server overloaded", body = ErrorBody),
    )
)]
pub async fn oembed(
    State(state): State<AppState>,
    RawQuery(query): RawQuery,
    headers: HeaderMap,
) -> Result<Response, AppError> {
    let query: OembedQuery = serde_urlencoded::from_str(query.as_deref().unwrap_or(""))
        .map_err(|e| AppError::BadRequest(format!("query: {e}")))?;
    if let Some(format) = query.format.as_deref().filter(|f| *f != "json") {
        return Err(AppError::NotImplemented(format!(
            "oEmbed format {format:?} is not served: ask for json"
        )));
    }
    let slug = model_slug(&query.url).ok_or(AppError::NotFound("model page"))?;
    let record = state.record_by_slug(slug).await?;
    // As a visitor without a token (a restricted model does not exist for
    // it): the consumer publishes what it gets.
    let public = VisitorHints::anonymous();
    let model = ServableModel::decide(&state, record, &public).await?;
    let base = public_base(&state, &headers);
    let (width, height) = fit(query.maxwidth, query.maxheight);
    let site = state.config().site_name.clone();
    let accept = headers
        .get(header::ACCEPT_LANGUAGE)
        .and_then(|v| v.to_str().ok());
    let languages = ContentLanguages::choose(query.lang.as_deref(), accept);
    let mut response = Json(answer(
        &model.record,
        &base,
        site,
        (width, height),
        &languages,
    ))
    .into_response();
    cache_headers::anonymous(&mut response, cache_headers::ANONYMOUS);
    if languages.negotiated {
        response
            .headers_mut()
            .append(header::VARY, HeaderValue::from_static("Accept-Language"));
    }
    Ok(response)
}

fn answer(
    record: &ModelRecord,
    base: &str,
    site: String,
    (width, height): (u32, u32),
    languages: &ContentLanguages,
) -> Oembed {
    let texts = localized(record, languages);
    // The embed opens in the language the title was chosen for.
    let src = match &languages.asked {
        Some(lang) => format!("{base}/embed/{}?lang={lang}", record.slug),
        None => format!("{base}/embed/{}", record.slug),
    };
    let has_thumbnail = record.curation.thumbnail_sha256.is_some();
    Oembed {
        r#type: "rich",
        version: "1.0",
        title: texts.title.text.to_owned(),
        author_name: texts.credit.map(|c| c.text.to_owned()),
        provider_name: site,
        provider_url: format!("{base}/"),
        cache_age: 300,
        html: format!(
            "<iframe src=\"{}\" width=\"{width}\" height=\"{height}\" title=\"{}\" \
             style=\"border:0\" loading=\"lazy\" allow=\"fullscreen; xr-spatial-tracking\" \
             allowfullscreen></iframe>",
            escape(&src),
            escape(texts.title.text)
        ),
        width,
        height,
        thumbnail_url: has_thumbnail.then(|| {
            format!(
                "{base}{}",
                super::curator::thumbnail::url(&record.slug, record.version)
            )
        }),
        thumbnail_width: has_thumbnail.then_some(crate::ingest::curation::THUMBNAIL_SIZE),
        thumbnail_height: has_thumbnail.then_some(crate::ingest::curation::THUMBNAIL_SIZE),
    }
}

/// The slug of a model page or embed URL (`…/m/{slug}` or `…/embed/{slug}`,
/// on any host: behind a CDN or proxy the consumer may know the site by
/// another name), ignoring a query or fragment.
fn model_slug(url: &str) -> Option<&str> {
    let rest = url
        .strip_prefix("https://")
        .or_else(|| url.strip_prefix("http://"))?;
    let path = &rest[rest.find('/')?..];
    let path = path.split(['?', '#']).next()?;
    let slug = path
        .strip_prefix("/m/")
        .or_else(|| path.strip_prefix("/embed/"))?;
    let slug = slug.strip_suffix('/').unwrap_or(slug);
    valid_slug(slug).then_some(slug)
}

/// The embed's size: 800 × 600 within the consumer's bounds, keeping 4:3,
/// never under 120 px a side.
fn fit(max_width: Option<u32>, max_height: Option<u32>) -> (u32, u32) {
    let mut width = WIDTH.min(max_width.unwrap_or(WIDTH));
    if let Some(max_height) = max_height {
        width = width.min(max_height.saturating_mul(4) / 3);
    }
    let width = width.max(MIN_SIDE);
    (width, (width * 3 / 4).max(MIN_SIDE))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn model_links_name_their_slug() {
        assert_eq!(model_slug("https://museo.example/m/stele"), Some("stele"));
        assert_eq!(
            model_slug("http://127.0.0.1:8080/embed/stele-2/"),
            Some("stele-2")
        );
        assert_eq!(
            model_slug("https://museo.example/m/stele?device=phone#x"),
            Some("stele")
        );
        for not_a_model in [
            "https://museo.example/",
            "https://museo.example/m/",
            "https://museo.example/m/Stele",
            "https://museo.example/m/a/b",
            "https://museo.example/admin",
            "ftp://museo.example/m/stele",
            "museo.example/m/stele",
            "https://museo.example/api/models/stele",
        ] {
            assert_eq!(model_slug(not_a_model), None, "{not_a_model}");
        }
    }

    #[test]
    fn the_embed_fits_the_consumers_bounds() {
        assert_eq!(fit(None, None), (800, 600));
        assert_eq!(fit(Some(640), None), (640, 480));
        assert_eq!(fit(Some(2000), Some(300)), (400, 300));
        assert_eq!(fit(Some(1), Some(1)), (120, 120));
    }
}
