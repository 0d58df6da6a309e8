use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use vitrine_codec::{BaseTarget, EncodeOptions};
use vitrine_colour::{encode_coloured, ColourMode};

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
    /// How colour travels: `ccc` (cell-complex texture, written beside the
    /// stream as OUTPUT.ccc.json, .cell.png, .colour.jpg, .colour-low.jpg),
    /// `vertex`, `vertex-metric` or `none`. Default: `vertex` when the mesh
    /// has colour or a texture, else `none`.
    #[arg(long)]
    pub colour: Option<ColourMode>,
    #[command(flatten)]
    pub ccc: vitrine::CccArgs,
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
    let (mesh, texture, report) = super::load_coloured_mesh(&args.input)?;
    let mode = args
        .colour
        .unwrap_or(if mesh.colors.is_some() || texture.is_some() {
            ColourMode::Vertex
        } else {
            ColourMode::None
        });
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
    let (encoded, mapping) = encode_coloured(
        &mesh,
        texture.as_ref(),
        mode,
        &args.ccc.options(),
        vitrine_codec::Encoder::new(args.options()).progress(|p| {
            bar.set_message(p.layer.to_string());
            bar.set_position((p.input_vertices - p.vertices) as u64);
        }),
    )?;
    bar.finish_and_clear();
    let elapsed = start.elapsed();
    std::fs::write(&output, &encoded.bytes)
        .with_context(|| format!("writing {}", output.display()))?;
    if let Some(m) = &mapping {
        let files = super::CccFiles::beside(&output);
        let write = |path: &std::path::Path, bytes: &[u8]| {
            std::fs::write(path, bytes).with_context(|| format!("writing {}", path.display()))
        };
        write(
            &files.parameters,
            &serde_json::to_vec_pretty(&m.parameters)?,
        )?;
        write(&files.cell, &m.cell_png)?;
        write(&files.colour, &m.colour_jpeg)?;
        write(&files.colour_low, &m.colour_low_jpeg)?;
        let r = &m.report;
        eprintln!(
            "cell complex: {} cells, {} tiles of {}², cell texture {} B, colour {} B (low {} B), ambiguous texels {:.2} %",
            r.cells,
            r.tiles,
            m.parameters.tile_size,
            r.cell_texture_bytes,
            r.colour_texture_bytes,
            r.colour_texture_low_bytes,
            r.ambiguous_texels as f64 * 100.0 / r.covered_texels.max(1) as f64
        );
    }
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
