//! `vitrine decode`: a stream file, up to a level, as a PLY, OBJ or GLB mesh.

use anyhow::{bail, Context};
use clap::Args;
use std::io::BufWriter;
use std::path::PathBuf;
use vitrine_codec::{decode, Limits};
use vitrine_mesh::export::{write_glb, write_obj, write_ply};

#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Stream file written by `vitrine encode`.
    pub input: PathBuf,
    /// Output mesh; the extension picks the format: .ply, .obj or .glb.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of refinement batches to apply (default: all).
    #[arg(short, long)]
    pub level: Option<usize>,
}

pub fn run(args: DecodeArgs) -> anyhow::Result<()> {
    let bytes =
        std::fs::read(&args.input).with_context(|| format!("reading {}", args.input.display()))?;
    let decoder = decode(&bytes, args.level, Limits::default())
        .with_context(|| format!("decoding {}", args.input.display()))?;
    let mesh = decoder.to_mesh();
    let file = std::fs::File::create(&args.output)
        .with_context(|| format!("creating {}", args.output.display()))?;
    let mut w = BufWriter::new(file);
    match args
        .output
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("ply") => write_ply(&mesh, &mut w)?,
        Some("obj") => write_obj(&mesh, &mut w)?,
        Some("glb") => write_glb(&mesh, &mut w)?,
        _ => bail!("output extension must be .ply, .obj or .glb"),
    }
    eprintln!(
        "level {} of {}: {} vertices, {} faces → {}",
        decoder.level(),
        decoder.header().batch_count(),
        mesh.positions.len(),
        mesh.triangles.len(),
        args.output.display()
    );
    Ok(())
}
