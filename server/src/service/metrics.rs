//! Prometheus metrics, one registry per [`super::AppState`] (no global
//! recorder, so in-process tests with several servers stay apart).

use super::AppState;
use axum::extract::{MatchedPath, Request};
use prometheus_client::encoding::{EncodeLabelSet, EncodeLabelValue, LabelValueEncoder};
use prometheus_client::metrics::counter::Counter;
use prometheus_client::metrics::family::Family;
use prometheus_client::metrics::gauge::Gauge;
use prometheus_client::metrics::histogram::{exponential_buckets, Histogram};
use prometheus_client::registry::Registry;
use std::sync::atomic::AtomicU64;
use std::time::Duration;

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RequestLabels {
    route: Route,
    status: u16,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct RouteLabels {
    route: Route,
}

/// The `route` label: the template the router matched (so label values are
/// bounded by the route list), or `unmatched` (fallbacks: the viewer's files,
/// 404s).
#[derive(Clone, Debug)]
pub struct Route(RouteName);

#[derive(Clone, Debug)]
enum RouteName {
    Matched(MatchedPath),
    /// A template answered before the router ([`super::fast_payload`]).
    Known(&'static str),
    Unmatched,
}

impl Route {
    pub fn of(request: &Request) -> Route {
        Route(match request.extensions().get::<MatchedPath>() {
            Some(matched) => RouteName::Matched(matched.clone()),
            None => RouteName::Unmatched,
        })
    }

    /// One of the router's templates, named without the router.
    pub fn known(template: &'static str) -> Route {
        Route(RouteName::Known(template))
    }

    pub fn as_str(&self) -> &str {
        match &self.0 {
            RouteName::Matched(matched) => matched.as_str(),
            RouteName::Known(template) => template,
            RouteName::Unmatched => "unmatched",
        }
    }
}

impl PartialEq for Route {
    fn eq(&self, other: &Route) -> bool {
        self.as_str() == other.as_str()
    }
}

impl Eq for Route {}

impl std::hash::Hash for Route {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        self.as_str().hash(state);
    }
}

impl EncodeLabelValue for Route {
    fn encode(&self, encoder: &mut LabelValueEncoder<'_>) -> std::fmt::Result {
        EncodeLabelValue::encode(&self.as_str(), encoder)
    }
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct CacheLabels {
    cache: &'static str,
    result: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct ReasonLabels {
    reason: &'static str,
}

#[derive(Clone, Debug, Hash, PartialEq, Eq, EncodeLabelSet)]
struct ModelLabels {
    model: String,
}

fn latency_histogram() -> Histogram {
    // 100 µs … 3.3 s
    Histogram::new(exponential_buckets(0.0001, 2.0, 16))
}

pub struct Metrics {
    registry: Registry,
    requests: Family<RequestLabels, Counter>,
    latency: Family<RouteLabels, Histogram, fn() -> Histogram>,
    cache: Family<CacheLabels, Counter>,
    capped: Family<ReasonLabels, Counter>,
    fast_path: Counter,
    inflight: Gauge,
    pressure: Gauge,
    latency_ewma: Gauge<f64, AtomicU64>,
    queue_ewma: Gauge<f64, AtomicU64>,
    cached_bytes: Gauge,
    admission_backlog: Gauge<f64, AtomicU64>,
    load_cap: Family<ModelLabels, Gauge>,
    good_enough: Family<ModelLabels, Gauge>,
}

impl Default for Metrics {
    fn default() -> Self {
        let mut m = Metrics {
            registry: Registry::with_prefix("vitrine"),
            requests: Family::default(),
            latency: Family::new_with_constructor(latency_histogram),
            cache: Family::default(),
            capped: Family::default(),
            fast_path: Counter::default(),
            inflight: Gauge::default(),
            pressure: Gauge::default(),
            latency_ewma: Gauge::default(),
            queue_ewma: Gauge::default(),
            cached_bytes: Gauge::default(),
            admission_backlog: Gauge::default(),
            load_cap: Family::default(),
            good_enough: Family::default(),
        };
        let r = &mut m.registry;
        r.register(
            "http_requests",
            "HTTP requests by route and status",
            m.requests.clone(),
        );
        r.register(
            "http_request_duration_seconds",
            "Time to response headers",
            m.latency.clone(),
        );
        r.register(
            "cache_lookups",
            "Cache lookups by cache and result (hit, miss)",
            m.cache.clone(),
        );
        r.register(
            "level_capped",
            "Batch requests refused above the level cap, by reason",
            m.capped.clone(),
        );
        r.register(
            "fast_path_answers",
            "Cached public payloads answered before the router (also counted in http_requests)",
            m.fast_path.clone(),
        );
        r.register(
            "inflight_requests",
            "Data requests in flight",
            m.inflight.clone(),
        );
        r.register(
            "load_pressure",
            "Load pressure step (0 = no load cap)",
            m.pressure.clone(),
        );
        r.register(
            "handler_latency_ewma_ms",
            "Smoothed handler latency",
            m.latency_ewma.clone(),
        );
        r.register(
            "queue_delay_ewma_ms",
            "Smoothed runtime queueing delay",
            m.queue_ewma.clone(),
        );
        r.register(
            "payload_cache_bytes",
            "Bytes held by the payload cache",
            m.cached_bytes.clone(),
        );
        r.register(
            "admission_backlog",
            "New visitors refused with 503 busy and not yet due back",
            m.admission_backlog.clone(),
        );
        r.register(
            "load_level_cap",
            "Current load cap per cached model",
            m.load_cap.clone(),
        );
        r.register(
            "good_enough_level",
            "Good-enough level per cached model",
            m.good_enough.clone(),
        );
        m
    }
}

impl Metrics {
    pub fn cache_lookup(&self, cache: &'static str, hit: bool) {
        let result = if hit { "hit" } else { "miss" };
        self.cache
            .get_or_create(&CacheLabels { cache, result })
            .inc();
    }

    pub fn observe(&self, route: Route, status: u16, elapsed: Duration) {
        self.latency
            .get_or_create(&RouteLabels {
                route: route.clone(),
            })
            .observe(elapsed.as_secs_f64());
        self.requests
            .get_or_create(&RequestLabels { route, status })
            .inc();
    }

    /// One answer from the fast path ([`super::fast_payload`]).
    pub fn fast_path_answer(&self) {
        self.fast_path.inc();
    }

    pub fn capped(&self, reason: &'static str) {
        self.capped.get_or_create(&ReasonLabels { reason }).inc();
    }
}

/// Prometheus text exposition, with gauges refreshed at scrape time.
pub fn render(state: &AppState) -> String {
    let m = state.metrics();
    let load = state.load().snapshot();
    m.inflight.set(load.inflight as i64);
    m.pressure.set(i64::from(load.pressure));
    m.latency_ewma.set(load.latency_ms);
    m.queue_ewma.set(load.queue_ms);
    m.cached_bytes.set(state.caches().payload_bytes() as i64);
    m.admission_backlog.set(state.admission().backlog());
    m.load_cap.clear();
    m.good_enough.clear();
    for (slug, load_cap, good_enough) in state.current_load_caps() {
        m.load_cap
            .get_or_create(&ModelLabels {
                model: slug.clone(),
            })
            .set(i64::from(load_cap));
        m.good_enough
            .get_or_create(&ModelLabels { model: slug })
            .set(i64::from(good_enough));
    }
    let mut out = String::new();
    // Writing to a String cannot fail.
    let _ = prometheus_client::encoding::text::encode(&mut out, &m.registry);
    out
}
