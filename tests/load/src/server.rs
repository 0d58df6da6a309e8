//! `vitrine serve` as a child process, with its CPU time and peak memory
//! read from `/proc/<pid>/stat` and `/proc/<pid>/status`.

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

/// Flags that put the load thresholds out of reach (as scripts/bench-service.sh)
/// and turn admission control off: the service without load protection.
pub const CAPS_OFF: &[&str] = &[
    "--admit-rate",
    "0",
    "--load-high-inflight",
    "1000000000",
    "--load-high-latency-ms",
    "1000000000",
    "--load-high-queue-ms",
    "1000000000",
];

pub struct Server {
    child: tokio::process::Child,
    pub pid: u32,
    pub url: String,
    pub log: PathBuf,
}

impl Server {
    pub async fn start(
        bin: &Path,
        db: &str,
        listen: &str,
        caps_on: bool,
        extra: &[String],
        log: PathBuf,
    ) -> Result<Server> {
        let mut args: Vec<String> = vec![
            "serve".into(),
            "--db".into(),
            db.into(),
            "--listen".into(),
            listen.into(),
            "--web-dir".into(),
            "/nonexistent".into(),
        ];
        if !caps_on {
            args.extend(CAPS_OFF.iter().map(|s| s.to_string()));
        }
        args.extend(extra.iter().cloned());
        let log_file = std::fs::File::create(&log).with_context(|| log.display().to_string())?;
        let child = tokio::process::Command::new(bin)
            .args(&args)
            .env(
                "RUST_LOG",
                std::env::var("RUST_LOG").unwrap_or("warn".into()),
            )
            .stdout(Stdio::null())
            .stderr(log_file)
            .kill_on_drop(true)
            .spawn()
            .with_context(|| format!("starting {}", bin.display()))?;
        let pid = child.id().context("server pid")?;
        let server = Server {
            child,
            pid,
            url: format!("http://{listen}"),
            log,
        };
        if let Err(e) = wait_ready(&server.url, Duration::from_secs(30)).await {
            let log = std::fs::read_to_string(&server.log).unwrap_or_default();
            bail!("{e}; server log:\n{log}");
        }
        Ok(server)
    }

    pub fn cpu_seconds(&self) -> Result<f64> {
        cpu_seconds(self.pid)
    }

    /// VmHWM: the process's peak resident set, in MiB.
    pub fn peak_rss_mib(&self) -> Result<f64> {
        let status = std::fs::read_to_string(format!("/proc/{}/status", self.pid))?;
        let kib: f64 = status
            .lines()
            .find_map(|l| l.strip_prefix("VmHWM:"))
            .and_then(|v| v.split_whitespace().next())
            .and_then(|v| v.parse().ok())
            .context("no VmHWM")?;
        Ok(kib / 1024.0)
    }

    /// SIGTERM, then wait (SIGKILL after 30 s).
    pub async fn stop(mut self) -> Result<std::process::ExitStatus> {
        let _ = tokio::process::Command::new("kill")
            .args(["-TERM", &self.pid.to_string()])
            .status()
            .await;
        match tokio::time::timeout(Duration::from_secs(30), self.child.wait()).await {
            Ok(status) => Ok(status?),
            Err(_) => {
                self.child.kill().await?;
                bail!("server {} ignored SIGTERM for 30 s", self.pid)
            }
        }
    }
}

pub async fn wait_ready(url: &str, within: Duration) -> Result<()> {
    let client = reqwest::Client::new();
    let deadline = Instant::now() + within;
    loop {
        if let Ok(r) = client.get(format!("{url}/readyz")).send().await {
            if r.status().is_success() {
                return Ok(());
            }
        }
        if Instant::now() > deadline {
            bail!("{url}/readyz did not answer 200 within {within:?}");
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

fn clock_ticks() -> f64 {
    std::process::Command::new("getconf")
        .arg("CLK_TCK")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(100.0)
}

/// User plus system CPU time of a process, in seconds.
pub fn cpu_seconds(pid: u32) -> Result<f64> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat"))?;
    // Fields after the command name, which sits in parentheses: state is
    // field 3, utime 14, stime 15 (proc(5)).
    let rest = stat.rsplit_once(") ").context("bad /proc stat")?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks: f64 = fields[11].parse::<f64>()? + fields[12].parse::<f64>()?;
    Ok(ticks / clock_ticks())
}

pub fn own_cpu_seconds() -> f64 {
    cpu_seconds(std::process::id()).unwrap_or(0.0)
}
