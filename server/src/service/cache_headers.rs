//! What browsers and shared caches (nginx, a CDN) may keep, route by route.
//! The rules, which `tests/topology/cache_rules.rs` checks on every route:
//!
//! - Base meshes, batches, textures: immutable under their URL, which names
//!   the compression (`/api/compressions/{id}/…`) or the texture; strong
//!   ETag. `public` when the public may fetch them, else `private` (see
//!   `payload.rs`). A new version has a new compression id, hence new URLs.
//! - Manifests and the model list, asked without a token: `public,
//!   max-age=2`, with `stale-while-revalidate` and
//!   `stale-if-error` so a proxy keeps answering while it refreshes or while
//!   the origin is away, and `Vary: Authorization` plus, when the device
//!   class was guessed rather than given as `?device=`, the headers it was
//!   guessed from. A manifest carries the load cap of the instance that
//!   answered: a cached one is at most two seconds older than the load it
//!   reports, and a batch above the current cap is still refused (429 with
//!   `Retry-After`), after which the viewer reads the manifest again.
//! - Anything asked with a token (`Authorization` or `?token=`, researcher or
//!   study invitation): `private, no-store` with the same `Vary`, so no
//!   shared cache can ever hand one visitor's caps to another.
//! - A download (`download.glb`): named by slug, so it changes with each new
//!   version: short-lived like a manifest, and `private, no-cache` when the
//!   level is this visitor's cap (no `?level=`) or a token was sent.
//! - What is the same for every visitor, token or not, because it is
//!   answered as an anonymous visitor sees it (oEmbed, the sitemap,
//!   robots.txt, the IIIF Manifests, Collection and annotation pages of
//!   `iiif/`, which also carry a strong ETag of their bytes): `public,
//!   max-age=300` ([`anonymous`]); the licence list, which changes with a
//!   release: `public, max-age=3600`.
//! - Errors: `no-store` (`error.rs`); pages: `no-cache` ([`page`]), and
//!   `Vary: Accept-Language` when their `<html lang>` was negotiated from it
//!   (no `?lang=`: `language.rs`), so a shared cache never hands a Portuguese
//!   page to a German visitor.
//!
//! Several layers (CORS, compression, these rules) name `Vary` headers; they
//! are merged into one line ([`merge_vary`]), which every cache reads alike.

use super::language::PageLanguage;
use super::visitor::VisitorHints;
use axum::http::{header, HeaderValue};
use axum::response::Response;

/// A public manifest or model list: two seconds in a shared cache.
const PUBLIC_SHORT: &str = "public, max-age=2, stale-while-revalidate=10, stale-if-error=60";
const PERSONAL: &str = "private, no-store";
/// What an anonymous visitor gets, whoever asks: five minutes anywhere.
pub const ANONYMOUS: &str = "public, max-age=300";
/// What changes only with a release of Vitrine (the licence list).
pub const RELEASE: &str = "public, max-age=3600";
const PERSONAL_REVALIDATE: &str = "private, no-cache";

/// Whether the answer depends on who the visitor is beyond the URL.
pub fn personal(hints: &VisitorHints) -> bool {
    hints.token.is_some()
}

/// The request headers a visitor answer depends on.
fn vary(hints: &VisitorHints) -> HeaderValue {
    if hints.device_explicit {
        HeaderValue::from_static("Authorization")
    } else {
        HeaderValue::from_static("Authorization, Sec-CH-UA-Mobile, User-Agent")
    }
}

/// A manifest or the model list: short-lived and shared when nothing
/// personal went into it, never shared otherwise.
pub fn visitor_json(response: &mut Response, hints: &VisitorHints) {
    let control = if personal(hints) {
        PERSONAL
    } else {
        PUBLIC_SHORT
    };
    let headers = response.headers_mut();
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static(control));
    headers.append(header::VARY, vary(hints));
}

/// An answer that is the same for every visitor (see the module's rules):
/// `control` is [`ANONYMOUS`] or [`RELEASE`].
pub fn anonymous(response: &mut Response, control: &'static str) {
    response
        .headers_mut()
        .insert(header::CACHE_CONTROL, HeaderValue::from_static(control));
}

/// A page of the viewer (`web.rs`): revalidated on every visit, and varying
/// on `Accept-Language` when the page's language was read from it.
pub fn page(response: &mut Response, language: PageLanguage) {
    let headers = response.headers_mut();
    headers.insert(header::CACHE_CONTROL, HeaderValue::from_static("no-cache"));
    if language.negotiated {
        headers.append(header::VARY, HeaderValue::from_static("Accept-Language"));
    }
}

/// A download: `level_given` is whether `?level=` chose it (else it is the
/// visitor's cap now); `public` whether the public may fetch that level;
/// `personal` whether a token was sent.
pub fn download(personal: bool, level_given: bool, public: bool) -> &'static str {
    if public && level_given && !personal {
        PUBLIC_SHORT
    } else {
        PERSONAL_REVALIDATE
    }
}

/// Every `Vary` line of `response` as one, each name once.
pub fn merge_vary<B>(mut response: axum::http::Response<B>) -> axum::http::Response<B> {
    let headers = response.headers_mut();
    if headers.get_all(header::VARY).iter().count() < 2 {
        return response;
    }
    let mut names: Vec<String> = Vec::new();
    for value in headers.get_all(header::VARY) {
        for name in value.to_str().unwrap_or("*").split(',') {
            let name = name.trim();
            if !name.is_empty() && !names.iter().any(|n| n.eq_ignore_ascii_case(name)) {
                names.push(name.to_owned());
            }
        }
    }
    let merged = HeaderValue::from_str(&names.join(", ")).unwrap_or(HeaderValue::from_static("*"));
    headers.insert(header::VARY, merged);
    response
}
