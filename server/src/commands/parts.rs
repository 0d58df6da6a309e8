//! `vitrine inspect --parts`: a charted stream as a viewer that refines
//! where the visitor looks sees it (issue 41): what every visitor fetches
//! first (the header, base, global batches and the charts' labels), then
//! per chart its parts' bytes and errors, and a close-up's cost: the prefix
//! plus one chart's parts to the final level, against the whole stream.

use std::fmt::Write as _;
use vitrine_codec::{part_table, Limits, NestedSummary, PartRecord, PartedLayout, StreamIndex};

/// The report, or `None` for a plain stream (no parts).
pub fn report(stream: &[u8]) -> anyhow::Result<Option<String>> {
    if let Some(summary) = NestedSummary::of(stream)? {
        return Ok(Some(nested_report(&summary, stream.len())));
    }
    let table = part_table(stream, Limits::default())?;
    let Some(first) = table.first() else {
        return Ok(None);
    };
    let index = StreamIndex::parse(stream)?;
    let step = f64::from(index.header.quantization.step);
    let charts = table.iter().map(|p| p.chart + 1).max().unwrap_or(0);
    let first_level = first.level;
    // Everything before the first part: header, base, global batches and
    // the first parted batch's head (chart count and labels).
    let chunk = index.batches[first_level - 1].clone();
    let layout = PartedLayout::parse(&stream[chunk.clone()])?
        .ok_or_else(|| anyhow::anyhow!("batch {first_level} has parts but no layout"))?;
    let prefix = chunk.start + layout.head.end;
    let total = stream.len();
    let mut out = String::new();
    let pct = |b: usize| 100.0 * b as f64 / total as f64;
    let _ = writeln!(
        out,
        "{charts} charts from level {first_level}; every visitor fetches {prefix} bytes first ({:.1} % of {total})",
        pct(prefix)
    );
    let _ = writeln!(
        out,
        "| chart | parts | inserted | bytes | close-up bytes | of the stream | error first → last part |"
    );
    let _ = writeln!(out, "|---:|---:|---:|---:|---:|---:|---:|");
    let mut closeups = Vec::new();
    for chart in 0..charts {
        let parts: Vec<&PartRecord> = table.iter().filter(|p| p.chart == chart).collect();
        let bytes: usize = parts.iter().map(|p| p.bytes.len()).sum();
        let inserted: usize = parts.iter().map(|p| p.inserted).sum();
        let errors: Vec<f64> = parts
            .iter()
            .filter(|p| p.inserted > 0)
            .map(|p| f64::from(p.error_steps) * step)
            .collect();
        let closeup = prefix + bytes;
        closeups.push(closeup);
        let _ = writeln!(
            out,
            "| {chart} | {} | {inserted} | {bytes} | {closeup} | {:.1} % | {:.4} → {:.4} |",
            parts.len(),
            pct(closeup),
            errors.first().copied().unwrap_or(0.0),
            errors.last().copied().unwrap_or(0.0),
        );
    }
    closeups.sort_unstable();
    let median = closeups[closeups.len() / 2];
    let _ = writeln!(
        out,
        "close-up of one chart to the final level: median {median} bytes ({:.1} %), largest {} ({:.1} %)",
        pct(median),
        closeups[closeups.len() - 1],
        pct(closeups[closeups.len() - 1])
    );
    Ok(Some(out))
}

/// A nested stream's (format 6) report, from the parts' lengths alone (the
/// errors per part are not measured for it yet): the prefix, each phase's
/// charts, and a close-up of one leaf (its parts, its ancestors' and their
/// split entries).
fn nested_report(summary: &NestedSummary, total: usize) -> String {
    let pct = |b: usize| 100.0 * b as f64 / total as f64;
    let mut out = String::new();
    let charts: Vec<String> = summary
        .part_bytes
        .iter()
        .map(|p| p.len().to_string())
        .collect();
    let _ = writeln!(
        out,
        "nested charts {} from level {}; every visitor fetches {} bytes first ({:.1} % of {total})",
        charts.join(" → "),
        summary.first_level,
        summary.prefix,
        pct(summary.prefix)
    );
    let _ = writeln!(
        out,
        "| phase | charts | part bytes, smallest chart | largest chart |"
    );
    let _ = writeln!(out, "|---:|---:|---:|---:|");
    for (phase, bytes) in summary.part_bytes.iter().enumerate() {
        let _ = writeln!(
            out,
            "| {phase} | {} | {} | {} |",
            bytes.len(),
            bytes.iter().min().unwrap_or(&0),
            bytes.iter().max().unwrap_or(&0)
        );
    }
    let mut closeups = summary.closeups.clone();
    closeups.sort_unstable();
    if let (Some(&median), Some(&largest)) = (closeups.get(closeups.len() / 2), closeups.last()) {
        let _ = writeln!(
            out,
            "close-up of one leaf to the final level (its parts, its ancestors' and their split entries): median {median} bytes ({:.1} %), largest {largest} ({:.1} %)",
            pct(median),
            pct(largest)
        );
    }
    out
}
