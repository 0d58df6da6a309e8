//! `vitrine serve --db … --listen …`: every setting a flag, a `VITRINE_*`
//! variable and a key of the `--config` file ([`crate::config`]); the
//! defaults are those of [`ServiceConfig::default`] and
//! [`ServeLimits::default`] (a test keeps them equal).

use crate::connections::{serve, shutdown_signal, ServeLimits};
use crate::database::{open_storage, redact};
use crate::service::admission::AdmissionConfig;
use crate::service::cap::CapRules;
use crate::service::load::LoadConfig;
use crate::service::{serving, AppState, CacheConfig, RequestLimits, ServiceConfig};
use crate::storage::ConnectOptions;
use std::net::SocketAddr;
use std::path::PathBuf;
use std::time::Duration;
use tokio::net::TcpListener;

#[derive(clap::Args, Clone, Debug, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub struct ServeArgs {
    /// A TOML file of these settings, keys named as the flags
    /// (`db-max-connections = 32`). Precedence: flag > VITRINE_* > file > default.
    #[arg(long, env = "VITRINE_CONFIG")]
    #[serde(skip)]
    pub config: Option<PathBuf>,
    /// Validate the configuration, print the effective one (secrets
    /// redacted) and exit: 0 when valid, 1 when not.
    #[arg(long)]
    #[serde(skip)]
    pub check_config: bool,
    /// Database URL: `sqlite:vitrine.db` or `postgres://user@host/db`.
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    #[arg(long, env = "VITRINE_LISTEN", default_value = "127.0.0.1:8080")]
    pub listen: SocketAddr,
    /// Also serve /metrics, /healthz and /readyz on this address.
    #[arg(long, env = "VITRINE_METRICS_LISTEN")]
    pub metrics_listen: Option<SocketAddr>,
    /// The viewer's build; a built-in page is served when it has no index.html.
    #[arg(long, env = "VITRINE_WEB_DIR", default_value = "web/dist")]
    pub web_dir: PathBuf,
    /// Origins allowed by CORS (comma-separated); none given means any.
    #[arg(
        long = "cors-origin",
        env = "VITRINE_CORS_ORIGINS",
        value_delimiter = ','
    )]
    #[serde(rename = "cors-origin")]
    pub cors_origins: Vec<String>,
    /// Uploads (`POST /api/models`) larger than this many MiB get 413.
    #[arg(long, env = "VITRINE_UPLOAD_LIMIT_MB", default_value_t = 512)]
    pub upload_limit_mb: u64,
    /// Where uploads are spooled while they are ingested (default: the
    /// system's temporary folder).
    #[arg(long, env = "VITRINE_UPLOAD_DIR")]
    pub upload_dir: Option<PathBuf>,
    /// Upload ingests run at once on this instance; up to 8 more wait.
    #[arg(long, env = "VITRINE_INGEST_JOBS", default_value_t = 1)]
    pub ingest_jobs: usize,
    /// Absolute base of links in shared pages (`og:image`), e.g.
    /// `https://museum.example`; default: the request's Host.
    #[arg(long, env = "VITRINE_PUBLIC_BASE_URL")]
    pub public_base_url: Option<String>,
    /// The museum's name where other sites show its links (oEmbed's
    /// `provider_name`, `og:site_name`), e.g. "Museo Nacional".
    #[arg(long, env = "VITRINE_SITE_NAME", default_value = "Vitrine")]
    pub site_name: String,

    #[arg(long, env = "VITRINE_DB_MAX_CONNECTIONS", default_value_t = 16)]
    pub db_max_connections: u32,
    /// How long a query waits for a connection or lock before answering 503.
    #[arg(long, env = "VITRINE_DB_TIMEOUT_MS", default_value_t = 3000)]
    pub db_timeout_ms: u64,

    /// Byte budget of the in-memory payload cache (0: off).
    #[arg(long, env = "VITRINE_CACHE_BYTES", default_value_t = 256 << 20)]
    pub cache_bytes: u64,
    /// How long model records, policies and tokens are trusted before re-reading.
    #[arg(long, env = "VITRINE_RECORD_TTL_MS", default_value_t = 10_000)]
    pub record_ttl_ms: u64,

    /// Vertex budget of phones.
    #[arg(long, env = "VITRINE_PHONE_MAX_VERTICES", default_value_t = 300_000)]
    pub phone_max_vertices: u32,
    #[arg(long, env = "VITRINE_TABLET_MAX_VERTICES", default_value_t = 1_000_000)]
    pub tablet_max_vertices: u32,
    /// Good-enough level without a study: first level with this fraction of the vertices.
    #[arg(long, env = "VITRINE_GOOD_ENOUGH_FRACTION", default_value_t = 0.2)]
    pub good_enough_fraction: f64,

    /// Hold every model at its good-enough level whatever the load (a launch
    /// day expecting a crowd; the thesis' capped reconstruction, §6.5).
    /// Study participants are not held.
    #[arg(long, env = "VITRINE_LOAD_PIN")]
    pub load_pin: bool,
    /// Load is high at this many data requests in flight…
    #[arg(long, env = "VITRINE_LOAD_HIGH_INFLIGHT", default_value_t = 384)]
    pub load_high_inflight: u64,
    /// …and low again at this many (with the other signals low too).
    #[arg(long, env = "VITRINE_LOAD_LOW_INFLIGHT", default_value_t = 128)]
    pub load_low_inflight: u64,
    /// Smoothed handler latency that counts as high load.
    #[arg(long, env = "VITRINE_LOAD_HIGH_LATENCY_MS", default_value_t = 250)]
    pub load_high_latency_ms: u64,
    #[arg(long, env = "VITRINE_LOAD_LOW_LATENCY_MS", default_value_t = 50)]
    pub load_low_latency_ms: u64,
    /// Smoothed runtime queueing delay that counts as high load.
    #[arg(long, env = "VITRINE_LOAD_HIGH_QUEUE_MS", default_value_t = 25)]
    pub load_high_queue_ms: u64,
    #[arg(long, env = "VITRINE_LOAD_LOW_QUEUE_MS", default_value_t = 5)]
    pub load_low_queue_ms: u64,
    #[arg(long, env = "VITRINE_LOAD_SAMPLE_MS", default_value_t = 250)]
    pub load_sample_ms: u64,
    /// Pressure steps from no load cap to the good-enough level.
    #[arg(long, env = "VITRINE_LOAD_STEPS", default_value_t = 4)]
    pub load_steps: u8,
    /// Calm samples before pressure falls one step.
    #[arg(long, env = "VITRINE_LOAD_COOLDOWN_SAMPLES", default_value_t = 8)]
    pub load_cooldown_samples: u32,
    /// New visitors (manifest requests) admitted per second once
    /// `--admit-burst` is used up; the rest get 503 `busy` with `Retry-After`
    /// (0: no admission control).
    #[arg(long, env = "VITRINE_ADMIT_RATE", default_value_t = 200.0)]
    pub admit_rate: f64,
    /// New visitors admitted at once.
    #[arg(long, env = "VITRINE_ADMIT_BURST", default_value_t = 100.0)]
    pub admit_burst: f64,
    /// `Retry-After` of load-capped answers.
    #[arg(long, env = "VITRINE_LOAD_RETRY_AFTER_S", default_value_t = 10)]
    pub load_retry_after_s: u64,

    /// Longest a request may take before 504.
    #[arg(long, env = "VITRINE_REQUEST_TIMEOUT_MS", default_value_t = 10_000)]
    pub request_timeout_ms: u64,
    /// Requests handled at once; more are shed with 503.
    #[arg(long, env = "VITRINE_MAX_CONCURRENCY", default_value_t = 1024)]
    pub max_concurrency: usize,
    #[arg(long, env = "VITRINE_MAX_BODY_BYTES", default_value_t = 64 * 1024)]
    pub max_body_bytes: usize,
    #[arg(long, env = "VITRINE_MAX_HEADER_BYTES", default_value_t = 16 * 1024)]
    pub max_header_bytes: usize,
    #[arg(long, env = "VITRINE_SHUTDOWN_GRACE_MS", default_value_t = 10_000)]
    pub shutdown_grace_ms: u64,
    /// After SIGTERM, how long `/readyz` answers 503 while requests are
    /// still served, so a load balancer's health check takes the instance
    /// out before it stops accepting connections.
    #[arg(long, env = "VITRINE_SHUTDOWN_DELAY_MS", default_value_t = 0)]
    pub shutdown_delay_ms: u64,

    /// Proxies whose `X-Forwarded-For` / `Forwarded` is believed
    /// (comma-separated CIDRs, e.g. `127.0.0.1/32,10.0.0.0/8`); none by default:
    /// the visitor is then the TCP peer.
    #[arg(
        long = "trusted-proxies",
        env = "VITRINE_TRUSTED_PROXIES",
        value_delimiter = ','
    )]
    pub trusted_proxies: Vec<ipnet::IpNet>,
    /// How often the database's change counter is read, so that versions
    /// ingested or withdrawn elsewhere show here (PostgreSQL also notifies at
    /// once; this is its fallback). 0: never.
    #[arg(long, env = "VITRINE_COHERENCE_POLL_MS", default_value_t = 2000)]
    pub coherence_poll_ms: u64,
    /// The museum's own words for the viewer: only from the file's
    /// `[ui.strings.<language>]` tables (config/mod.rs), never a flag.
    #[arg(skip)]
    #[serde(skip)]
    pub ui_strings: crate::service::UiStrings,
}

