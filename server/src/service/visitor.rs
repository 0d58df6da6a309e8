//! Who is asking: device class from an explicit `?device=` or client hints,
//! researcher token from `Authorization: Bearer` or `?token=`, and the
//! visitor's address: the TCP peer, or, when that peer is a trusted proxy
//! (`--trusted-proxies`), the address it forwarded.
//!
//! Behind a proxy the device class and the audience need nothing new: the
//! proxy passes the query, `User-Agent`, `Sec-CH-UA-Mobile` and
//! `Authorization` through unchanged.

use super::cap::DeviceClass;
use super::error::AppError;
use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};
use ipnet::IpNet;
use serde::Deserialize;
use std::net::{IpAddr, SocketAddr};
use utoipa::IntoParams;

/// The visitor's address, as [`client_address`] decided it (a request
/// extension; absent for requests that did not come over TCP).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ClientAddr(pub IpAddr);

/// The TCP peer of a connection (a request extension set by the accept loop).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PeerAddr(pub SocketAddr);

/// Who the visitor is, given the TCP `peer`: the peer itself unless it is a
/// trusted proxy. Then the forwarded chain (`X-Forwarded-For`, else
/// `Forwarded: for=`) is read from the right, skipping trusted proxies; the
/// first address that is not one is the visitor (an address further left
/// was written by the client and proves nothing). Unreadable entries stop
/// the walk at the last trusted hop.
pub fn client_address(peer: IpAddr, headers: &HeaderMap, trusted: &[IpNet]) -> IpAddr {
    let is_trusted = |ip: &IpAddr| trusted.iter().any(|net| net.contains(ip));
    if !is_trusted(&peer) {
        return peer;
    }
    let chain = forwarded_chain(headers);
    let mut visitor = peer;
    for hop in chain.iter().rev() {
        let Some(ip) = hop else { break };
        visitor = *ip;
        if !is_trusted(ip) {
            break;
        }
    }
    visitor
}

/// The forwarded addresses, leftmost (the client's claim) first; `None` for
/// an entry that is not an address (`unknown`, an obfuscated name).
fn forwarded_chain(headers: &HeaderMap) -> Vec<Option<IpAddr>> {
    let values = |name: &str| -> Vec<String> {
        headers
            .get_all(name)
            .iter()
            .filter_map(|v| v.to_str().ok())
            .flat_map(|v| v.split(','))
            .map(|v| v.trim().to_owned())
            .filter(|v| !v.is_empty())
            .collect()
    };
    let xff = values("x-forwarded-for");
    if !xff.is_empty() {
        return xff.iter().map(|v| parse_node(v)).collect();
    }
    values("forwarded")
        .iter()
        .filter_map(|element| {
            element.split(';').find_map(|pair| {
                let (k, v) = pair.split_once('=')?;
                k.trim().eq_ignore_ascii_case("for").then(|| parse_node(v))
            })
        })
        .collect()
}

/// Records the visitor's [`ClientAddr`] on the request, for the log and
/// for whatever is decided per visitor.
pub async fn mark_client(
    axum::extract::State(state): axum::extract::State<super::AppState>,
    mut request: axum::extract::Request,
    next: axum::middleware::Next,
) -> axum::response::Response {
    if let Some(PeerAddr(peer)) = request.extensions().get::<PeerAddr>().copied() {
        let trusted = &state.config().trusted_proxies;
        let client = client_address(peer.ip(), request.headers(), trusted);
        request.extensions_mut().insert(ClientAddr(client));
    }
    next.run(request).await
}

/// `192.0.2.1`, `192.0.2.1:8080`, `"[2001:db8::1]:443"`, `2001:db8::1`.
fn parse_node(text: &str) -> Option<IpAddr> {
    let t = text.trim().trim_matches('"');
    if let Ok(ip) = t.parse::<IpAddr>() {
        return Some(ip);
    }
    if let Ok(sa) = t.parse::<SocketAddr>() {
        return Some(sa.ip());
    }
    t.strip_prefix('[')
        .and_then(|r| r.split_once(']'))
        .and_then(|(ip, _)| ip.parse().ok())
}

/// What the request says about the visitor, before the token is checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VisitorHints {
    pub device: DeviceClass,
    /// Whether `device` came from `?device=` rather than a guess.
    pub device_explicit: bool,
    pub token: Option<String>,
}

impl VisitorHints {
    /// A desktop visitor without a token: what a CMS fetching an oEmbed or
    /// a crawler reading the sitemap is, and what they publish to anyone.
    pub fn anonymous() -> VisitorHints {
        VisitorHints {
            device: DeviceClass::Desktop,
            device_explicit: false,
            token: None,
        }
    }
}

