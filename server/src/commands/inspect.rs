use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use vitrine_codec::{breakdown, Header};
use vitrine_colour::ccc::{CccParameters, CellComplex};
use vitrine_colour::vertex_colours_from_texture;
use vitrine_quality::{stream_quality, Original, QualityOptions};

#[derive(Args, Debug)]
pub struct InspectArgs {
    /// Stream file written by `vitrine encode`.
    pub input: PathBuf,
    /// The mesh the stream was encoded from: also print quality per level
    /// (Hausdorff, Roy colour RMSE, 24-view image RMSE). A cell complex
    /// written beside the stream by `encode --colour ccc` is used for colour.
    #[arg(long)]
    pub original: Option<PathBuf>,
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
    if let Some(original) = &args.original {
        print_quality(&bytes, &args, original)?;
    }
    Ok(())
}

fn print_quality(
    bytes: &[u8],
    args: &InspectArgs,
    original: &std::path::Path,
) -> anyhow::Result<()> {
    let (mut mesh, texture, _) = super::load_coloured_mesh(original)?;
    if let Some(t) = &texture {
        mesh.colors = Some(vertex_colours_from_texture(&mesh, t));
    }
    let files = super::CccFiles::beside(&args.input);
    let complex = if files.parameters.exists() {
        let read = |p: &std::path::Path| {
            std::fs::read(p).with_context(|| format!("reading {}", p.display()))
        };
        let parameters: CccParameters = serde_json::from_slice(&read(&files.parameters)?)?;
        Some(CellComplex::from_images(
            &parameters,
            &read(&files.cell)?,
            &read(&files.colour)?,
        )?)
    } else {
        None
    };
    let quality = stream_quality(
        bytes,
        complex.as_ref(),
        &Original {
            mesh: &mesh,
            texture: texture.as_ref(),
        },
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
