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

mod faults;
mod hostile;
mod http;
mod report;
mod server;
mod sim;

use anyhow::{bail, Context, Result};
use clap::{Parser, Subcommand};
use report::{Baselines, Summary};
use serde::{Deserialize, Serialize};
use sim::{CrowdConfig, DecodeProfile, Pattern};
use std::path::PathBuf;
use std::sync::Arc;
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
            Command::Run(args) => run(args).await,
            Command::Profile {
                url,
                slug,
                token,
                runs,
                output,
            } => {
                let p = sim::measure_profile(&url, &slug, token.as_deref(), runs).await?;
                std::fs::write(&output, serde_json::to_vec_pretty(&p)?)?;
                eprintln!(
                    "decode profile of {slug}: {:.0} ms over {} levels",
                    p.decode_ms.iter().sum::<f64>(),
                    p.decode_ms.len()
                );
                Ok(())
            }
            Command::Crowd(args) => crowd(args).await,
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
            Command::Plot { results, svg } => {
                let mut r: Results = serde_json::from_slice(&std::fs::read(&results)?)?;
                // Regroup the runs, so that a newer median rule applies.
                let mut groups: Vec<Vec<Summary>> = Vec::new();
                for run in &r.runs {
                    let same = |g: &Vec<Summary>| {
                        g[0].caps == run.caps
                            && g[0].visitors == run.visitors
                            && g[0].pattern == run.pattern
                    };
                    match groups.iter_mut().find(|g| same(g)) {
                        Some(g) => g.push(run.clone()),
                        None => groups.push(vec![run.clone()]),
                    }
                }
                r.medians = groups.iter().map(|g| report::median_of(g)).collect();
                let lone = lone_seconds(&r);
                std::fs::write(&svg, report::svg(&r.medians, lone, &plot_title(&r)))?;
                print!("{}", report::markdown(&r.medians));
                Ok(())
            }
        }
    })
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

