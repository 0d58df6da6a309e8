//! The language of the pages the service sends: `?lang=` when it names one
//! the viewer speaks, else the best of the visitor's `Accept-Language`
//! (RFC 9110 §12.5.4, q-values honoured), else English. The page's
//! `<html lang dir>` carries it before any script runs, so a screen reader
//! and the browser's hyphenation and fonts are right from the first paint;
//! the viewer then takes its catalogue from the same attribute.
//! `web/src/i18n/languages.js` lists the same languages.

use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};
use std::convert::Infallible;

/// The viewer's languages, by their primary subtag, and whether they are
/// written right to left.
const SUPPORTED: [(&str, bool); 7] = [
    ("en", false),
    ("pt", false),
    ("es", false),
    ("fr", false),
    ("de", false),
    ("it", false),
    ("ar", true),
];

const DEFAULT: &str = "en";

/// The language a page is sent in, and how it was chosen.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PageLanguage {
    /// A supported primary subtag (`pt`, `ar`).
    pub code: &'static str,
    /// Whether the choice read `Accept-Language` (no usable `?lang=`): the
    /// answer must then say `Vary: Accept-Language`.
    pub negotiated: bool,
}

impl PageLanguage {
    /// `?lang=`'s value, then the `Accept-Language` header.
    pub fn choose(lang_query: Option<&str>, accept_language: Option<&str>) -> PageLanguage {
        if let Some(code) = lang_query.and_then(supported) {
            return PageLanguage {
                code,
                negotiated: false,
            };
        }
        PageLanguage {
            code: accept_language.and_then(best_accepted).unwrap_or(DEFAULT),
            negotiated: true,
        }
    }

    /// `rtl` or `ltr`.
    pub fn dir(self) -> &'static str {
        let rtl = SUPPORTED.iter().any(|&(c, rtl)| c == self.code && rtl);
        if rtl {
            "rtl"
        } else {
            "ltr"
        }
    }

    /// `index.html` with its `<html …>` tag replaced by one that states this
    /// language and direction (the page as built names none).
    pub fn apply(self, html: &str) -> String {
        let tag = format!("<html lang=\"{}\" dir=\"{}\">", self.code, self.dir());
        match html.find("<html").and_then(|start| {
            let end = start + html[start..].find('>')?;
            Some((start, end))
        }) {
            Some((start, end)) => format!("{}{tag}{}", &html[..start], &html[end + 1..]),
            None => html.to_owned(),
        }
    }
}

impl<S: Send + Sync> FromRequestParts<S> for PageLanguage {
    type Rejection = Infallible;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, Infallible> {
        Ok(from_parts(parts.uri.query(), &parts.headers))
    }
}

fn from_parts(query: Option<&str>, headers: &HeaderMap) -> PageLanguage {
    let (lang, accept) = query_and_header(query, headers);
    PageLanguage::choose(lang, accept)
}

/// `?lang=`'s value and the `Accept-Language` header.
fn query_and_header<'a>(
    query: Option<&'a str>,
    headers: &'a HeaderMap,
) -> (Option<&'a str>, Option<&'a str>) {
    // Codes are plain ASCII: a percent-encoded value names no supported
    // language, so the pairs are read as they are.
    let lang = query
        .unwrap_or("")
        .split('&')
        .find_map(|pair| pair.strip_prefix("lang="));
    let accept = headers
        .get(header::ACCEPT_LANGUAGE)
        .and_then(|v| v.to_str().ok());
    (lang, accept)
}

/// The languages a visitor wants a model's own texts in (its title,
/// description, credit), most wanted first: `?lang=`'s tag as given (a
/// museum may write in languages the viewer's controls do not speak), then
/// the `Accept-Language` ranges by q-value when the page's language was
/// negotiated from them, then the page's language.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ContentLanguages {
    pub wanted: Vec<String>,
    /// `?lang=`'s tag, when it gave a well-formed one.
    pub asked: Option<String>,
    /// Whether `Accept-Language` was read (the answer varies on it).
    pub negotiated: bool,
}

impl ContentLanguages {
    pub fn choose(lang_query: Option<&str>, accept_language: Option<&str>) -> ContentLanguages {
        let page = PageLanguage::choose(lang_query, accept_language);
        let asked = lang_query
            .map(str::trim)
            .filter(|t| well_formed(t))
            .map(str::to_owned);
        let mut wanted: Vec<String> = asked.iter().cloned().collect();
        if page.negotiated {
            wanted.extend(accept_language.map(ranges_by_q).unwrap_or_default());
        }
        wanted.push(page.code.to_owned());
        let mut seen = Vec::<String>::new();
        wanted.retain(|t| {
            let new = !seen.iter().any(|s| s.eq_ignore_ascii_case(t));
            seen.push(t.clone());
            new
        });
        ContentLanguages {
            wanted,
            asked,
            negotiated: page.negotiated,
        }
    }
}

impl<S: Send + Sync> FromRequestParts<S> for ContentLanguages {
    type Rejection = Infallible;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, Infallible> {
        let (lang, accept) = query_and_header(parts.uri.query(), &parts.headers);
        Ok(ContentLanguages::choose(lang, accept))
    }
}

