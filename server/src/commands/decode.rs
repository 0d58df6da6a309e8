//! `vitrine decode`: a stream file, up to a level, as a PLY, OBJ, GLB or MD2 mesh.

use super::mesh_format::MeshFormat;
use anyhow::Context;
use clap::Args;
use std::path::PathBuf;
use vitrine_codec::{decode, Limits};

#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Stream file written by `vitrine encode`.
    pub input: PathBuf,
    /// Output mesh; the extension picks the format: .ply, .obj, .glb or .md2.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Number of refinement batches to apply (default: all).
    #[arg(short, long)]
    pub level: Option<usize>,
}

pub fn run(args: DecodeArgs) -> anyhow::Result<()> {
    let format = MeshFormat::from_path(&args.output)?;
    let bytes =
        std::fs::read(&args.input).with_context(|| format!("reading {}", args.input.display()))?;
    let decoder = decode(&bytes, args.level, Limits::default())
        .with_context(|| format!("decoding {}", args.input.display()))?;
    let mesh = decoder.to_mesh();
    format.write(&mesh, &args.output)?;
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