impl ServeArgs {
    pub fn connect_options(&self) -> ConnectOptions {
        ConnectOptions {
            max_connections: self.db_max_connections,
            acquire_timeout: Duration::from_millis(self.db_timeout_ms),
            ..ConnectOptions::default()
        }
    }

    pub fn service_config(&self) -> ServiceConfig {
        let ms = Duration::from_millis;
        ServiceConfig {
            caps: CapRules {
                phone_max_vertices: self.phone_max_vertices,
                tablet_max_vertices: self.tablet_max_vertices,
                good_enough_fraction: self.good_enough_fraction,
            },
            load: LoadConfig {
                high_inflight: self.load_high_inflight,
                low_inflight: self.load_low_inflight,
                high_latency: ms(self.load_high_latency_ms),
                low_latency: ms(self.load_low_latency_ms),
                high_queue: ms(self.load_high_queue_ms),
                low_queue: ms(self.load_low_queue_ms),
                sample_every: ms(self.load_sample_ms),
                steps: self.load_steps,
                cooldown_samples: self.load_cooldown_samples,
                retry_after: Duration::from_secs(self.load_retry_after_s),
            },
            admission: AdmissionConfig {
                rate: self.admit_rate,
                burst: self.admit_burst,
            },
            cache: CacheConfig {
                payload_bytes: self.cache_bytes,
                record_ttl: ms(self.record_ttl_ms),
                ..CacheConfig::default()
            },
            limits: RequestLimits {
                timeout: ms(self.request_timeout_ms),
                max_concurrency: self.max_concurrency,
                max_body_bytes: self.max_body_bytes,
                ..RequestLimits::default()
            },
            web_dir: self.web_dir.clone(),
            cors_origins: self.cors_origins.clone(),
            uploads: crate::service::curator::UploadConfig {
                dir: self.upload_dir.clone().unwrap_or_else(std::env::temp_dir),
                limit_bytes: self.upload_limit_mb << 20,
                concurrent_jobs: self.ingest_jobs.max(1),
                max_queued: 8,
                public_base_url: self.public_base_url.clone(),
            },
            trusted_proxies: self.trusted_proxies.clone(),
            site_name: self.site_name.clone(),
            ui_strings: self.ui_strings.clone(),
        }
    }

