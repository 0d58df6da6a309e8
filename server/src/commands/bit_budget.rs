//! `vitrine-dev bits`: where a stream's bits go, layer by layer, coarsest
//! first (issue 47's table): vertices inserted, connectivity bits per
//! inserted vertex, geometry bits per inserted vertex split into the
//! tangential and normal components, and each layer's share of the stream.
//! Then what each trial predictor of `vitrine_codec::bit_budget` would
//! spend on the same residuals.

use anyhow::Context;
use clap::Args;
use std::fmt::Write as _;
use std::path::PathBuf;
use vitrine_codec::{bit_budget, PassBits, StreamIndex};

#[derive(Args, Debug)]
pub struct BitsArgs {
    /// A plain (format 4) stream, as `vitrine encode` writes without `--charts`.
    pub stream: PathBuf,
}

pub fn run(args: BitsArgs) -> anyhow::Result<()> {
    let bytes = std::fs::read(&args.stream)
        .with_context(|| format!("reading {}", args.stream.display()))?;
    let passes = bit_budget(&bytes)?;
    let index = StreamIndex::parse(&bytes)?;
    print!("{}", table(&passes, index.base.len(), bytes.len()));
    Ok(())
}

/// The markdown table: one row per batch, then the total and the trials.
pub fn table(passes: &[PassBits], base_bytes: usize, total_bytes: usize) -> String {
    let total_bits = total_bytes as f64 * 8.0;
    let mut out = String::new();
    let _ = writeln!(
        out,
        "| layer | inserted | conn b/v | tangential b/v | normal b/v | geometry b/v | share |"
    );
    let _ = writeln!(out, "|---:|---:|---:|---:|---:|---:|---:|");
    let _ = writeln!(
        out,
        "| base | | | | | | {:.1} % |",
        100.0 * base_bytes as f64 * 8.0 / total_bits
    );
    let batches = passes.iter().map(|p| p.batch).max().unwrap_or(0);
    for batch in 1..=batches {
        let layer: Vec<&PassBits> = passes.iter().filter(|p| p.batch == batch).collect();
        let n: u32 = layer.iter().map(|p| p.inserted).sum();
        if n == 0 {
            continue;
        }
        let per = |bits: f64| bits / n as f64;
        let conn: f64 = layer
            .iter()
            .map(|p| p.connectivity_bytes as f64 * 8.0)
            .sum();
        let tangential: f64 = layer
            .iter()
            .map(|p| p.geometry_bits[0] + p.geometry_bits[1])
            .sum();
        let normal: f64 = layer.iter().map(|p| p.geometry_bits[2]).sum();
        let stored: f64 = layer
            .iter()
            .map(|p| (p.connectivity_bytes + p.geometry_bytes + p.colour_bytes) as f64 * 8.0)
            .sum();
        let _ = writeln!(
            out,
            "| {batch} | {n} | {:.2} | {:.2} | {:.2} | {:.2} | {:.1} % |",
            per(conn),
            per(tangential),
            per(normal),
            per(tangential + normal),
            100.0 * stored / total_bits
        );
    }
    let inserted: u32 = passes.iter().map(|p| p.inserted).sum();
    let geometry: f64 = passes
        .iter()
        .map(|p| p.geometry_bits.iter().sum::<f64>())
        .sum();
    let _ = writeln!(
        out,
        "\n{inserted} vertices inserted; their geometry: {:.3} b/v",
        geometry / inserted.max(1) as f64
    );
    let mut names: Vec<&str> = Vec::new();
    for p in passes {
        for (name, _) in &p.trials {
            if !names.contains(&name.as_str()) {
                names.push(name);
            }
        }
    }
    for name in names {
        let bits: f64 = passes
            .iter()
            .flat_map(|p| p.trials.iter().filter(|(n, _)| n == name).map(|t| t.1))
            .sum();
        let _ = writeln!(
            out,
            "trial {name}: {:.3} b/v ({:+.2} %)",
            bits / inserted.max(1) as f64,
            100.0 * (bits / geometry - 1.0)
        );
    }
    out
}
