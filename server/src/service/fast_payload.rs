//! A crowd's commonest request answered before the router: a public
//! visitor's base mesh or batch that the payload cache already holds.
//!
//! Under wrk a cached batch cost the service about twice the CPU that nginx
//! spends sending the same bytes as a static file, and a profile put most of
//! the difference in the stack every route shares (routing, two `from_fn`
//! middlewares and a `map_response`, tracing, the timeout, CORS, compression,
//! extractors), not in the payload's own work (issue 46). Here the same
//! decisions are taken from the caches alone (the record is public and
//! servable, the level is within the public cap for the guessed device and
//! the current load) and the same answer is sent: the handler's headers, the
//! ones the layers add, the request counted in flight until its body is sent,
//! and its latency and status in the metrics. A test compares the two answers
//! header by header.
//!
//! Anything else goes on to the router unchanged: a token or any query
//! string, a conditional or non-GET request, an origin allow-list, a record
//! or payload not cached, a level above the cap, a full concurrency limit.

use super::cap::Audience;
use super::metrics::Route;
use super::payload::{cache_control, etag, payload_response, OCTET_STREAM};
use super::visitor::guess_device;
use super::{AppState, Visitor};
use crate::service::cache::{Payload, PayloadKey};
use axum::http::{header, HeaderMap, HeaderValue, Method, Request};
use axum::response::Response;
use std::convert::Infallible;
use std::future::{ready, Ready};
use std::task::{Context, Poll};
use std::time::Instant;
use tower::Service;

const BASE_ROUTE: &str = "/api/compressions/{id}/base";
const BATCH_ROUTE: &str = "/api/compressions/{id}/batches/{iteration}";

/// `inner` (the router) behind the fast path.
#[derive(Clone)]
pub struct FastPayload<S> {
    inner: S,
    state: AppState,
}

impl<S> FastPayload<S> {
    pub fn new(inner: S, state: AppState) -> FastPayload<S> {
        FastPayload { inner, state }
    }
}

impl<S, B> Service<Request<B>> for FastPayload<S>
where
    S: Service<Request<B>, Response = Response, Error = Infallible>,
{
    type Response = Response;
    type Error = Infallible;
    type Future = futures_util::future::Either<Ready<Result<Response, Infallible>>, S::Future>;

    fn poll_ready(&mut self, cx: &mut Context<'_>) -> Poll<Result<(), Infallible>> {
        self.inner.poll_ready(cx)
    }

    fn call(&mut self, request: Request<B>) -> Self::Future {
        use futures_util::future::Either;
        // Outside the router's panic layer: a panic here (a bug) hands the
        // request to the router rather than dropping the connection.
        let fast = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
            answer(
                &self.state,
                request.method(),
                request.uri(),
                request.headers(),
            )
        }));
        match fast {
            Ok(Some(response)) => Either::Left(ready(Ok(response))),
            Ok(None) | Err(_) => Either::Right(self.inner.call(request)),
        }
    }
}

/// Which payload a path names: `(compression id, level)`, level 0 the base.
fn payload_path(path: &str) -> Option<(i64, u32, &'static str)> {
    let rest = path.strip_prefix("/api/compressions/")?;
    let (id, rest) = rest.split_once('/')?;
    let id = decimal(id)?;
    if rest == "base" {
        return Some((id, 0, BASE_ROUTE));
    }
    let level = u32::try_from(decimal(rest.strip_prefix("batches/")?)?).ok()?;
    (level > 0).then_some((id, level, BATCH_ROUTE))
}

/// A positive decimal without sign or leading zero (the router's handlers
/// answer everything else, with their own errors).
fn decimal(text: &str) -> Option<i64> {
    let plain = !text.is_empty()
        && text.len() <= 18
        && !text.starts_with('0')
        && text.bytes().all(|b| b.is_ascii_digit());
    plain.then(|| text.parse().ok()).flatten()
}

/// The answer, when it can be given from the caches alone.
fn answer(
    state: &AppState,
    method: &Method,
    uri: &axum::http::Uri,
    headers: &HeaderMap,
) -> Option<Response> {
    if method != Method::GET
        || uri.query().is_some()
        || headers.contains_key(header::AUTHORIZATION)
        || headers.contains_key(header::IF_NONE_MATCH)
        || !state.config().cors_origins.is_empty()
    {
        return None;
    }
    let (id, level, route) = payload_path(uri.path())?;
    let started = Instant::now();
    let metrics = state.metrics();
    let record = state.caches().record_now(metrics, id)?;
    if !record.policy.public_access || !record.servable() || level > record.batch_count() {
        return None;
    }
    if level > 0 {
        let visitor = Visitor {
            audience: Audience::Public,
            device: guess_device(headers),
            device_explicit: false,
            grant: None,
            study_model: None,
        };
        if level > state.level_cap(&record, &visitor).level {
            return None;
        }
    }
    // (A record whose levels do not cover its batch count is the router's
    // to report.)
    let sha256 = &record.levels.get(level as usize)?.sha256;
    let key = if level == 0 {
        PayloadKey::Base(id)
    } else {
        PayloadKey::Batch(id, level)
    };
    let Payload::Mesh(bytes) = state.caches().payload_now(metrics, key)? else {
        return None;
    };
    // The concurrency limit holds here too (the guard's permit is released
    // once the handler returns, as this one is at once).
    drop(state.permits().try_acquire().ok()?);
    let inflight = state.load().begin();
    let length = HeaderValue::from(bytes.len());
    let mut response = payload_response(
        bytes,
        etag(sha256),
        cache_control(&record, level),
        HeaderValue::from_static(OCTET_STREAM),
    );
    let h = response.headers_mut();
    // As axum's router sets it for a body of known size.
    h.insert(header::CONTENT_LENGTH, length);
    // What the layers add to this answer (layers.rs): CORS for any origin
    // (its `Vary` already merged into one line), then `nosniff`.
    h.insert(
        header::VARY,
        HeaderValue::from_static(
            "origin, access-control-request-method, access-control-request-headers",
        ),
    );
    h.insert(
        header::ACCESS_CONTROL_ALLOW_ORIGIN,
        HeaderValue::from_static("*"),
    );
    h.insert(
        header::ACCESS_CONTROL_EXPOSE_HEADERS,
        HeaderValue::from_static("etag,retry-after,content-length"),
    );
    h.insert(
        header::X_CONTENT_TYPE_OPTIONS,
        HeaderValue::from_static("nosniff"),
    );
    metrics.fast_path_answer();
    metrics.observe(Route::known(route), 200, started.elapsed());
    Some(super::guard::counted(response, Some(inflight)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn only_the_payload_paths_are_recognised() {
        assert_eq!(
            payload_path("/api/compressions/12/base"),
            Some((12, 0, BASE_ROUTE))
        );
        assert_eq!(
            payload_path("/api/compressions/12/batches/7"),
            Some((12, 7, BATCH_ROUTE))
        );
        for path in [
            "/api/compressions/12/batches/0",
            "/api/compressions/012/base",
            "/api/compressions/-1/base",
            "/api/compressions/1/batches/07",
            "/api/compressions/1/batches/",
            "/api/compressions/1/batches/7/",
            "/api/compressions/1/parts/1/0",
            "/api/compressions/1%20/base",
            "/api/compressions/99999999999999999999/base",
            "/api/compressions/1/batches/99999999999",
            "/api/models/1",
        ] {
            assert_eq!(payload_path(path), None, "{path}");
        }
    }
}
