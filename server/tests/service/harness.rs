//! Test databases on both backends, a TCP proxy to cut PostgreSQL off, and a
//! server on port 0.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Duration;
use tempfile::TempDir;
use tokio::net::TcpListener;
use tokio::sync::oneshot;
use vitrine::ingest::{ingest_mesh, IngestOptions, IngestReport, ModelMeta};
use vitrine::storage::{connect, ConnectOptions, Storage};
use vitrine::{app, AppState, ServeLimits, ServiceConfig};
use vitrine_codec::{encode, EncodeOptions, Encoded, IndexedMesh};
use vitrine_samples::{paint, torus};

use super::proxy::Proxy;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Backend {
    Sqlite,
    Postgres,
}

/// A fresh database, dropped at the end of the test.
pub struct TestDb {
    /// What the service connects to (through the proxy for PostgreSQL).
    pub url: String,
    pub storage: Arc<dyn Storage>,
    sqlite: Option<SqliteFile>,
    postgres: Option<PgDatabase>,
}

struct SqliteFile {
    dir: TempDir,
    path: PathBuf,
}

struct PgDatabase {
    admin_url: String,
    name: String,
    proxy: Proxy,
}

fn admin_url() -> String {
    std::env::var("VITRINE_TEST_POSTGRES")
        .unwrap_or_else(|_| "postgres://postgres@127.0.0.1:5432/postgres".into())
}

/// Options that make outages show quickly.
pub fn test_connect_options() -> ConnectOptions {
    ConnectOptions {
        max_connections: 8,
        acquire_timeout: Duration::from_millis(750),
        max_lifetime: Duration::from_millis(200),
    }
}

impl TestDb {
    /// `None` when PostgreSQL is unreachable outside CI (the test is skipped);
    /// under `CI` that is a failure.
    pub async fn new(backend: Backend) -> Option<TestDb> {
        let db = match backend {
            Backend::Sqlite => Self::sqlite(),
            Backend::Postgres => Self::postgres().await?,
        };
        db.storage.migrate().await.expect("migrations apply");
        Some(db)
    }

    fn sqlite() -> TestDb {
        let dir = tempfile::tempdir().expect("temp dir");
        let path = dir.path().join("vitrine.db");
        let url = format!("sqlite:{}", path.display());
        let storage = connect(&url, &test_connect_options()).expect("sqlite storage");
        TestDb {
            url,
            storage,
            sqlite: Some(SqliteFile { dir, path }),
            postgres: None,
        }
    }

    async fn postgres() -> Option<TestDb> {
        use sqlx::Connection;
        let admin = admin_url();
        let mut conn = match sqlx::PgConnection::connect(&admin).await {
            Ok(c) => c,
            Err(e) if std::env::var_os("CI").is_some() => {
                panic!("PostgreSQL at {admin} is unreachable ({e}); CI needs it: run scripts/start-postgres.sh")
            }
            Err(e) => {
                // Straight to stderr: the test harness captures only the print macros.
                use std::io::Write;
                let _ = writeln!(
                    std::io::stderr(),
                    "note: skipping a PostgreSQL test: {admin} is unreachable ({e}); run scripts/start-postgres.sh"
                );
                return None;
            }
        };
        let name = format!("vitrine_test_{}", hex::encode(rand::random::<[u8; 6]>()));
        sqlx::query(&format!("CREATE DATABASE {name}"))
            .execute(&mut conn)
            .await
            .expect("create database");
        let _ = conn.close().await;
        let target = pg_host_port(&admin);
        let proxy = Proxy::start(target).await;
        let url = format!("postgres://postgres@{}/{name}", proxy.addr());
        let url = match pg_password(&admin) {
            Some(password) => url.replacen("postgres@", &format!("postgres:{password}@"), 1),
            None => url,
        };
        let storage = connect(&url, &test_connect_options()).expect("postgres storage");
        Some(TestDb {
            url,
            storage,
            sqlite: None,
            postgres: Some(PgDatabase {
                admin_url: admin,
                name,
                proxy,
            }),
        })
    }

    /// Runs one SQL statement on the database, beside the storage (a test
    /// reaching into rows the service never writes that way).
    pub async fn execute(&self, sql: &str) {
        use sqlx::Connection;
        if self.sqlite.is_some() {
            let mut conn = sqlx::SqliteConnection::connect(&self.url)
                .await
                .expect("sqlite");
            sqlx::query(sql).execute(&mut conn).await.expect(sql);
        } else {
            let mut conn = sqlx::PgConnection::connect(&self.url)
                .await
                .expect("postgres");
            sqlx::query(sql).execute(&mut conn).await.expect(sql);
        }
    }

    /// Another storage on the same database (e.g. a second server).
    pub fn connect_again(&self) -> Arc<dyn Storage> {
        connect(&self.url, &test_connect_options()).expect("storage")
    }

    /// The database goes away: PostgreSQL's connections are cut and new ones
    /// refused; SQLite's file is moved aside, so connections (reopened after
    /// `max_lifetime`) cannot open it.
    pub async fn outage(&self) {
        if let Some(f) = &self.sqlite {
            for suffix in ["", "-wal", "-shm"] {
                let from = PathBuf::from(format!("{}{suffix}", f.path.display()));
                let to = f.dir.path().join(format!("away{suffix}"));
                if from.exists() {
                    std::fs::rename(from, to).expect("move database aside");
                }
            }
        }
        if let Some(pg) = &self.postgres {
            pg.proxy.cut();
        }
    }

