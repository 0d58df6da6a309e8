//! `vitrine-load run`: load scenarios, each crowd on a `vitrine serve`
//! started afresh, caps off and on; writes results.json, report.md and an
//! SVG plot, and fails on the checks asked for.

use crate::report::{self, Baselines, Summary};
use crate::sim::{self, CrowdConfig, DecodeProfile};
use crate::{fail_on, lone_seconds, machine, plot_title, server, Results, RunArgs};
use anyhow::{bail, Result};
use std::sync::Arc;
use std::time::Duration;

pub async fn run(args: RunArgs) -> Result<()> {
    std::fs::create_dir_all(&args.out)?;
    let command = redacted_command();
    let mut machine_line = format!("before: {}", machine());
    let scenarios = Scenarios {
        profile: Arc::new(decode_profile(&args).await?),
        args: &args,
    };
    let mut tally = Tally::default();
    for caps in &args.caps {
        let caps_on = match caps.as_str() {
            "on" => true,
            "off" => false,
            other => bail!("--caps takes off and on, not {other:?}"),
        };
        scenarios.with_caps(caps, caps_on, &mut tally).await?;
    }
    machine_line.push_str(&format!("; after: {}", machine()));
    let results = Results {
        machine: machine_line,
        command,
        profile: (*scenarios.profile).clone(),
        baselines: tally.baselines,
        runs: tally.runs,
        medians: tally.medians,
    };
    let md = write_reports(&args, &results)?;
    println!("{md}");
    fail_on(&tally.violations)?;
    eprintln!("load checks passed");
    Ok(())
}

/// The command line, for the report; the token is a secret of the test
/// database, so not in it.
fn redacted_command() -> String {
    let mut command = Vec::new();
    let mut secret = false;
    for a in std::env::args() {
        command.push(if secret { "…".to_string() } else { a.clone() });
        secret = a == "--token";
    }
    command.join(" ")
}

/// The decode profile from `--profile`, else measured on a server of its own.
async fn decode_profile(args: &RunArgs) -> Result<DecodeProfile> {
    let profile = match &args.profile {
        Some(p) => serde_json::from_slice(&std::fs::read(p)?)?,
        None => {
            let s = start(args, true, "profile".into()).await?;
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
    Ok(profile)
}

/// A fresh `vitrine serve`, logging to `serve-{tag}.log`.
async fn start(args: &RunArgs, caps_on: bool, tag: String) -> Result<server::Server> {
    let log = args.out.join(format!("serve-{tag}.log"));
    server::Server::start(
        &args.bin,
        &args.db,
        &args.listen,
        caps_on,
        &args.serve_args,
        log,
    )
    .await
}

/// Every run so far, the medians, the lone visitors' times, what failed.
#[derive(Default)]
struct Tally {
    runs: Vec<Summary>,
    medians: Vec<Summary>,
    baselines: Vec<(String, Baselines)>,
    violations: Vec<String>,
}

struct Scenarios<'a> {
    args: &'a RunArgs,
    profile: Arc<DecodeProfile>,
}

impl Scenarios<'_> {
    fn crowd_config(&self, url: &str, visitors: usize, sequential: bool) -> CrowdConfig {
        let (args, mix) = (self.args, &self.args.mix);
        CrowdConfig {
            base_url: url.to_owned(),
            slug: args.slug.clone(),
            token: mix.token.clone(),
            visitors,
            pattern: args.pattern,
            tablet_share: mix.tablet_share,
            researcher_share: mix.researcher_share,
            tablet_factor: mix.tablet_factor,
            request_timeout: Duration::from_secs(mix.request_timeout_s),
            stay: Duration::from_secs_f64(mix.stay_s.max(0.0)),
            sigterm: None,
            sequential,
            close_up: mix.close_up,
        }
    }

    /// Every crowd size, `--runs` times each, with load caps `caps`.
    async fn with_caps(&self, caps: &str, caps_on: bool, tally: &mut Tally) -> Result<()> {
        let base = self.lone_visitors(caps, caps_on).await?;
        for &n in &self.args.visitors {
            let mut runs = Vec::new();
            for run in 1..=self.args.runs {
                let sum = self.one_run(caps, caps_on, n, run, &base).await?;
                run_violations(caps, n, &sum, &mut tally.violations);
                runs.push(sum);
            }
            let m = report::median_of(&runs);
            if caps_on && self.args.check_visitors == Some(n) {
                median_violations(self.args, n, &m, &mut tally.violations);
            }
            tally.medians.push(m);
            tally.runs.extend(runs);
        }
        tally.baselines.push((caps.to_owned(), base));
        Ok(())
    }

    /// A lone visitor of each kind, one after another, on a fresh server.
    async fn lone_visitors(&self, caps: &str, caps_on: bool) -> Result<Baselines> {
        let s = start(self.args, caps_on, format!("caps-{caps}-alone")).await?;
        let config = self.crowd_config(&s.url, 1000, true);
        let alone = sim::run_crowd(config, Arc::clone(&self.profile)).await;
        s.stop().await?;
        let base = Baselines::from_visitors(&alone?.visitors);
        for (d, a, t) in &base.0 {
            eprintln!(
                "caps {caps}: lone {d:?}/{a:?} visitor: level {} in {:.2} s",
                t.len().saturating_sub(1),
                t.last().copied().unwrap_or(0.0) / 1e3
            );
        }
        Ok(base)
    }

    /// A crowd of `n` on a fresh server, with the server's and the
    /// harness's CPU time and the server's peak memory.
    async fn one_run(
        &self,
        caps: &str,
        caps_on: bool,
        n: usize,
        run: usize,
        base: &Baselines,
    ) -> Result<Summary> {
        let s = start(self.args, caps_on, format!("caps-{caps}-{n}-{run}")).await?;
        let cpu0 = s.cpu_seconds()?;
        let own0 = server::own_cpu_seconds();
        let config = self.crowd_config(&s.url, n, false);
        let outcome = sim::run_crowd(config, Arc::clone(&self.profile)).await?;
        let mut sum = report::summarize(&outcome, base);
        sum.server_cpu_s = s.cpu_seconds()? - cpu0;
        sum.server_cpu_pct = 100.0 * sum.server_cpu_s / outcome.wall.as_secs_f64();
        sum.server_peak_rss_mib = s.peak_rss_mib()?;
        sum.harness_cpu_s = server::own_cpu_seconds() - own0;
        s.stop().await?;
        sum.caps = caps.to_owned();
        sum.pattern = self.args.pattern.to_string();
        sum.run = run;
        log_run(n, &sum);
        Ok(sum)
    }
}