/// Letters, digits, hyphens (and the underscores some clients send), 1–35
/// bytes: worth comparing with a stored tag (checked properly when written).
fn well_formed(tag: &str) -> bool {
    (1..=35).contains(&tag.len())
        && tag
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_')
}

/// The header's language ranges with q > 0, highest q first (stable for
/// equals), `*` left out.
fn ranges_by_q(header: &str) -> Vec<String> {
    let mut ranges: Vec<(String, f32)> = header
        .split(',')
        .filter_map(|range| {
            let mut parts = range.split(';');
            let tag = parts.next()?.trim();
            let q = parts
                .filter_map(|p| p.trim().strip_prefix("q="))
                .find_map(|q| q.trim().parse::<f32>().ok())
                .unwrap_or(1.0);
            (q > 0.0 && tag != "*" && well_formed(tag)).then(|| (tag.to_owned(), q))
        })
        .collect();
    ranges.sort_by(|a, b| b.1.total_cmp(&a.1));
    ranges.into_iter().map(|(tag, _)| tag).collect()
}

/// Whether the viewer speaks `code` (a primary subtag, lower case).
pub fn is_supported(code: &str) -> bool {
    SUPPORTED.iter().any(|&(c, _)| c == code)
}

/// The supported language a tag (`pt-BR`, `AR`) belongs to.
fn supported(tag: &str) -> Option<&'static str> {
    let primary = tag.trim().split(['-', '_']).next()?;
    SUPPORTED
        .iter()
        .map(|&(code, _)| code)
        .find(|code| code.eq_ignore_ascii_case(primary))
}

/// The supported language with the highest q-value; among equals, the one
/// the visitor listed first. `q=0` is a refusal; `*` adds nothing the
/// default does not.
fn best_accepted(header: &str) -> Option<&'static str> {
    ranges_by_q(header).iter().find_map(|tag| supported(tag))
}

#[cfg(test)]
mod tests {
    use super::PageLanguage;

    fn code(query: Option<&str>, accept: Option<&str>) -> &'static str {
        PageLanguage::choose(query, accept).code
    }

    #[test]
    fn the_query_wins_when_it_names_a_supported_language() {
        assert_eq!(code(Some("pt"), Some("de")), "pt");
        assert!(!PageLanguage::choose(Some("pt"), Some("de")).negotiated);
        // An unsupported ?lang= falls through to the header.
        assert_eq!(code(Some("xx"), Some("de")), "de");
        assert!(PageLanguage::choose(Some("xx"), Some("de")).negotiated);
    }

    #[test]
    fn accept_language_is_read_by_q_value() {
        assert_eq!(code(None, Some("es")), "es");
        assert_eq!(code(None, Some("pt-BR,pt;q=0.9,en;q=0.8")), "pt");
        assert_eq!(code(None, Some("en;q=0.5, fr;q=0.8")), "fr");
        assert_eq!(code(None, Some("de;q=0.7, IT;q=0.7")), "de");
        // Unsupported languages are passed over, not taken as English.
        assert_eq!(code(None, Some("ja, ko;q=0.9, ar;q=0.2")), "ar");
        // q=0 refuses.
        assert_eq!(code(None, Some("fr;q=0, de;q=0.1")), "de");
        assert_eq!(code(None, Some("fr;q=0")), "en");
    }

    #[test]
    fn english_when_nothing_usable_is_asked() {
        assert_eq!(code(None, None), "en");
        assert_eq!(code(None, Some("")), "en");
        assert_eq!(code(None, Some("*")), "en");
        assert_eq!(code(None, Some("zh-Hant;q=abc, ;;,")), "en");
    }

    #[test]
    fn content_languages_keep_what_the_viewer_does_not_speak() {
        use super::ContentLanguages;
        let c = ContentLanguages::choose(Some("ca"), Some("es;q=0.8, en, *;q=0.1, fr;q=0"));
        assert_eq!(c.wanted, ["ca", "en", "es"]);
        assert!(c.negotiated);
        let c = ContentLanguages::choose(Some("pt-BR"), Some("de"));
        assert_eq!(c.wanted, ["pt-BR", "pt"]);
        assert!(!c.negotiated);
        assert_eq!(ContentLanguages::choose(Some("<x>"), None).wanted, ["en"]);
    }

    #[test]
    fn arabic_is_right_to_left() {
        assert_eq!(PageLanguage::choose(Some("ar"), None).dir(), "rtl");
        assert_eq!(PageLanguage::choose(Some("fr"), None).dir(), "ltr");
    }

    #[test]
    fn the_html_tag_is_replaced() {
        let page = "<!doctype html>\n<html lang=\"en\">\n<head></head></html>";
        let ar = PageLanguage::choose(Some("ar"), None).apply(page);
        assert_eq!(
            ar,
            "<!doctype html>\n<html lang=\"ar\" dir=\"rtl\">\n<head></head></html>"
        );
    }
}
