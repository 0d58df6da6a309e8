//! `vitrine-load`: the crowd load harness and fault helpers of issue #6.
//!
//! ```text
//! vitrine-load run --db sqlite:load.db --slug igea2m --token … --visitors 1,50,100,1000,5000
//! vitrine-load profile --url http://127.0.0.1:8080 --slug igea2m -o profile.json
//! vitrine-load crowd --url … --slug … --profile profile.json --visitors 200 --pattern steady:20
//! vitrine-load hostile --url … --slug …
//! vitrine-load disconnects --url … --path /api/compressions/1/batches/13
//! vitrine-load proxy --listen 127.0.0.1:15433 --to 127.0.0.1:5433 --delay-ms 100
//! ```
//! See tests/README.md and scripts/load.sh, scripts/faults.sh.

mod close_up;
mod crowd;
mod faults;
mod hostile;
mod http;
mod report;
mod scenarios;
mod server;
mod sim;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use report::{Baselines, Summary};
use serde::{Deserialize, Serialize};
use sim::{DecodeProfile, Pattern};
use std::path::PathBuf;
use std::time::Duration;

#[derive(Parser)]
#[command(
    name = "vitrine-load",
    about = "Crowd load harness and fault helpers for Vitrine"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone, Debug)]
struct Mix {
    /// Share of visitors on tablets (the rest on desktops).
    #[arg(long, default_value_t = 0.3)]
    tablet_share: f64,
    /// Share of visitors with a researcher token (the rest public).
    #[arg(long, default_value_t = 0.05)]
    researcher_share: f64,
    /// Tablets decode this many times slower than this machine's native decoder.
    #[arg(long, default_value_t = 3.0)]
    tablet_factor: f64,
    /// Researcher token (`vitrine token`); without it researchers are public visitors.
    #[arg(long, env = "VITRINE_LOAD_TOKEN")]
    token: Option<String>,
    /// Per request, to the last byte.
    #[arg(long, default_value_t = 120)]
    request_timeout_s: u64,
    /// How long a visitor held by a load cap keeps the page open, reading
    /// the manifest again after each `Retry-After` as the viewer does and
    /// refining further when the cap has risen (0: stop at the first cap).
    #[arg(long, default_value_t = 30.0)]
    stay_s: f64,
    /// Each visitor looks closely at one region of a charted or nested
    /// stream and fetches only its parts once the charts begin, as the
    /// viewer's `?refine=view` does (streams without parts: whole batches).
    #[arg(long)]
    close_up: bool,
}

#[derive(Subcommand)]
enum Command {
    /// Load scenarios: starts `vitrine serve` afresh for each run, caps off
    /// and on; writes results.json, report.md and an SVG plot.
    Run(RunArgs),
    /// Measures the decode time of each level (the visitors' wait) to a file.
    Profile {
        #[arg(long)]
        url: String,
        #[arg(long)]
        slug: String,
        #[arg(long, env = "VITRINE_LOAD_TOKEN")]
        token: Option<String>,
        #[arg(long, default_value_t = 2)]
        runs: usize,
        #[arg(short, long)]
        output: PathBuf,
    },
    /// One crowd against a running server, with a timeline of answers and
    /// optional checks (for the fault scripts).
    Crowd(CrowdArgs),
    /// Hostile HTTP cases; exits non-zero if any gets the wrong answer.
    Hostile {
        #[arg(long)]
        url: String,
        #[arg(long)]
        slug: String,
        #[arg(long, env = "VITRINE_LOAD_TOKEN")]
        token: Option<String>,
        /// Also the slow-client cases (about 12 s).
        #[arg(long)]
        slow: bool,
    },
    /// Clients that hang up mid-answer; checks the server is unharmed.
    Disconnects {
        #[arg(long)]
        url: String,
        #[arg(long)]
        path: String,
        #[arg(long, default_value_t = 300)]
        clients: usize,
        /// Bytes read before hanging up (0: hang up before reading).
        #[arg(long, default_value_t = 16384)]
        read_bytes: usize,
    },
    /// A TCP proxy that delays everything the upstream sends.
    Proxy {
        #[arg(long)]
        listen: String,
        #[arg(long)]
        to: String,
        #[arg(long, default_value_t = 100)]
        delay_ms: u64,
    },
    /// Redraws the table and the SVG from a results.json.
    Plot {
        results: PathBuf,
        #[arg(long)]
        svg: PathBuf,
    },
}