    pub fn serve_limits(&self) -> ServeLimits {
        ServeLimits {
            max_header_bytes: self.max_header_bytes,
            shutdown_grace: Duration::from_millis(self.shutdown_grace_ms),
            ..ServeLimits::default()
        }
    }
}

/// Names every model stored in a stream format this build cannot decode:
/// the service refuses them (409 `stale_format`) until they are ingested
/// again, and the web team should hear that at start-up, not from visitors.
async fn warn_stale_models(storage: &dyn crate::storage::Storage) {
    match storage.list_models().await {
        Ok(models) => {
            for m in models.iter().filter(|m| !m.servable()) {
                tracing::warn!(
                    slug = %m.slug,
                    stored_format = m.stream_format,
                    this_build_reads = vitrine_codec::VERSION,
                    "model is stored in a stream format this build cannot serve; \
                     ingest it again (vitrine ingest) to show it"
                );
            }
        }
        Err(e) => tracing::warn!(error = %e, "could not list models to check their stream format"),
    }
}

/// Runs until Ctrl-C or SIGTERM. A database that is down at start-up is
/// waited for; one that goes away later gives 503s until it is back.
pub async fn run(args: ServeArgs) -> anyhow::Result<()> {
    // The file, when there is one, fills in what flags and variables did not.
    let args = match args.config {
        Some(_) => crate::config::resolve(&serve_argv())?,
        None => args,
    };
    if args.check_config {
        let valid = crate::config::validate(&args);
        print!("{}", crate::config::effective_toml(&args)?);
        return valid;
    }
    super::init_tracing();
    let storage = open_storage(&args.db, &args.connect_options(), true).await?;
    warn_stale_models(storage.as_ref()).await;
    let state = AppState::new(storage, args.service_config());
    let _sampler = state.spawn_load_sampler();
    let _coherence = crate::service::coherence::spawn(
        &state,
        args.db.starts_with("postgres").then(|| args.db.clone()),
        Duration::from_millis(args.coherence_poll_ms),
    );
    if args.load_pin {
        state.load().force_pressure(Some(u8::MAX));
        tracing::info!("load caps pinned at every model's good-enough level");
    }
    let listener = listen(args.listen)?;
    tracing::info!(
        addr = %listener.local_addr()?,
        db = %redact(&args.db),
        backend = state.storage().backend(),
        "serving"
    );
    if let Some(addr) = args.metrics_listen {
        let ops = TcpListener::bind(addr).await?;
        let router = crate::service::ops_app(state.clone());
        let limits = args.serve_limits();
        tracing::info!(addr = %ops.local_addr()?, "serving metrics");
        tokio::spawn(async move { serve(ops, router, limits, std::future::pending()).await });
    }
    let draining = state.clone();
    let delay = Duration::from_millis(args.shutdown_delay_ms);
    let shutdown = async move {
        shutdown_signal().await;
        // Not ready first; keep serving while the balancer notices; then
        // stop accepting and let open requests finish.
        draining.start_draining();
        tracing::info!(
            delay_ms = delay.as_millis() as u64,
            "shutdown asked: /readyz answers 503"
        );
        tokio::time::sleep(delay).await;
    };
    serve(listener, serving(state), args.serve_limits(), shutdown).await?;
    Ok(())
}