fn log_run(n: usize, sum: &Summary) {
    let (caps, run) = (&sum.caps, sum.run);
    eprintln!(
        "caps {caps}, {n} visitors, run {run}: p99 {:.1} ms (200/304 only {:.1}, to head {:.1}), reconstruction median {:.2} s (× {:.2} lone, p95 × {:.2}; with the admission wait × {:.2} / {:.2}), {} refused at admission (wait ≤ {:.1} s), {} load-capped ({} resumed after {} re-checks, {} still held when leaving), errors {:?}, server CPU {:.1} s, harness CPU {:.1} s, peak RSS {:.0} MiB, wall {:.1} s",
        sum.p99_ms, sum.p99_ok_ms, sum.head_p99_ms, sum.recon_median_s, sum.ratio_median, sum.ratio_p95,
        sum.ratio_wait_median, sum.ratio_wait_p95, sum.admission_refused, sum.admission_wait_max_s,
        sum.load_capped, sum.resumed, sum.rechecks, sum.held_at_end, sum.errors, sum.server_cpu_s, sum.harness_cpu_s, sum.server_peak_rss_mib, sum.wall_s
    );
}

/// Any answer but 429/503 is an error, and so is a 429/503 without
/// `Retry-After`.
fn run_violations(caps: &str, n: usize, sum: &Summary, violations: &mut Vec<String>) {
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
}

/// `--max-p99-ms`, `--check-resume` and `--max-ratio` on the median of the
/// caps-on runs of `--check-visitors`.
fn median_violations(args: &RunArgs, n: usize, m: &Summary, violations: &mut Vec<String>) {
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

/// results.json, report.md and the SVG when asked; returns the report.
fn write_reports(args: &RunArgs, results: &Results) -> Result<String> {
    std::fs::write(
        args.out.join("results.json"),
        serde_json::to_vec_pretty(results)?,
    )?;
    let table = report::markdown(&results.medians);
    let md = format!(
        "Machine: {}\n\nCommand: `{}`\n\n{}",
        results.machine, results.command, table
    );
    std::fs::write(args.out.join("report.md"), &md)?;
    if let Some(svg) = &args.svg {
        let lone = lone_seconds(results);
        std::fs::write(
            svg,
            report::svg(&results.medians, lone, &plot_title(results)),
        )?;
    }
    Ok(md)
}