#[derive(clap::Args)]
struct RunArgs {
    #[arg(long, default_value = "target/release/vitrine")]
    bin: PathBuf,
    #[arg(long)]
    db: String,
    #[arg(long)]
    slug: String,
    #[arg(long, default_value = "127.0.0.1:18090")]
    listen: String,
    /// Crowd sizes, comma-separated.
    #[arg(long, value_delimiter = ',', default_value = "1,50,100,1000,5000")]
    visitors: Vec<usize>,
    /// Load caps off (thresholds out of reach) and/or on (the defaults).
    #[arg(long, value_delimiter = ',', default_value = "off,on")]
    caps: Vec<String>,
    /// burst (all at once), ramp:SECS or steady:SECS.
    #[arg(long, default_value = "burst")]
    pattern: Pattern,
    /// Runs per scenario; the table gives column-wise medians.
    #[arg(long, default_value_t = 1)]
    runs: usize,
    #[command(flatten)]
    mix: Mix,
    /// A decode profile from an earlier run (else measured, 2 decodes).
    #[arg(long)]
    profile: Option<PathBuf>,
    #[arg(long, default_value = "target/load")]
    out: PathBuf,
    #[arg(long)]
    svg: Option<PathBuf>,
    /// Passed to `vitrine serve` (repeat the flag for each argument).
    #[arg(long = "serve-arg", allow_hyphen_values = true)]
    serve_args: Vec<String>,
    /// Fail if a caps-on scenario of `--check-visitors` has a higher p99.
    #[arg(long)]
    max_p99_ms: Option<f64>,
    /// Fail if its visitors' p95 reconstruction exceeds this multiple of a lone visitor's.
    #[arg(long)]
    max_ratio: Option<f64>,
    #[arg(long)]
    check_visitors: Option<usize>,
    /// Fail unless load caps held some of its visitors and every one of them
    /// refined on after a re-check (run with thresholds the crowd exceeds).
    #[arg(long)]
    check_resume: bool,
}

#[derive(clap::Args)]
struct CrowdArgs {
    #[arg(long)]
    url: String,
    #[arg(long)]
    slug: String,
    #[arg(long)]
    profile: PathBuf,
    #[arg(long, default_value_t = 100)]
    visitors: usize,
    #[arg(long, default_value = "steady:20")]
    pattern: Pattern,
    #[command(flatten)]
    mix: Mix,
    /// Timeline bucket width.
    #[arg(long, default_value_t = 1000)]
    timeline_ms: u64,
    /// Statuses besides 200/304 that are acceptable (each with Retry-After for 429/503).
    #[arg(long, default_value = "429,503")]
    allow: String,
    /// Statuses that must be seen at least once (e.g. 503 during an outage).
    #[arg(long, value_delimiter = ',')]
    require: Vec<u16>,
    /// Every request started this long after the start must get 200/304.
    #[arg(long)]
    clean_after_s: Option<f64>,
    /// Sends SIGTERM to this pid `--sigterm-after-s` into the run; requests
    /// in flight then must complete, later ones may find the port closed.
    #[arg(long)]
    sigterm_pid: Option<u32>,
    #[arg(long, default_value_t = 3.0)]
    sigterm_after_s: f64,
    /// Writes the summary and timeline as JSON.
    #[arg(long)]
    json: Option<PathBuf>,
    /// Fail unless visitors started on at least this many model versions
    /// (a version ingested mid-run reached them).
    #[arg(long, default_value_t = 0)]
    require_versions: usize,
}

#[derive(Serialize, Deserialize)]
struct Results {
    machine: String,
    command: String,
    profile: DecodeProfile,
    baselines: Vec<(String, Baselines)>,
    runs: Vec<Summary>,
    medians: Vec<Summary>,
}

fn main() -> Result<()> {
    let cli = Cli::parse();
    let mut builder = tokio::runtime::Builder::new_multi_thread();
    // Worker threads (default: one per core). The harness shares the cores
    // with the server it measures.
    if let Some(n) = std::env::var("VITRINE_LOAD_THREADS")
        .ok()
        .and_then(|v| v.parse::<usize>().ok())
    {
        builder.worker_threads(n.max(1));
    }
    let runtime = builder.enable_all().build()?;
    runtime.block_on(async {
        match cli.command {
            Command::Run(args) => scenarios::run(args).await,
            Command::Profile {
                url,
                slug,
                token,
                runs,
                output,
            } => profile(&url, &slug, token.as_deref(), runs, &output).await,
            Command::Crowd(args) => crowd::crowd(args).await,
            Command::Hostile {
                url,
                slug,
                token,
                slow,
            } => hostile_cmd(&url, &slug, token, slow).await,
            Command::Disconnects {
                url,
                path,
                clients,
                read_bytes,
            } => {
                let addr = url.trim_start_matches("http://").trim_end_matches('/');
                let line = faults::disconnects(addr, &path, clients, read_bytes).await?;
                println!("{line}");
                Ok(())
            }
            Command::Proxy {
                listen,
                to,
                delay_ms,
            } => faults::proxy(&listen, &to, Duration::from_millis(delay_ms)).await,
            Command::Plot { results, svg } => plot(&results, &svg),
        }
    })
}

