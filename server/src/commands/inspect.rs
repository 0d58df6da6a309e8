//! `vitrine inspect`: what each level of a stream costs and, given the
//! original mesh, how close each level comes to it.

use crate::ccc_files::CccFiles;
use crate::source::{load_coloured_mesh, QualityReference};
use anyhow::Context;
use clap::Args;
use std::path::{Path, PathBuf};
use vitrine_codec::{breakdown, Header, LevelBreakdown};
use vitrine_quality::QualityOptions;

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Stream file written by `vitrine encode`.
    pub input: PathBuf,
    /// The mesh the stream was encoded from: also print quality per level
    /// (Hausdorff, Roy colour RMSE, 24-view image RMSE). A cell complex
    /// written beside the stream by `encode --colour ccc` is used for colour.
    #[arg(long)]
    pub original: Option<PathBuf>,
    /// For a charted stream: what a viewer refining where the visitor looks
    /// fetches (the shared prefix, each chart's parts and errors, a
    /// close-up's bytes).
    #[arg(long)]
    pub parts: bool,
    /// Side of the image metric's snapshots.
    #[arg(long, default_value_t = 512)]
    pub image_size: u32,
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
    print_levels(&bytes, &levels, header.final_level().vertices);
    if args.parts {
        match super::parts::report(&bytes)? {
            Some(report) => print!("{report}"),
            None => println!("a plain stream: no parts (encode with --charts)"),
        }
    }
    if let Some(original) = &args.original {
        print_quality(&bytes, &args, original)?;
    }
    Ok(())
}

/// Per level, and summed over the stream, bits per vertex by what they code.
fn print_levels(bytes: &[u8], levels: &[LevelBreakdown], final_vertices: u32) {
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
    let n = final_vertices as f64;
    let sum =
        |f: fn(&LevelBreakdown) -> u32| levels[1..].iter().map(f).sum::<u32>() as f64 * 8.0 / n;
    println!(
        "whole stream per final vertex: connectivity {:.2}, geometry {:.2}, colour {:.2}, base mesh {:.2}, total {:.2} bits",
        sum(|l| l.connectivity + l.overhead),
        sum(|l| l.geometry),
        sum(|l| l.colour),
        levels[0].bytes as f64 * 8.0 / n,
        bytes.len() as f64 * 8.0 / n
    );
}

fn print_quality(bytes: &[u8], args: &InspectArgs, original: &Path) -> anyhow::Result<()> {
    let source = load_coloured_mesh(original)?;
    let reference = QualityReference::new(source.mesh, source.texture);
    let complex = CccFiles::beside(&args.input).read_complex()?;
    let quality = reference.measure(
        bytes,
        complex.as_ref(),
        &QualityOptions {
            image_size: args.image_size,
            ..QualityOptions::default()
        },
    )?;
    println!(
        "\nquality against {}{}:",
        original.display(),
        if complex.is_some() {
            " (colour from the cell complex)"
        } else {
            ""
        }
    );
    println!("level  vertices  Hausdorff/diag   Roy RMSE  image RMSE");
    for q in &quality {
        let roy = q
            .roy_rmse
            .map_or_else(|| "—".to_string(), |r| format!("{r:.2}"));
        println!(
            "{:5} {:9} {:15.6} {:>10} {:11.2}",
            q.level, q.vertices, q.hausdorff, roy, q.image_rmse
        );
    }
    Ok(())
}