/// This process's arguments after `serve`, to parse them with the file's.
fn serve_argv() -> Vec<std::ffi::OsString> {
    std::env::args_os()
        .skip(1)
        .skip_while(|a| a != "serve")
        .skip(1)
        .collect()
}

/// Connections the kernel may hold for us before `accept`. Tokio's
/// default (1,024) overflows when a crowd arrives in the same instant: the
/// dropped SYNs are retried by clients one second later, which was the whole
/// of a 1,000-visitor burst's p99. The kernel caps it at `net.core.somaxconn`.
const LISTEN_BACKLOG: u32 = 8192;

fn listen(addr: std::net::SocketAddr) -> std::io::Result<TcpListener> {
    let socket = if addr.is_ipv4() {
        tokio::net::TcpSocket::new_v4()?
    } else {
        tokio::net::TcpSocket::new_v6()?
    };
    socket.set_reuseaddr(true)?;
    socket.bind(addr)?;
    socket.listen(LISTEN_BACKLOG)
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        serve: ServeArgs,
    }

    #[test]
    fn flag_defaults_match_library_defaults() {
        let args = Cli::parse_from(["vitrine"]).serve;
        assert_eq!(args.service_config(), ServiceConfig::default());
        assert_eq!(args.serve_limits(), ServeLimits::default());
        let c = args.connect_options();
        let d = ConnectOptions::default();
        assert_eq!(
            (c.max_connections, c.acquire_timeout),
            (d.max_connections, d.acquire_timeout)
        );
    }
}
