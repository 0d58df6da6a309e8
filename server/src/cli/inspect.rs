use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use vitrine_codec::{breakdown, Header};

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Stream file written by `vitrine encode`.
    pub input: PathBuf,
}

pub fn run(args: InspectArgs) -> anyhow::Result<()> {
    let bytes =
        std::fs::read(&args.input).with_context(|| format!("reading {}", args.input.display()))?;
    let header = Header::parse(&bytes)?;
    let levels = breakdown(&bytes)?;
    let q = header.quantization;
    println!(
        "{}: {} bytes, {}-bit quantization (step {:.6}), colour: {}, {} refinement batches",
        args.input.display(),
        bytes.len(),
        q.bits,
        q.step,
        if header.has_colour {
            "per vertex"
        } else {
            "none"
        },
        header.batch_count()
    );
    println!("level  vertices     faces      bytes   conn b/v   geom b/v  colour b/v  total b/v");
    for (k, l) in levels.iter().enumerate() {
        // Bits per vertex *added* by this level, the figure AD01 reports per layer.
        let added = if k == 0 {
            l.vertices
        } else {
            l.vertices - levels[k - 1].vertices
        } as f64;
        let bpv = |bytes: u32| bytes as f64 * 8.0 / added;
        println!(
            "{k:5} {:9} {:9} {:10} {:10.2} {:10.2} {:11.2} {:10.2}",
            l.vertices,
            l.faces,
            l.bytes,
            bpv(l.connectivity + l.overhead),
            bpv(l.geometry),
            bpv(l.colour),
            bpv(l.bytes)
        );
    }
    let n = header.final_level().vertices as f64;
    let sum = |f: fn(&vitrine_codec::LevelBreakdown) -> u32| {
        levels[1..].iter().map(f).sum::<u32>() as f64 * 8.0 / n
    };
    println!(
        "whole stream per final vertex: connectivity {:.2}, geometry {:.2}, colour {:.2}, base mesh {:.2}, total {:.2} bits",
        sum(|l| l.connectivity + l.overhead),
        sum(|l| l.geometry),
        sum(|l| l.colour),
        levels[0].bytes as f64 * 8.0 / n,
        bytes.len() as f64 * 8.0 / n
    );
    Ok(())
}
