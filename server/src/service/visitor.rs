//! Who is asking: device class from an explicit `?device=` or client hints,
//! researcher token from `Authorization: Bearer` or `?token=`.

use super::cap::DeviceClass;
use super::error::AppError;
use axum::extract::FromRequestParts;
use axum::http::request::Parts;
use axum::http::{header, HeaderMap};
use serde::Deserialize;
use utoipa::IntoParams;

/// What the request says about the visitor, before the token is checked.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VisitorHints {
    pub device: DeviceClass,
    /// Whether `device` came from `?device=` rather than a guess.
    pub device_explicit: bool,
    pub token: Option<String>,
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
