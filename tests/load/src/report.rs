//! Per-scenario numbers, the Markdown table and the SVG plot.

use crate::sim::{Audience, CrowdOutcome, Device, Req, VisitorResult};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt::Write as _;

/// When a lone visitor of each (device, audience) had each level on screen.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Baselines(pub Vec<(Device, Audience, Vec<f64>)>);

impl Baselines {
    pub fn from_visitors(visitors: &[VisitorResult]) -> Baselines {
        Baselines(
            visitors
                .iter()
                .filter_map(|v| Some((v.device?, v.audience?, v.level_ms.clone())))
                .collect(),
        )
    }

    /// A lone visitor's time to `level`, for this kind of visitor.
    pub fn time(&self, device: Device, audience: Audience, level: u32) -> Option<f64> {
        self.0
            .iter()
            .find(|(d, a, _)| *d == device && *a == audience)
            .and_then(|(_, _, t)| t.get(level as usize).copied())
    }
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Summary {
    pub caps: String,
    pub visitors: usize,
    pub pattern: String,
    pub run: usize,
    pub requests: usize,
    pub p50_ms: f64,
    pub p95_ms: f64,
    pub p99_ms: f64,
    /// p99 of the time to the response head (the service's own delay).
    #[serde(default)]
    pub head_p99_ms: f64,
    /// p99 to the last byte, by kind of request (manifest, base, batch...).
    #[serde(default)]
    pub p99_ms_by_kind: BTreeMap<String, f64>,
    pub max_ms: f64,
    /// Time to the level where refinement first stopped (completed visitors).
    pub recon_median_s: f64,
    pub recon_p95_s: f64,
    /// Each visitor's time over a lone visitor's time to the same level.
    pub ratio_median: f64,
    pub ratio_p95: f64,
    pub ratio_max: f64,
    /// The same, counting the wait for admission (503 `busy` and its
    /// `Retry-After`) as part of the visitor's time.
    #[serde(default)]
    pub ratio_wait_median: f64,
    #[serde(default)]
    pub ratio_wait_p95: f64,
    /// Visitors refused at least once at admission, and their wait.
    #[serde(default)]
    pub admission_refused: usize,
    #[serde(default)]
    pub admission_wait_median_s: f64,
    #[serde(default)]
    pub admission_wait_max_s: f64,
    /// p99 over the requests answered 200/304 only (the p99 above covers
    /// every request, refusals included).
    #[serde(default)]
    pub p99_ok_ms: f64,
    pub completed: usize,
    pub failed: usize,
    /// Public desktop visitors: median level reached.
    pub public_desktop_level: f64,
    pub load_capped: usize,
    /// Level at which a load cap first held visitors → how many.
    pub load_capped_levels: BTreeMap<u32, usize>,
    /// Visitors who refined further once a load cap lifted.
    #[serde(default)]
    pub resumed: usize,
    /// Visitors still held by a load cap when they left.
    #[serde(default)]
    pub held_at_end: usize,
    /// Manifest reads after a load cap's `Retry-After`.
    #[serde(default)]
    pub rechecks: usize,
    pub bytes: u64,
    /// Status (or "no answer") → count, for everything but 200 and 304.
    pub errors: BTreeMap<String, usize>,
    /// 429/503 answers without `Retry-After`.
    pub missing_retry_after: usize,
    pub server_cpu_s: f64,
    /// Of one core: 200 % is both cores.
    pub server_cpu_pct: f64,
    pub server_peak_rss_mib: f64,
    pub harness_cpu_s: f64,
    pub wall_s: f64,
    pub pressure_max: u8,
    /// Each run's p99, p95 × lone visitor and load-capped visitors.
    #[serde(default)]
    pub per_run: String,
}

pub fn percentile(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    let rank = ((p / 100.0) * sorted.len() as f64).ceil() as usize;
    sorted[rank.clamp(1, sorted.len()) - 1]
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

pub fn status_key(r: &Req) -> Option<String> {
    match r.status {
        200 | 304 => None,
        0 => Some("no answer".into()),
        s => Some(s.to_string()),
    }
}

pub fn summarize(outcome: &CrowdOutcome, baselines: &Baselines) -> Summary {
    let mut sum = Summary {
        wall_s: outcome.wall.as_secs_f64(),
        pressure_max: outcome.pressure_max,
        ..requests_summary(&outcome.requests)
    };
    add_reconstruction(&mut sum, &outcome.visitors, baselines);
    add_visitors(&mut sum, &outcome.visitors);
    sum
}

/// Latencies, answers and bytes of every request.
fn requests_summary(requests: &[Req]) -> Summary {
    let ms = |r: &Req| r.dur_us as f64 / 1e3;
    let lat = sorted(requests.iter().map(ms).collect());
    let heads = sorted(
        requests
            .iter()
            .filter(|r| r.status != 0)
            .map(|r| r.head_us as f64 / 1e3)
            .collect(),
    );
    let ok = sorted(
        requests
            .iter()
            .filter(|r| matches!(r.status, 200 | 304))
            .map(ms)
            .collect(),
    );
    let mut errors = BTreeMap::new();
    let mut missing_retry_after = 0;
    let mut by_kind: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for r in requests {
        if let Some(k) = status_key(r) {
            *errors.entry(k).or_insert(0) += 1;
        }
        if matches!(r.status, 429 | 503) && !r.retry_after {
            missing_retry_after += 1;
        }
        by_kind
            .entry(format!("{:?}", r.kind).to_lowercase())
            .or_default()
            .push(ms(r));
    }
    Summary {
        requests: requests.len(),
        p50_ms: percentile(&lat, 50.0),
        p95_ms: percentile(&lat, 95.0),
        p99_ms: percentile(&lat, 99.0),
        head_p99_ms: percentile(&heads, 99.0),
        p99_ms_by_kind: by_kind
            .into_iter()
            .map(|(k, v)| (k, percentile(&sorted(v), 99.0)))
            .collect(),
        max_ms: lat.last().copied().unwrap_or(f64::NAN),
        p99_ok_ms: percentile(&ok, 99.0),
        bytes: requests.iter().map(|r| r.bytes).sum(),
        errors,
        missing_retry_after,
        ..Summary::default()
    }
}

/// Reconstruction times of the visitors who completed, alone and as a
/// multiple of a lone visitor's time to the same level.
fn add_reconstruction(sum: &mut Summary, visitors: &[VisitorResult], baselines: &Baselines) {
    let done: Vec<&VisitorResult> = visitors.iter().filter(|v| v.complete()).collect();
    // Up to where refinement first stopped: a visitor resumed after a load
    // cap lifted has waited out `Retry-After`, which is the cap's price, not
    // the crowd's (counted apart below).
    let recon = sorted(
        done.iter()
            .filter_map(|v| Some(v.first_stop()?.1))
            .collect(),
    );
    // × lone visitor, from admission and counting the wait for it.
    let (ratios, ratios_wait): (Vec<f64>, Vec<f64>) = done
        .iter()
        .filter_map(|v| {
            let (level, time) = v.first_stop()?;
            let alone = baselines.time(v.device?, v.audience?, level)?;
            Some((time / alone, (time + v.admission_wait_ms) / alone))
        })
        .unzip();
    let (ratios, ratios_wait) = (sorted(ratios), sorted(ratios_wait));
    sum.recon_median_s = percentile(&recon, 50.0) / 1e3;
    sum.recon_p95_s = percentile(&recon, 95.0) / 1e3;
    sum.ratio_median = percentile(&ratios, 50.0);
    sum.ratio_p95 = percentile(&ratios, 95.0);
    sum.ratio_max = ratios.last().copied().unwrap_or(f64::NAN);
    sum.ratio_wait_median = percentile(&ratios_wait, 50.0);
    sum.ratio_wait_p95 = percentile(&ratios_wait, 95.0);
    sum.completed = done.len();
    sum.failed = visitors.len() - done.len();
}

/// Admission waits, levels reached and load caps, over every visitor.
fn add_visitors(sum: &mut Summary, visitors: &[VisitorResult]) {
    let refused: Vec<&VisitorResult> = visitors.iter().filter(|v| v.refusals > 0).collect();
    let waits = sorted(refused.iter().map(|v| v.admission_wait_ms / 1e3).collect());
    let levels = sorted(
        visitors
            .iter()
            .filter(|v| v.device == Some(Device::Desktop) && v.audience == Some(Audience::Public))
            .filter_map(|v| v.reached().map(f64::from))
            .collect(),
    );
    let mut load_capped_levels = BTreeMap::new();
    for v in visitors.iter().filter(|v| v.load_capped()) {
        if let Some((l, _)) = v.first_stop() {
            *load_capped_levels.entry(l).or_insert(0) += 1;
        }
    }
    sum.admission_refused = refused.len();
    sum.admission_wait_median_s = if waits.is_empty() {
        0.0
    } else {
        percentile(&waits, 50.0)
    };
    sum.admission_wait_max_s = waits.last().copied().unwrap_or(0.0);
    sum.public_desktop_level = percentile(&levels, 50.0);
    sum.load_capped = visitors.iter().filter(|v| v.load_capped()).count();
    sum.load_capped_levels = load_capped_levels;
    sum.resumed = visitors.iter().filter(|v| v.resumed).count();
    sum.held_at_end = visitors.iter().filter(|v| v.held_at_end).count();
    sum.rechecks = visitors.iter().map(|v| v.rechecks as usize).sum();
    sum.visitors = visitors.len();
}

/// Several runs of one scenario as one row: the run with the median p99,
/// whole (so that its columns agree), and every run's key numbers.
pub fn median_of(runs: &[Summary]) -> Summary {
    let mut order: Vec<&Summary> = runs.iter().collect();
    order.sort_by(|a, b| a.p99_ms.total_cmp(&b.p99_ms));
    let mut m = order[order.len() / 2].clone();
    m.per_run = runs
        .iter()
        .map(|r| {
            format!(
                "{:.0} ms, ×{:.2}, {} capped, {} refused",
                r.p99_ms, r.ratio_p95, r.load_capped, r.admission_refused
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    m
}

fn map(m: &BTreeMap<impl std::fmt::Display, usize>) -> String {
    if m.is_empty() {
        return "–".into();
    }
    m.iter()
        .map(|(k, v)| format!("{k}: {v}"))
        .collect::<Vec<_>>()
        .join(", ")
}

pub fn markdown(rows: &[Summary]) -> String {
    let mut s = String::new();
    s.push_str("| caps | visitors | arrivals | requests | p50 ms | p95 ms | p99 ms | p99 to response head ms | p99 of 200/304 ms | reconstruction median / p95 s | × lone visitor, median / p95 | × lone counting the admission wait, median / p95 | refused at admission (max wait s) | public desktop level (median) | load-capped visitors (first held at level: n); resumed after a re-check / still held when leaving (re-checks) | failed visitors | non-2xx answers | bytes served | server CPU s (% of a core) | server peak RSS MiB | harness CPU s | max pressure | every run: p99, p95 × lone, load-capped |\n");
    s.push_str(
        "|---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.2} / {:.2} | {:.2} / {:.2} | {:.2} / {:.2} | {} ({:.1}) | {} | {} ({}); {} / {} ({}) | {} | {} | {:.1} MB | {:.1} ({:.0} %) | {:.0} | {:.1} | {} | {} |",
            r.caps,
            r.visitors,
            r.pattern,
            r.requests,
            r.p50_ms,
            r.p95_ms,
            r.p99_ms,
            r.head_p99_ms,
            r.p99_ok_ms,
            r.recon_median_s,
            r.recon_p95_s,
            r.ratio_median,
            r.ratio_p95,
            r.ratio_wait_median,
            r.ratio_wait_p95,
            r.admission_refused,
            r.admission_wait_max_s,
            r.public_desktop_level,
            r.load_capped,
            map(&r.load_capped_levels),
            r.resumed,
            r.held_at_end,
            r.rechecks,
            r.failed,
            map(&r.errors),
            r.bytes as f64 / 1e6,
            r.server_cpu_s,
            r.server_cpu_pct,
            r.server_peak_rss_mib,
            r.harness_cpu_s,
            r.pressure_max,
            r.per_run,
        );
    }
    s
}

/// A panel: label, left edge, (value, whisker top) of a row, goal line.
type Panel<'a> = (
    &'a str,
    f64,
    &'a dyn Fn(&Summary) -> (f64, f64),
    Option<(f64, &'a str)>,
);

/// Two panels: reconstruction time (median, p95 whisker) and request p99
/// against visitors (log scale), caps off and on.
pub fn svg(rows: &[Summary], lone_s: Option<f64>, title: &str) -> String {
    let (w, h) = (960.0, 420.0);
    let mut s = String::new();
    let _ = writeln!(
        s,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" viewBox="0 0 {w} {h}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(s, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(
        s,
        r#"<text x="{}" y="20" text-anchor="middle" font-size="14">{}</text>"#,
        w / 2.0,
        escape(title)
    );
    let panels: [Panel; 2] = [
        (
            "full reconstruction per visitor, s (median, whisker to p95)",
            30.0,
            &|r: &Summary| (r.recon_median_s, r.recon_p95_s),
            lone_s.map(|l| (l * 1.2, "1.2 × lone visitor")),
        ),
        (
            "request latency p99, ms",
            510.0,
            &|r: &Summary| (r.p99_ms, r.p99_ms),
            Some((100.0, "goal 100 ms")),
        ),
    ];
    for (label, x0, value, goal) in panels {
        let frame = Frame::new(rows, x0, value, goal);
        frame.axes(&mut s, label, rows);
        if let Some((g, text)) = goal {
            frame.goal(&mut s, g, text);
        }
        for caps in ["off", "on"] {
            let mut pts: Vec<&Summary> = rows.iter().filter(|r| r.caps == caps).collect();
            pts.sort_by_key(|r| r.visitors);
            if !pts.is_empty() {
                frame.series(&mut s, &pts, value, colour(caps));
            }
        }
    }
    for (i, caps) in ["off", "on"].iter().enumerate() {
        let lx = 100.0 + 200.0 * i as f64;
        let _ = writeln!(
            s,
            r#"<line x1="{lx}" x2="{}" y1="{}" y2="{}" stroke="{}" stroke-width="2"/><text x="{}" y="{}">load caps {caps}</text>"#,
            lx + 24.0,
            h - 14.0,
            h - 14.0,
            colour(caps),
            lx + 30.0,
            h - 10.0
        );
    }
    s.push_str("</svg>\n");
    s
}

fn colour(caps: &str) -> &'static str {
    if caps == "on" {
        "#1f77b4"
    } else {
        "#d62728"
    }
}

/// One panel's plot area: visitors on a log scale across, the value up.
struct Frame {
    px: f64,
    py: f64,
    pw: f64,
    ph: f64,
    ymax: f64,
    max_v: f64,
}

impl Frame {
    fn new(
        rows: &[Summary],
        x0: f64,
        value: &dyn Fn(&Summary) -> (f64, f64),
        goal: Option<(f64, &str)>,
    ) -> Frame {
        let ymax = rows
            .iter()
            .map(|r| value(r).1)
            .chain(goal.map(|g| g.0))
            .filter(|v| v.is_finite())
            .fold(0.0_f64, f64::max)
            * 1.1;
        Frame {
            px: x0 + 50.0,
            py: 50.0,
            pw: 380.0,
            ph: 300.0,
            ymax: if ymax > 0.0 { nice(ymax) } else { 1.0 },
            max_v: rows.iter().map(|r| r.visitors).max().unwrap_or(1).max(2) as f64,
        }
    }

    fn x(&self, v: f64) -> f64 {
        self.px + self.pw * (v.max(1.0).ln() / self.max_v.ln())
    }

    fn y(&self, v: f64) -> f64 {
        self.py + self.ph - self.ph * (v / self.ymax).clamp(0.0, 1.0)
    }

    /// The frame, its title, the value grid and the visitor ticks.
    fn axes(&self, s: &mut String, label: &str, rows: &[Summary]) {
        let (px, py, pw, ph) = (self.px, self.py, self.pw, self.ph);
        let _ = writeln!(
            s,
            r##"<rect x="{px}" y="{py}" width="{pw}" height="{ph}" fill="none" stroke="#888"/>"##
        );
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">{}</text>"#,
            px + pw / 2.0,
            py - 8.0,
            escape(label)
        );
        for i in 0..=4 {
            let v = self.ymax * f64::from(i) / 4.0;
            let _ = writeln!(
                s,
                r##"<line x1="{px}" x2="{}" y1="{y}" y2="{y}" stroke="#eee"/><text x="{}" y="{}" text-anchor="end">{}</text>"##,
                px + pw,
                px - 4.0,
                self.y(v) + 4.0,
                short(v),
                y = self.y(v)
            );
        }
        let mut ticks: Vec<usize> = rows.iter().map(|r| r.visitors).collect();
        ticks.sort_unstable();
        ticks.dedup();
        for t in ticks {
            let _ = writeln!(
                s,
                r#"<text x="{}" y="{}" text-anchor="middle">{t}</text>"#,
                self.x(t as f64),
                py + ph + 16.0
            );
        }
        let _ = writeln!(
            s,
            r#"<text x="{}" y="{}" text-anchor="middle">simultaneous visitors (log scale)</text>"#,
            px + pw / 2.0,
            py + ph + 34.0
        );
    }

    fn goal(&self, s: &mut String, g: f64, text: &str) {
        let (px, pw) = (self.px, self.pw);
        let _ = writeln!(
            s,
            r##"<line x1="{px}" x2="{}" y1="{y}" y2="{y}" stroke="#2ca02c" stroke-dasharray="6 4"/><text x="{}" y="{}" fill="#2ca02c" text-anchor="end">{}</text>"##,
            px + pw,
            px + pw - 4.0,
            self.y(g) - 4.0,
            escape(text),
            y = self.y(g)
        );
    }

    /// One caps setting's line, points and whiskers.
    fn series(
        &self,
        s: &mut String,
        pts: &[&Summary],
        value: &dyn Fn(&Summary) -> (f64, f64),
        c: &str,
    ) {
        let path: Vec<String> = pts
            .iter()
            .filter(|r| value(r).0.is_finite())
            .map(|r| format!("{:.1},{:.1}", self.x(r.visitors as f64), self.y(value(r).0)))
            .collect();
        let _ = writeln!(
            s,
            r#"<polyline points="{}" fill="none" stroke="{c}" stroke-width="2"/>"#,
            path.join(" ")
        );
        for r in pts {
            let (m, hi) = value(r);
            if !m.is_finite() {
                continue;
            }
            let cx = self.x(r.visitors as f64);
            if hi.is_finite() && hi > m {
                let _ = writeln!(
                    s,
                    r#"<line x1="{cx}" x2="{cx}" y1="{}" y2="{}" stroke="{c}"/>"#,
                    self.y(m),
                    self.y(hi)
                );
            }
            let _ = writeln!(
                s,
                r#"<circle cx="{cx}" cy="{}" r="3.5" fill="{c}"/>"#,
                self.y(m)
            );
        }
    }
}

fn nice(v: f64) -> f64 {
    let p = 10f64.powf(v.log10().floor());
    for m in [1.0, 2.0, 2.5, 5.0, 10.0] {
        if m * p >= v {
            return m * p;
        }
    }
    10.0 * p
}

fn short(v: f64) -> String {
    if v >= 100.0 || v == 0.0 {
        format!("{v:.0}")
    } else if v >= 10.0 {
        format!("{v:.1}")
    } else {
        format!("{v:.2}")
    }
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles() {
        let v: Vec<f64> = (1..=100).map(f64::from).collect();
        assert_eq!(percentile(&v, 50.0), 50.0);
        assert_eq!(percentile(&v, 99.0), 99.0);
        assert_eq!(percentile(&v, 100.0), 100.0);
        assert_eq!(percentile(&[7.0], 99.0), 7.0);
    }

    #[test]
    fn svg_is_well_formed_enough() {
        let rows = vec![
            Summary {
                caps: "off".into(),
                visitors: 1,
                recon_median_s: 3.0,
                recon_p95_s: 3.0,
                p99_ms: 5.0,
                ..Summary::default()
            },
            Summary {
                caps: "on".into(),
                visitors: 100,
                recon_median_s: 3.2,
                recon_p95_s: 3.5,
                p99_ms: 50.0,
                ..Summary::default()
            },
        ];
        let svg = svg(&rows, Some(3.0), "t <x>");
        assert!(svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"));
        assert!(svg.contains("t &lt;x&gt;"));
        assert_eq!(svg.matches("<polyline").count(), 4);
    }
}