    pub async fn restore(&self) {
        if let Some(f) = &self.sqlite {
            for suffix in ["", "-wal", "-shm"] {
                let from = f.dir.path().join(format!("away{suffix}"));
                let to = PathBuf::from(format!("{}{suffix}", f.path.display()));
                if from.exists() {
                    std::fs::rename(from, to).expect("move database back");
                }
            }
        }
        if let Some(pg) = &self.postgres {
            pg.proxy.restore();
        }
    }
}

impl Drop for TestDb {
    fn drop(&mut self) {
        let Some(pg) = self.postgres.take() else {
            return;
        };
        pg.proxy.cut();
        // Drop runs outside any runtime we may block: use a thread of its own.
        let _ = std::thread::spawn(move || {
            let rt = tokio::runtime::Builder::new_current_thread()
                .enable_all()
                .build()
                .expect("runtime");
            rt.block_on(async {
                use sqlx::Connection;
                if let Ok(mut conn) = sqlx::PgConnection::connect(&pg.admin_url).await {
                    let sql = format!("DROP DATABASE IF EXISTS {} WITH (FORCE)", pg.name);
                    let _ = sqlx::query(&sql).execute(&mut conn).await;
                }
            });
        })
        .join();
    }
}

fn pg_host_port(url: &str) -> String {
    let rest = url.split_once("://").map_or(url, |(_, r)| r);
    let rest = rest.rsplit_once('@').map_or(rest, |(_, r)| r);
    let host = rest.split(['/', '?']).next().unwrap_or("127.0.0.1:5432");
    if host.contains(':') {
        host.to_owned()
    } else {
        format!("{host}:5432")
    }
}

fn pg_password(url: &str) -> Option<String> {
    let rest = url.split_once("://")?.1;
    let userinfo = rest.rsplit_once('@')?.0;
    Some(userinfo.split_once(':')?.1.to_owned())
}

/// A painted torus: 1,800 vertices, about 7 levels.
pub fn sample_mesh() -> IndexedMesh {
    let mut m = torus(60, 30, 1.0, 0.3);
    paint(&mut m);
    m
}

/// The codec's own output for `sample_mesh`, to compare served bytes with.
pub fn sample_encoded() -> Encoded {
    encode(&sample_mesh(), &EncodeOptions::default()).expect("encode")
}

pub async fn ingest_sample(storage: &dyn Storage, slug: &str, policy: &str) -> IngestReport {
    ingest_sample_with(storage, slug, policy, None).await
}

/// With a good-enough level from a (pretend) quality study.
pub async fn ingest_sample_with(
    storage: &dyn Storage,
    slug: &str,
    policy: &str,
    good_enough_level: Option<u32>,
) -> IngestReport {
    let mut meta = ModelMeta::new(slug, format!("Sample {slug}"));
    meta.policy = policy.into();
    meta.good_enough_level = good_enough_level;
    ingest_mesh(storage, sample_mesh(), meta, &IngestOptions::default())
        .await
        .expect("ingest")
}

/// A service configuration for tests: no static files, small device budgets.
pub fn test_config() -> ServiceConfig {
    let mut config = ServiceConfig {
        web_dir: PathBuf::from("/nonexistent"),
        ..ServiceConfig::default()
    };
    config.caps.phone_max_vertices = 150;
    config.caps.tablet_max_vertices = 400;
    config
}

/// A server on 127.0.0.1:0 that stops when dropped.
pub struct TestServer {
    pub base: String,
    stop: Option<oneshot::Sender<()>>,
    running: Option<tokio::task::JoinHandle<std::io::Result<()>>>,
}

impl TestServer {
    pub async fn start(storage: Arc<dyn Storage>, config: ServiceConfig) -> TestServer {
        TestServer::serve(AppState::new(storage, config)).await
    }

    /// Serves `state`, which the test may keep to steer the service.
    pub async fn serve(state: AppState) -> TestServer {
        state.spawn_load_sampler();
        let listener = TcpListener::bind("127.0.0.1:0").await.expect("bind");
        let base = format!("http://{}", listener.local_addr().expect("addr"));
        let (stop, stopped) = oneshot::channel::<()>();
        let router = app(state);
        let limits = ServeLimits {
            shutdown_grace: Duration::from_secs(5),
            ..ServeLimits::default()
        };
        let running = tokio::spawn(async move {
            let shutdown = async {
                let _ = stopped.await;
            };
            vitrine::serve(listener, router, limits, shutdown).await
        });
        TestServer {
            base,
            stop: Some(stop),
            running: Some(running),
        }
    }

    /// Asks for a graceful shutdown and waits until `serve` returns.
    pub async fn shut_down(mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
        if let Some(running) = self.running.take() {
            running.await.expect("serve task").expect("serve");
        }
    }

    pub fn url(&self, path: &str) -> String {
        format!("{}{path}", self.base)
    }
}

impl Drop for TestServer {
    fn drop(&mut self) {
        if let Some(stop) = self.stop.take() {
            let _ = stop.send(());
        }
    }
}

/// Polls `check` every 20 ms until it holds or `within` passes.
pub async fn eventually<F, Fut>(within: Duration, what: &str, mut check: F)
where
    F: FnMut() -> Fut,
    Fut: std::future::Future<Output = bool>,
{
    let deadline = tokio::time::Instant::now() + within;
    loop {
        if check().await {
            return;
        }
        assert!(
            tokio::time::Instant::now() < deadline,
            "timed out waiting for {what}"
        );
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}