async fn run(args: RunArgs) -> Result<()> {
    std::fs::create_dir_all(&args.out)?;
    // The token is a secret of the test database: not in the report.
    let mut command = Vec::new();
    let mut secret = false;
    for a in std::env::args() {
        command.push(if secret { "…".to_string() } else { a.clone() });
        secret = a == "--token";
    }
    let command = command.join(" ");
    let mut machine_line = format!("before: {}", machine());
    let start = |caps_on: bool, tag: String| {
        let log = args.out.join(format!("serve-{tag}.log"));
        server::Server::start(
            &args.bin,
            &args.db,
            &args.listen,
            caps_on,
            &args.serve_args,
            log,
        )
    };
    let profile = match &args.profile {
        Some(p) => serde_json::from_slice(&std::fs::read(p)?)?,
        None => {
            let s = start(true, "profile".into()).await?;
            let p = sim::measure_profile(&s.url, &args.slug, args.mix.token.as_deref(), 2).await;
            s.stop().await?;
            let p = p?;
            std::fs::write(
                args.out.join("profile.json"),
                serde_json::to_vec_pretty(&p)?,
            )?;
            p
        }
    };
    eprintln!(
        "decode profile: {} levels, {:.2} s in all (native, this machine)",
        profile.decode_ms.len(),
        profile.decode_ms.iter().sum::<f64>() / 1e3
    );
    let profile = Arc::new(profile);
    let crowd_config = |url: &str, visitors: usize, sequential: bool| CrowdConfig {
        base_url: url.to_owned(),
        slug: args.slug.clone(),
        token: args.mix.token.clone(),
        visitors,
        pattern: args.pattern,
        tablet_share: args.mix.tablet_share,
        researcher_share: args.mix.researcher_share,
        tablet_factor: args.mix.tablet_factor,
        request_timeout: Duration::from_secs(args.mix.request_timeout_s),
        stay: Duration::from_secs_f64(args.mix.stay_s.max(0.0)),
        sigterm: None,
        sequential,
    };
    let mut all = Vec::new();
    let mut medians = Vec::new();
    let mut baselines = Vec::new();
    let mut violations = Vec::new();
    for caps in &args.caps {
        let caps_on = match caps.as_str() {
            "on" => true,
            "off" => false,
            other => bail!("--caps takes off and on, not {other:?}"),
        };
        // A lone visitor of each kind, one after another, on a fresh server.
        let s = start(caps_on, format!("caps-{caps}-alone")).await?;
        let alone = sim::run_crowd(crowd_config(&s.url, 1000, true), Arc::clone(&profile)).await;
        s.stop().await?;
        let base = Baselines::from_visitors(&alone?.visitors);
        for (d, a, t) in &base.0 {
            eprintln!(
                "caps {caps}: lone {d:?}/{a:?} visitor: level {} in {:.2} s",
                t.len().saturating_sub(1),
                t.last().copied().unwrap_or(0.0) / 1e3
            );
        }
        for &n in &args.visitors {
            let mut runs = Vec::new();
            for run in 1..=args.runs {
                let s = start(caps_on, format!("caps-{caps}-{n}-{run}")).await?;
                let cpu0 = s.cpu_seconds()?;
                let own0 = server::own_cpu_seconds();
                let outcome =
                    sim::run_crowd(crowd_config(&s.url, n, false), Arc::clone(&profile)).await?;
                let mut sum = report::summarize(&outcome, &base);
                sum.server_cpu_s = s.cpu_seconds()? - cpu0;
                sum.server_cpu_pct = 100.0 * sum.server_cpu_s / outcome.wall.as_secs_f64();
                sum.server_peak_rss_mib = s.peak_rss_mib()?;
                sum.harness_cpu_s = server::own_cpu_seconds() - own0;
                s.stop().await?;
                sum.caps = caps.clone();
                sum.pattern = args.pattern.to_string();
                sum.run = run;
                eprintln!(
                    "caps {caps}, {n} visitors, run {run}: p99 {:.1} ms (200/304 only {:.1}, to head {:.1}), reconstruction median {:.2} s (× {:.2} lone, p95 × {:.2}; with the admission wait × {:.2} / {:.2}), {} refused at admission (wait ≤ {:.1} s), {} load-capped ({} resumed after {} re-checks, {} still held when leaving), errors {:?}, server CPU {:.1} s, harness CPU {:.1} s, peak RSS {:.0} MiB, wall {:.1} s",
                    sum.p99_ms, sum.p99_ok_ms, sum.head_p99_ms, sum.recon_median_s, sum.ratio_median, sum.ratio_p95,
                    sum.ratio_wait_median, sum.ratio_wait_p95, sum.admission_refused, sum.admission_wait_max_s,
                    sum.load_capped, sum.resumed, sum.rechecks, sum.held_at_end, sum.errors, sum.server_cpu_s, sum.harness_cpu_s, sum.server_peak_rss_mib, sum.wall_s
                );
                for (status, count) in &sum.errors {
                    if status != "429" && status != "503" {
                        violations.push(format!(
                            "caps {caps}, {n} visitors: {count} answers {status}"
                        ));
                    }
                }
                if sum.missing_retry_after > 0 {
                    violations.push(format!(
                        "caps {caps}, {n} visitors: {} 429/503 without Retry-After",
                        sum.missing_retry_after
                    ));
                }
                runs.push(sum);
            }
            let m = report::median_of(&runs);
            if caps_on && args.check_visitors == Some(n) {
                if let Some(max) = args.max_p99_ms {
                    if m.p99_ms.is_nan() || m.p99_ms > max {
                        violations.push(format!(
                            "caps on, {n} visitors: p99 {:.1} ms > {max} ms",
                            m.p99_ms
                        ));
                    }
                }
                if args.check_resume && (m.load_capped == 0 || m.resumed < m.load_capped) {
                    violations.push(format!(
                        "caps on, {n} visitors: {} resumed of {} load-capped ({} still held when leaving)",
                        m.resumed, m.load_capped, m.held_at_end
                    ));
                }
                if let Some(max) = args.max_ratio {
                    if m.ratio_p95.is_nan() || m.ratio_p95 > max {
                        violations.push(format!(
                            "caps on, {n} visitors: p95 reconstruction × {:.2} lone > × {max}",
                            m.ratio_p95
                        ));
                    }
                }
            }
            medians.push(m);
            all.extend(runs);
        }
        baselines.push((caps.clone(), base));
    }
    machine_line.push_str(&format!("; after: {}", machine()));
    let results = Results {
        machine: machine_line,
        command,
        profile: (*profile).clone(),
        baselines,
        runs: all,
        medians,
    };
    std::fs::write(
        args.out.join("results.json"),
        serde_json::to_vec_pretty(&results)?,
    )?;
    let table = report::markdown(&results.medians);
    let md = format!(
        "Machine: {}\n\nCommand: `{}`\n\n{}",
        results.machine, results.command, table
    );
    std::fs::write(args.out.join("report.md"), &md)?;
    if let Some(svg) = &args.svg {
        let lone = lone_seconds(&results);
        std::fs::write(
            svg,
            report::svg(&results.medians, lone, &plot_title(&results)),
        )?;
    }
    println!("{md}");
    if !violations.is_empty() {
        for v in &violations {
            eprintln!("FAIL: {v}");
        }
        bail!("{} check(s) failed", violations.len());
    }
    eprintln!("load checks passed");
    Ok(())
}