/// The query parameters every visitor route reads.
#[derive(Deserialize, IntoParams)]
#[into_params(parameter_in = Query)]
pub struct HintQuery {
    /// Device class; without it the class is guessed from `Sec-CH-UA-Mobile`
    /// and `User-Agent`.
    #[param(value_type = Option<DeviceClass>)]
    device: Option<String>,
    /// Researcher token, when `Authorization: Bearer` cannot be sent.
    token: Option<String>,
}

impl<S: Send + Sync> FromRequestParts<S> for VisitorHints {
    type Rejection = AppError;

    async fn from_request_parts(parts: &mut Parts, _: &S) -> Result<Self, AppError> {
        let query: HintQuery = serde_urlencoded::from_str(parts.uri.query().unwrap_or(""))
            .map_err(|e| AppError::BadRequest(format!("query: {e}")))?;
        let explicit = match query.device.as_deref() {
            Some(d) => Some(DeviceClass::parse(d).ok_or_else(|| {
                AppError::BadRequest(format!(
                    "device must be phone, tablet or desktop, not {d:?}"
                ))
            })?),
            None => None,
        };
        let token = bearer(&parts.headers)?
            .or(query.token)
            .filter(|t| !t.is_empty());
        Ok(VisitorHints {
            device: explicit.unwrap_or_else(|| guess_device(&parts.headers)),
            device_explicit: explicit.is_some(),
            token,
        })
    }
}

fn bearer(headers: &HeaderMap) -> Result<Option<String>, AppError> {
    let Some(value) = headers.get(header::AUTHORIZATION) else {
        return Ok(None);
    };
    let value = value
        .to_str()
        .map_err(|_| AppError::BadRequest("Authorization is not ASCII".into()))?;
    match value.split_once(' ') {
        Some((scheme, token)) if scheme.eq_ignore_ascii_case("bearer") => {
            Ok(Some(token.trim().to_owned()))
        }
        _ => Err(AppError::BadRequest(
            "Authorization must be 'Bearer <token>'".into(),
        )),
    }
}

/// `Sec-CH-UA-Mobile: ?1` says phone; otherwise the usual User-Agent tokens
/// ("iPad"/"Tablet"; "Mobi", or Android without "Mobile", which is a tablet).
pub fn guess_device(headers: &HeaderMap) -> DeviceClass {
    let ua = headers
        .get(header::USER_AGENT)
        .and_then(|v| v.to_str().ok())
        .unwrap_or("");
    if ua.contains("iPad") || ua.contains("Tablet") {
        return DeviceClass::Tablet;
    }
    if headers
        .get("sec-ch-ua-mobile")
        .is_some_and(|v| v.as_bytes() == b"?1")
    {
        return DeviceClass::Phone;
    }
    if ua.contains("Mobi") || ua.contains("iPhone") {
        DeviceClass::Phone
    } else if ua.contains("Android") {
        DeviceClass::Tablet
    } else {
        DeviceClass::Desktop
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use axum::http::HeaderValue;

    fn ua(s: &'static str) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(header::USER_AGENT, HeaderValue::from_static(s));
        h
    }

    #[test]
    fn device_guesses() {
        let iphone = "Mozilla/5.0 (iPhone; CPU iPhone OS 17_0 like Mac OS X) Mobile/15E148";
        let pixel = "Mozilla/5.0 (Linux; Android 14; Pixel 8) Chrome/120.0 Mobile Safari/537.36";
        let tab = "Mozilla/5.0 (Linux; Android 13; SM-X200) Chrome/120.0 Safari/537.36";
        let ipad = "Mozilla/5.0 (iPad; CPU OS 17_0 like Mac OS X) Mobile/15E148";
        let desktop = "Mozilla/5.0 (X11; Linux x86_64) Chrome/120.0 Safari/537.36";
        assert_eq!(guess_device(&ua(iphone)), DeviceClass::Phone);
        assert_eq!(guess_device(&ua(pixel)), DeviceClass::Phone);
        assert_eq!(guess_device(&ua(tab)), DeviceClass::Tablet);
        assert_eq!(guess_device(&ua(ipad)), DeviceClass::Tablet);
        assert_eq!(guess_device(&ua(desktop)), DeviceClass::Desktop);
        let mut hinted = ua(desktop);
        hinted.insert("sec-ch-ua-mobile", HeaderValue::from_static("?1"));
        assert_eq!(guess_device(&hinted), DeviceClass::Phone);
        assert_eq!(guess_device(&HeaderMap::new()), DeviceClass::Desktop);
    }
}
