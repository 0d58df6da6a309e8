//! `vitrine encode`: a mesh file into a progressive stream file, with the
//! cell complex written beside it in `ccc` mode.

use super::charts::ChartsArg;
use super::guard::GuardArgs;
use super::ingest::CccArgs;
use crate::ccc_files::CccFiles;
use crate::ingest::{FeatureSetting, GuardOptions, Guards};
use crate::source::{default_colour_mode, describe_repair, load_coloured_frame, SourceMesh};
use anyhow::Context;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::time::Instant;
use vitrine_codec::{BaseTarget, EncodeOptions, Encoded};
use vitrine_colour::ccc::TextureMapping;
use vitrine_colour::{encode_coloured, ColourMode};

#[derive(Args, Debug)]
pub struct EncodeArgs {
    /// Input mesh: .ply, .obj, .off, .gltf, .glb or .md2.
    pub input: PathBuf,
    /// MD2: the animation frame the stream carries.
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
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
    /// `vertex`, `vertex-metric` or `none`. Default: `ccc` for a textured
    /// scan, `vertex` when the mesh has per-vertex colour only, else `none`.
    #[arg(long)]
    pub colour: Option<ColourMode>,
    #[command(flatten)]
    pub ccc: CccArgs,
    #[command(flatten)]
    pub guard: GuardArgs,
    /// Cut the stream into charts that decode on several cores (format 5):
    /// `off` (the default: format 4), `auto` (2 charts from 100,000 vertices, 4 from 200,000;
    /// plain below 100,000), a number of charts, 2–64, `nested` (format 6:
    /// nested charts for view-dependent streaming, shaped by the mesh's size)
    /// or `nested:TOP,FANOUT,PHASES` (format 6 in this shape: TOP charts, each
    /// split into FANOUT children at each of PHASES − 1 splits).
    #[arg(long, default_value = "off")]
    pub charts: ChartsArg,
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
            charts: self.charts.0,
            ..EncodeOptions::default()
        }
    }
}

pub fn run(args: EncodeArgs) -> anyhow::Result<()> {
    let output = args
        .output
        .clone()
        .unwrap_or_else(|| args.input.with_extension("vtr"));
    let guards = args.guard.options()?;
    let source = load_coloured_frame(&args.input, args.frame)?;
    if let Some(text) = describe_repair(&source.repair) {
        eprintln!("repair: {text}");
    }
    let start = Instant::now();
    let (encoded, mapping) = encode_with_progress(&source, &args, &guards)?;
    let elapsed = start.elapsed();
    std::fs::write(&output, &encoded.bytes)
        .with_context(|| format!("writing {}", output.display()))?;
    if let Some(m) = &mapping {
        CccFiles::beside(&output).write(m)?;
        print_complex(m);
    }
    let (n, h) = (source.mesh.positions.len(), &encoded.header);
    eprintln!(
        "{}: {} vertices, {} faces → {} bytes ({:.2} bits/vertex), {} levels, base {} vertices, {:.2} s",
        output.display(),
        n,
        source.mesh.triangles.len(),
        encoded.bytes.len(),
        encoded.bytes.len() as f64 * 8.0 / n as f64,
        h.batch_count(),
        h.levels[0].vertices,
        elapsed.as_secs_f64()
    );
    Ok(())
}

/// Encodes in the colour mode asked for (by default the one the mesh's
/// colour calls for) under the guards asked for, with a progress bar of
/// the vertices removed so far.
fn encode_with_progress(
    source: &SourceMesh,
    args: &EncodeArgs,
    guards: &GuardOptions,
) -> anyhow::Result<(Encoded, Option<TextureMapping>)> {
    let (mesh, texture) = (&source.mesh, source.texture.as_ref());
    let mode = args
        .colour
        .unwrap_or_else(|| default_colour_mode(mesh, texture));
    let options = args.options();
    if guards.features.is_some() && guards.feature_setting == FeatureSetting::Auto {
        eprintln!(
            "feature guard: encoding under {} settings to choose one for this scan…",
            vitrine_simplify::SEARCHED_SETTINGS.len()
        );
    }
    let guards = Guards::new(mesh, guards, &options)?;
    if let Some(f) = guards.features() {
        eprintln!("{}", f.describe());
    }
    let bar = ProgressBar::new(mesh.positions.len() as u64);
    bar.set_style(
        ProgressStyle::with_template(
            "{spinner} layer {msg} [{bar:40}] {pos}/{len} vertices removed",
        )
        .expect("valid template")
        .progress_chars("=> "),
    );
    let encoded = encode_coloured(
        mesh,
        texture,
        mode,
        &args.ccc.options(),
        guards
            .apply(vitrine_codec::Encoder::new(options))
            .progress(|p| {
                bar.set_message(p.layer.to_string());
                bar.set_position((p.input_vertices - p.vertices) as u64);
            }),
    )?;
    bar.finish_and_clear();
    Ok(encoded)
}

fn print_complex(m: &TextureMapping) {
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