async fn crowd(args: CrowdArgs) -> Result<()> {
    let profile: DecodeProfile = serde_json::from_slice(
        &std::fs::read(&args.profile).with_context(|| args.profile.display().to_string())?,
    )?;
    let config = CrowdConfig {
        base_url: args.url.trim_end_matches('/').to_owned(),
        slug: args.slug.clone(),
        token: args.mix.token.clone(),
        visitors: args.visitors,
        pattern: args.pattern,
        tablet_share: args.mix.tablet_share,
        researcher_share: args.mix.researcher_share,
        tablet_factor: args.mix.tablet_factor,
        request_timeout: Duration::from_secs(args.mix.request_timeout_s),
        stay: Duration::from_secs_f64(args.mix.stay_s.max(0.0)),
        sigterm: args
            .sigterm_pid
            .map(|p| (p, Duration::from_secs_f64(args.sigterm_after_s))),
        sequential: false,
    };
    let outcome = sim::run_crowd(config, Arc::new(profile)).await?;
    let sum = report::summarize(&outcome, &Baselines::default());

    // Timeline: answers by status per bucket of request start time.
    let width = args.timeline_ms.max(1) * 1000;
    let mut timeline: std::collections::BTreeMap<u64, std::collections::BTreeMap<String, usize>> =
        Default::default();
    for r in &outcome.requests {
        let key = if r.status == 0 {
            "no answer".to_string()
        } else {
            r.status.to_string()
        };
        *timeline
            .entry(r.start_us / width)
            .or_default()
            .entry(key)
            .or_insert(0) += 1;
    }
    println!("| from s | answers by status |\n|---:|---|");
    for (b, counts) in &timeline {
        let c: Vec<String> = counts.iter().map(|(k, v)| format!("{k}: {v}")).collect();
        println!("| {:.1} | {} |", (*b * width) as f64 / 1e6, c.join(", "));
    }
    println!(
        "\n{} visitors ({} completed, {} failed, {} refused at admission), {} requests, p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms, {:.1} MB, non-2xx {:?}, max load pressure {}",
        sum.visitors, sum.completed, sum.failed, sum.admission_refused, sum.requests, sum.p50_ms, sum.p99_ms, sum.max_ms,
        sum.bytes as f64 / 1e6, sum.errors, sum.pressure_max
    );

    let mut violations = Vec::new();
    let allow: Vec<u16> = args
        .allow
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let allowed = |status: u16| matches!(status, 200 | 304) || allow.contains(&status);
    for (status, count) in &sum.errors {
        let ok = status.parse::<u16>().is_ok_and(allowed);
        // Around a SIGTERM, requests after the listener closed find no server.
        let after_sigterm = args.sigterm_pid.is_some() && status == "no answer";
        if !ok && !after_sigterm {
            violations.push(format!("{count} answers {status}"));
        }
    }
    if sum.missing_retry_after > 0 {
        violations.push(format!(
            "{} 429/503 answers without Retry-After",
            sum.missing_retry_after
        ));
    }
    for required in &args.require {
        if !outcome.requests.iter().any(|r| r.status == *required) {
            violations.push(format!("no {required} answer was seen"));
        }
    }
    if let Some(after) = args.clean_after_s {
        let from = (after * 1e6) as u64;
        let late: Vec<_> = outcome
            .requests
            .iter()
            .filter(|r| r.start_us >= from && !matches!(r.status, 200 | 304))
            .collect();
        println!(
            "requests started after {after} s: {} not 200/304",
            late.len()
        );
        if !late.is_empty() {
            violations.push(format!(
                "{} requests started after {after} s failed (first: status {})",
                late.len(),
                late[0].status
            ));
        }
    }
    if let Some(at) = outcome.sigterm_at {
        // In the handler for sure: sent 200 ms before SIGTERM, not answered by then.
        let sig = at.as_micros() as u64;
        let in_flight: Vec<_> = outcome
            .requests
            .iter()
            .filter(|r| r.start_us + 200_000 <= sig && r.start_us + r.dur_us > sig)
            .collect();
        // Finished: an HTTP answer, 200 or a documented refusal, not a reset.
        let bad = in_flight
            .iter()
            .filter(|r| !(matches!(r.status, 200 | 304) || allow.contains(&r.status)))
            .count();
        let ok = in_flight.iter().filter(|r| r.status == 200).count();
        let refused = outcome
            .requests
            .iter()
            .filter(|r| r.start_us > sig && r.status == 0)
            .count();
        println!(
            "SIGTERM at {:.2} s: {} requests in flight (sent ≥ 200 ms before): {} completed with 200, {} with 429/503, {} cut off; {} later requests found the server gone",
            at.as_secs_f64(),
            in_flight.len(),
            ok,
            in_flight.len() - ok - bad,
            bad,
            refused
        );
        if in_flight.is_empty() {
            violations.push("no request was in flight at SIGTERM: nothing was shown".into());
        }
        if bad > 0 {
            violations.push(format!(
                "{bad} in-flight requests did not complete at shutdown"
            ));
        }
    }
    if let Some(path) = &args.json {
        let v = serde_json::json!({ "summary": sum, "timeline": timeline, "requests": outcome.requests });
        std::fs::write(path, serde_json::to_vec_pretty(&v)?)?;
    }
    if !violations.is_empty() {
        for v in &violations {
            eprintln!("FAIL: {v}");
        }
        bail!("{} check(s) failed", violations.len());
    }
    println!("crowd checks passed");
    Ok(())
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
