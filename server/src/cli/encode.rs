use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use vitrine_codec::{encode_with_progress, BaseTarget, EncodeOptions};

#[derive(Args, Debug)]
pub struct EncodeArgs {
    /// Input mesh: .ply, .obj, .off, .gltf or .glb.
    pub input: PathBuf,
    /// Output stream file (default: input with extension .vtr).
    #[arg(short, long)]
    pub output: Option<PathBuf>,
    /// Position quantization in bits (8–16).
    #[arg(short = 'q', long, default_value_t = 12)]
    pub bits: u8,
    /// Stop when the base mesh has at most this many vertices…
    #[arg(long, conflicts_with = "base_fraction")]
    pub base_vertices: Option<u32>,
    /// …or at most this fraction of the input's vertices.
    #[arg(long, default_value_t = 0.01)]
    pub base_fraction: f32,
    /// Allow retriangulations that fold (slightly smaller, uglier low levels).
    #[arg(long)]
    pub no_geometric_guard: bool,
}

impl EncodeArgs {
    pub fn options(&self) -> EncodeOptions {
        EncodeOptions {
            quantization_bits: self.bits,
            base: match self.base_vertices {
                Some(n) => BaseTarget::Vertices(n),
                None => BaseTarget::Fraction(self.base_fraction),
            },
            geometric_guard: !self.no_geometric_guard,
            ..EncodeOptions::default()
        }
    }
}

pub fn run(args: EncodeArgs) -> anyhow::Result<()> {
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| args.input.with_extension("vtr"));
    let (mesh, report) = super::load_mesh(&args.input)?;
    if let Some(text) = super::describe_repair(&report) {
        eprintln!("repair: {text}");
    }
    let n = mesh.positions.len() as u64;
    let bar = ProgressBar::new(n);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} layer {msg} [{bar:40}] {pos}/{len} vertices removed",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let start = Instant::now();
    let encoded = encode_with_progress(&mesh, &args.options(), |p| {
        bar.set_message(p.layer.to_string());
        bar.set_position((p.input_vertices - p.vertices) as u64);
    })?;
    bar.finish_and_clear();
    let elapsed = start.elapsed();
    std::fs::write(&output, &encoded.bytes)
        .with_context(|| format!("writing {}", output.display()))?;
    let h = &encoded.header;
    eprintln!(
        "{}: {} vertices, {} faces → {} bytes ({:.2} bits/vertex), {} levels, base {} vertices, {:.2} s",
        output.display(),
        n,
        mesh.triangles.len(),
        encoded.bytes.len(),
        encoded.bytes.len() as f64 * 8.0 / n as f64,
        h.batch_count(),
        h.levels[0].vertices,
        elapsed.as_secs_f64()
    );
    Ok(())
}