async fn profile(
    url: &str,
    slug: &str,
    token: Option<&str>,
    runs: usize,
    output: &std::path::Path,
) -> Result<()> {
    let p = sim::measure_profile(url, slug, token, runs).await?;
    std::fs::write(output, serde_json::to_vec_pretty(&p)?)?;
    eprintln!(
        "decode profile of {slug}: {:.0} ms over {} levels",
        p.decode_ms.iter().sum::<f64>(),
        p.decode_ms.len()
    );
    Ok(())
}

fn plot(results: &std::path::Path, svg: &std::path::Path) -> Result<()> {
    let mut r: Results = serde_json::from_slice(&std::fs::read(results)?)?;
    // Regroup the runs, so that a newer median rule applies.
    let mut groups: Vec<Vec<Summary>> = Vec::new();
    for run in &r.runs {
        let same = |g: &Vec<Summary>| {
            g[0].caps == run.caps && g[0].visitors == run.visitors && g[0].pattern == run.pattern
        };
        match groups.iter_mut().find(|g| same(g)) {
            Some(g) => g.push(run.clone()),
            None => groups.push(vec![run.clone()]),
        }
    }
    r.medians = groups.iter().map(|g| report::median_of(g)).collect();
    let lone = lone_seconds(&r);
    std::fs::write(svg, report::svg(&r.medians, lone, &plot_title(&r)))?;
    print!("{}", report::markdown(&r.medians));
    Ok(())
}

fn machine() -> String {
    let cores = std::thread::available_parallelism().map_or(0, |n| n.get());
    let load = std::fs::read_to_string("/proc/loadavg").unwrap_or_default();
    let mem = std::fs::read_to_string("/proc/meminfo")
        .ok()
        .and_then(|m| {
            m.lines()
                .find_map(|l| l.strip_prefix("MemTotal:"))
                .and_then(|v| v.split_whitespace().next()?.parse::<f64>().ok())
        })
        .map_or(0.0, |kib| kib / 1024.0 / 1024.0);
    format!(
        "{cores} cores, {mem:.0} GiB; load average {}",
        load.split_whitespace()
            .take(3)
            .collect::<Vec<_>>()
            .join(" ")
    )
}

fn lone_seconds(r: &Results) -> Option<f64> {
    // A lone public desktop visitor's full reconstruction, caps off.
    r.baselines.iter().find_map(|(caps, b)| {
        (caps == "off" || r.baselines.len() == 1)
            .then(|| {
                b.0.iter()
                    .find(|(d, a, _)| *d == sim::Device::Desktop && *a == sim::Audience::Public)
                    .and_then(|(_, _, t)| t.last().map(|ms| ms / 1e3))
            })
            .flatten()
    })
}

fn plot_title(r: &Results) -> String {
    let v = r.profile.vertices.last().copied().unwrap_or(0);
    format!(
        "{} ({:.2} M vertices, {} levels): crowd arriving at once, one 2-core machine",
        r.profile.model,
        f64::from(v) / 1e6,
        r.profile.vertices.len()
    )
}

/// Prints each failed check and fails when there is one.
fn fail_on(violations: &[String]) -> Result<()> {
    if violations.is_empty() {
        return Ok(());
    }
    for v in violations {
        eprintln!("FAIL: {v}");
    }
    bail!("{} check(s) failed", violations.len());
}

async fn hostile_cmd(url: &str, slug: &str, token: Option<String>, slow: bool) -> Result<()> {
    let url = url.trim_end_matches('/');
    let manifest: serde_json::Value = reqwest::get(format!("{url}/api/models/{slug}"))
        .await?
        .error_for_status()?
        .json()
        .await?;
    let target = hostile::Target {
        addr: url.trim_start_matches("http://").to_owned(),
        slug: slug.to_owned(),
        compression_id: manifest["compression_id"]
            .as_i64()
            .context("compression_id")?,
        last_level: manifest["last_level"].as_u64().context("last_level")? as u32,
        token,
        slow,
    };
    let cases = hostile::run(&target).await?;
    println!("| case | expected | got | |\n|---|---|---|---|");
    for c in &cases {
        println!(
            "| {} | {} | {} | {} |",
            c.name.replace('|', "\\|"),
            c.expected,
            c.got,
            if c.pass { "pass" } else { "**FAIL**" }
        );
    }
    let failed = cases.iter().filter(|c| !c.pass).count();
    if failed > 0 {
        bail!(
            "{failed} of {} hostile cases got the wrong answer",
            cases.len()
        );
    }
    println!("\nall {} hostile cases answered as expected", cases.len());
    Ok(())
}
