//! `vitrine-load crowd`: one crowd against a running server, a timeline of
//! its answers, and the checks the fault scripts ask for.

use crate::report::{self, Baselines, Summary};
use crate::sim::{self, CrowdConfig, CrowdOutcome, DecodeProfile};
use crate::{fail_on, CrowdArgs};
use anyhow::{Context, Result};
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Duration;

/// Answers by status, per bucket of request start time.
type Timeline = BTreeMap<u64, BTreeMap<String, usize>>;

pub async fn crowd(args: CrowdArgs) -> Result<()> {
    let profile: DecodeProfile = serde_json::from_slice(
        &std::fs::read(&args.profile).with_context(|| args.profile.display().to_string())?,
    )?;
    let outcome = sim::run_crowd(crowd_config(&args), Arc::new(profile)).await?;
    let sum = report::summarize(&outcome, &Baselines::default());
    let timeline = timeline(&outcome, args.timeline_ms);
    print_timeline(&timeline, args.timeline_ms);
    println!(
        "\n{} visitors ({} completed, {} failed, {} refused at admission), {} requests, p50 {:.1} ms, p99 {:.1} ms, max {:.1} ms, {:.1} MB, non-2xx {:?}, max load pressure {}",
        sum.visitors, sum.completed, sum.failed, sum.admission_refused, sum.requests, sum.p50_ms, sum.p99_ms, sum.max_ms,
        sum.bytes as f64 / 1e6, sum.errors, sum.pressure_max
    );

    let mut versions: BTreeMap<i64, usize> = BTreeMap::new();
    for v in &outcome.visitors {
        if let Some(c) = v.compression_id {
            *versions.entry(c).or_insert(0) += 1;
        }
    }
    let mixed = outcome.visitors.iter().filter(|v| v.mixed_versions).count();
    let newer = outcome
        .visitors
        .iter()
        .filter(|v| v.newer_version_seen)
        .count();
    println!(
        "versions (compression id: visitors who started on it) {versions:?}; {newer} saw a newer one on a re-read; {mixed} saw a mix of two"
    );
    let allow: Vec<u16> = args
        .allow
        .split(',')
        .filter_map(|s| s.trim().parse().ok())
        .collect();
    let mut violations = status_violations(&args, &sum, &allow);
    if mixed > 0 {
        violations.push(format!("{mixed} visitors got batches of two versions"));
    }
    if args.require_versions > versions.len() {
        violations.push(format!(
            "visitors started on {} version(s), {} required",
            versions.len(),
            args.require_versions
        ));
    }
    for required in &args.require {
        if !outcome.requests.iter().any(|r| r.status == *required) {
            violations.push(format!("no {required} answer was seen"));
        }
    }
    if let Some(after) = args.clean_after_s {
        violations.extend(clean_after(&outcome, after));
    }
    if let Some(at) = outcome.sigterm_at {
        violations.extend(shutdown(&outcome, at, &allow));
    }
    if let Some(path) = &args.json {
        let v = serde_json::json!({ "summary": sum, "timeline": timeline, "requests": outcome.requests });
        std::fs::write(path, serde_json::to_vec_pretty(&v)?)?;
    }
    fail_on(&violations)?;
    println!("crowd checks passed");
    Ok(())
}

fn crowd_config(args: &CrowdArgs) -> CrowdConfig {
    CrowdConfig {
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
        close_up: args.mix.close_up,
    }
}

fn timeline(outcome: &CrowdOutcome, bucket_ms: u64) -> Timeline {
    let width = bucket_ms.max(1) * 1000;
    let mut timeline = Timeline::default();
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
    timeline
}

fn print_timeline(timeline: &Timeline, bucket_ms: u64) {
    let width = bucket_ms.max(1) * 1000;
    println!("| from s | answers by status |\n|---:|---|");
    for (b, counts) in timeline {
        let c: Vec<String> = counts.iter().map(|(k, v)| format!("{k}: {v}")).collect();
        println!("| {:.1} | {} |", (*b * width) as f64 / 1e6, c.join(", "));
    }
}

/// Answers other than 200/304 and `--allow`, and 429/503 without `Retry-After`.
fn status_violations(args: &CrowdArgs, sum: &Summary, allow: &[u16]) -> Vec<String> {
    let mut violations = Vec::new();
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
    violations
}

/// `--clean-after-s`: every request started after `after` s got 200/304.
fn clean_after(outcome: &CrowdOutcome, after: f64) -> Option<String> {
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
    (!late.is_empty()).then(|| {
        format!(
            "{} requests started after {after} s failed (first: status {})",
            late.len(),
            late[0].status
        )
    })
}

/// `--sigterm-pid`: the requests in flight at SIGTERM completed.
fn shutdown(outcome: &CrowdOutcome, at: Duration, allow: &[u16]) -> Vec<String> {
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
    let mut violations = Vec::new();
    if in_flight.is_empty() {
        violations.push("no request was in flight at SIGTERM: nothing was shown".into());
    }
    if bad > 0 {
        violations.push(format!(
            "{bad} in-flight requests did not complete at shutdown"
        ));
    }
    violations
}
