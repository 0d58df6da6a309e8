//! `vitrine-dev colour-bench`: the thesis' three-way colour comparison (§5.5,
//! Tables 11 and 15) on our codec: per mode, vertices base → full, layers,
//! connectivity bits per vertex against unguarded AD, the cell texture
//! against float UVs, and per-level quality curves (Hausdorff, Roy colour
//! RMSE, Lindstrom–Turk image RMSE) drawn as SVG.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use crate::source::{load_coloured_mesh, read_back, QualityReference};
use anyhow::Context;
use clap::Args;
use vitrine_codec::{breakdown, EncodeOptions};
use vitrine_colour::ccc::{CccOptions, TextureMapping};
use vitrine_colour::{encode_coloured, ColourMode};
use vitrine_quality::{LevelQuality, QualityOptions};

#[derive(Args, Debug)]
pub struct ColourBenchArgs {
    /// Coloured meshes (per-vertex colour, or a texture through OBJ+MTL or glTF).
    #[arg(required = true)]
    pub meshes: Vec<PathBuf>,
    /// Side of the 24 snapshots of the image metric.
    #[arg(long, default_value_t = 512)]
    pub image_size: u32,
    /// Surface samples per mesh for the Hausdorff distance.
    #[arg(long, default_value_t = 100_000)]
    pub samples: usize,
    /// Folder for the SVG curves and the JSON of every level.
    #[arg(long, default_value = "docs/colour")]
    pub out: PathBuf,
    /// Position quantization in bits.
    #[arg(long, default_value_t = 12)]
    pub bits: u8,
}

struct ModeRun {
    mode: ColourMode,
    base_vertices: u32,
    full_vertices: u32,
    layers: usize,
    connectivity_bpv: f64,
    total_bytes: usize,
    quality: Vec<LevelQuality>,
    seconds: f64,
}

/// The three markdown tables, a row or a few per mesh.
#[derive(Default)]
struct Tables {
    modes: String,
    complex_sizes: String,
    low_levels: String,
}

pub fn run(args: ColourBenchArgs) -> anyhow::Result<()> {
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("creating {}", args.out.display()))?;
    let mut tables = Tables::default();
    for path in &args.meshes {
        bench_mesh(path, &args, &mut tables)?;
    }
    println!("| mesh | mode | vertices base → full | layers | connectivity b/v | vs unguarded AD | stream | encode + measure |");
    println!("|---|---|---|---|---|---|---|---|");
    print!("{}", tables.modes);
    println!("\n| mesh | vertices | cells | grid | atlas side | cell texture (PNG) | colour low (JPEG) | colour full (JPEG) | float UVs | ambiguous texels |");
    println!("|---|---|---|---|---|---|---|---|---|---|");
    print!("{}", tables.complex_sizes);
    println!("\nImage RMSE (luma 0–255, 24 views) at the levels with ≤ 20 % of the vertices:\n");
    println!("| mesh | mode | vertices → RMSE |");
    println!("|---|---|---|");
    print!("{}", tables.low_levels);
    Ok(())
}

/// Every mode on one mesh: its table rows, and its curves as SVG and JSON in `args.out`.
fn bench_mesh(path: &Path, args: &ColourBenchArgs, tables: &mut Tables) -> anyhow::Result<()> {
    let name = mesh_name(path);
    eprintln!("{name}: importing");
    let source = load_coloured_mesh(path)?;
    let reference = QualityReference::new(source.mesh, source.texture);
    anyhow::ensure!(
        reference.mesh.colors.is_some(),
        "{}: no colour to compare",
        path.display()
    );
    let options = EncodeOptions {
        quantization_bits: args.bits,
        ..EncodeOptions::default()
    };
    let quality = QualityOptions {
        image_size: args.image_size,
        hausdorff_samples: args.samples,
    };
    // Unguarded AD on the geometry: the connectivity baseline.
    let (plain, _) = encode_coloured(
        &reference.mesh,
        None,
        ColourMode::None,
        &CccOptions::default(),
        vitrine_codec::Encoder::new(options.clone()),
    )?;
    let vertices = reference.mesh.positions.len();
    let plain_conn = connectivity_bpv(&plain.bytes, vertices)?;
    let mut runs = Vec::new();
    for mode in [
        ColourMode::Ccc,
        ColourMode::Vertex,
        ColourMode::VertexMetric,
    ] {
        eprintln!("  {mode}: encoding and measuring every level");
        let (run, mapping) = run_mode(&reference, mode, &options, &quality)?;
        if let Some(m) = &mapping {
            complex_row(&mut tables.complex_sizes, &name, vertices, m)?;
        }
        runs.push(run);
    }
    mode_rows(tables, &name, &runs, plain_conn)?;
    write_curves(&args.out, &name, &runs)?;
    eprintln!("  unguarded connectivity {plain_conn:.3} b/v");
    Ok(())
}

/// Every level of every mode as `NAME.json`, and the curves as `NAME.svg`.
fn write_curves(out: &Path, name: &str, runs: &[ModeRun]) -> anyhow::Result<()> {
    let json: Vec<_> = runs
        .iter()
        .map(|r| serde_json::json!({ "mode": r.mode, "levels": r.quality }))
        .collect();
    std::fs::write(
        out.join(format!("{name}.json")),
        serde_json::to_string_pretty(&json)?,
    )?;
    std::fs::write(out.join(format!("{name}.svg")), curves_svg(name, runs))?;
    Ok(())
}

/// One mode: encoded (the time counts the complex read back, not the
/// measuring), then every level measured.
fn run_mode(
    reference: &QualityReference,
    mode: ColourMode,
    options: &EncodeOptions,
    quality: &QualityOptions,
) -> anyhow::Result<(ModeRun, Option<TextureMapping>)> {
    let start = Instant::now();
    let (encoded, mapping) = encode_coloured(
        &reference.mesh,
        reference.texture.as_ref(),
        mode,
        &CccOptions::default(),
        vitrine_codec::Encoder::new(options.clone()),
    )?;
    let complex = mapping.as_ref().map(read_back).transpose()?;
    let seconds = start.elapsed().as_secs_f64();
    let levels = breakdown(&encoded.bytes)?;
    let run = ModeRun {
        mode,
        base_vertices: levels[0].vertices,
        full_vertices: levels.last().map_or(0, |l| l.vertices),
        layers: levels.len() - 1,
        connectivity_bpv: connectivity_bpv(&encoded.bytes, reference.mesh.positions.len())?,
        total_bytes: encoded.bytes.len(),
        quality: reference.measure(&encoded.bytes, complex.as_ref(), quality)?,
        seconds,
    };
    Ok((run, mapping))
}

fn complex_row(
    out: &mut String,
    name: &str,
    vertices: usize,
    m: &TextureMapping,
) -> std::fmt::Result {
    let r = &m.report;
    writeln!(
        out,
        "| {name} | {} | {} | {}×{}×{} | {} | {:.1} KB | {:.1} KB | {:.1} KB | {:.2} MB | {:.2} % |",
        vertices,
        m.parameters.cells,
        m.parameters.dims[0],
        m.parameters.dims[1],
        m.parameters.dims[2],
        m.parameters.atlas.width,
        r.cell_texture_bytes as f64 / 1e3,
        r.colour_texture_low_bytes as f64 / 1e3,
        r.colour_texture_bytes as f64 / 1e3,
        vertices as f64 * 8.0 / 1e6,
        r.ambiguous_texels as f64 * 100.0 / r.covered_texels.max(1) as f64,
    )
}

/// Each mode's sizes, and its image RMSE at the low levels by fraction of vertices.
fn mode_rows(
    tables: &mut Tables,
    name: &str,
    runs: &[ModeRun],
    plain_conn: f64,
) -> std::fmt::Result {
    for r in runs {
        writeln!(
            tables.modes,
            "| {name} | {} | {} → {} | {} | {:.3} | {:+.2} % | {:.1} KB | {:.1} s |",
            r.mode,
            r.base_vertices,
            r.full_vertices,
            r.layers,
            r.connectivity_bpv,
            (r.connectivity_bpv / plain_conn - 1.0) * 100.0,
            r.total_bytes as f64 / 1e3,
            r.seconds,
        )?;
    }
    for r in runs {
        let picks: Vec<String> = r
            .quality
            .iter()
            .filter(|q| (q.vertices as f64) <= 0.2 * r.full_vertices as f64)
            .map(|q| {
                format!(
                    "{:.1} % → {:.1}",
                    100.0 * q.vertices as f64 / r.full_vertices as f64,
                    q.image_rmse
                )
            })
            .collect();
        writeln!(
            tables.low_levels,
            "| {name} | {} | {} |",
            r.mode,
            picks.join(", ")
        )?;
    }
    Ok(())
}

fn mesh_name(path: &Path) -> String {
    path.file_stem()
        .map_or_else(|| "mesh".into(), |s| s.to_string_lossy().into_owned())
}

fn connectivity_bpv(stream: &[u8], vertices: usize) -> anyhow::Result<f64> {
    let levels = breakdown(stream)?;
    let bytes: u64 = levels
        .iter()
        .map(|l| (l.connectivity + l.overhead) as u64)
        .sum();
    Ok(bytes as f64 * 8.0 / vertices as f64)
}

/// Reads one curve's value off a level.
type Metric = fn(&LevelQuality) -> Option<f64>;

/// The panels' size and margin.
const W: f64 = 420.0;
const H: f64 = 280.0;
const PAD: f64 = 48.0;

/// Two panels, image RMSE and Roy RMSE against the fraction of vertices
/// (log scale), one line per mode. Hand-written SVG: a few polylines do
/// not need a plotting library.
fn curves_svg(name: &str, runs: &[ModeRun]) -> String {
    let mut svg = format!(
        "<svg xmlns='http://www.w3.org/2000/svg' width='{}' height='{}' font-family='sans-serif' font-size='11'>\n",
        2.0 * W,
        H + 30.0
    );
    writeln!(svg, "<text x='8' y='16' font-size='13'>{name}: quality per level (x: vertices, log scale)</text>").ok();
    let panels: [(&str, Metric); 2] = [
        ("image RMSE (luma, 24 views)", |q| Some(q.image_rmse)),
        ("Roy colour RMSE", |q| q.roy_rmse),
    ];
    for (p, (title, value)) in panels.iter().enumerate() {
        panel_svg(&mut svg, p as f64 * W, title, *value, runs);
    }
    svg.push_str("</svg>\n");
    svg
}

/// Where a panel's values land: x on a log scale over the vertex counts, y
/// linear from 0 to a little above the largest value.
struct Scale {
    x0: f64,
    xmin: f64,
    xmax: f64,
    ymax: f64,
}

impl Scale {
    fn over(x0: f64, points: &[(f64, f64)]) -> Scale {
        let (xmin, xmax) = points
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &(x, _)| {
                (a.min(x), b.max(x))
            });
        let ymax = points.iter().fold(0.0f64, |m, &(_, y)| m.max(y)).max(1e-9) * 1.05;
        Scale {
            x0,
            xmin,
            xmax,
            ymax,
        }
    }

    fn x(&self, x: f64) -> f64 {
        let (lo, hi) = (self.xmin.ln(), self.xmax.ln());
        self.x0 + PAD + (x.ln() - lo) / (hi - lo).max(1e-9) * (W - 1.5 * PAD)
    }

    fn y(&self, y: f64) -> f64 {
        30.0 + (H - PAD) * (1.0 - y / self.ymax)
    }
}

/// One panel at `x0`: axes, their end labels, and a line per mode.
fn panel_svg(svg: &mut String, x0: f64, title: &str, value: Metric, runs: &[ModeRun]) {
    let colours = ["#d1495b", "#00798c", "#edae49"];
    let points: Vec<(f64, f64)> = runs
        .iter()
        .flat_map(|r| {
            r.quality
                .iter()
                .filter_map(|q| value(q).map(|v| (q.vertices as f64, v)))
        })
        .collect();
    let scale = Scale::over(x0, &points);
    axes_svg(svg, title, &scale);
    for (i, r) in runs.iter().enumerate() {
        let pts: Vec<String> = r
            .quality
            .iter()
            .filter_map(|q| {
                let v = value(q)?;
                Some(format!(
                    "{:.1},{:.1}",
                    scale.x(q.vertices as f64),
                    scale.y(v)
                ))
            })
            .collect();
        writeln!(
            svg,
            "<polyline fill='none' stroke='{}' stroke-width='2' points='{}'/>",
            colours[i % 3],
            pts.join(" ")
        )
        .ok();
        writeln!(
            svg,
            "<text x='{}' y='{}' fill='{}'>{}</text>",
            x0 + W - 2.5 * PAD,
            52.0 + 14.0 * i as f64,
            colours[i % 3],
            r.mode
        )
        .ok();
    }
}

fn axes_svg(svg: &mut String, title: &str, scale: &Scale) {
    let (x0, y0) = (scale.x0, scale.y(0.0));
    writeln!(svg, "<text x='{}' y='40'>{title}</text>", x0 + PAD).ok();
    writeln!(
        svg,
        "<line x1='{0}' y1='{2}' x2='{1}' y2='{2}' stroke='#444'/><line x1='{0}' y1='30' x2='{0}' y2='{2}' stroke='#444'/>",
        x0 + PAD,
        x0 + W - PAD / 2.0,
        y0
    )
    .ok();
    writeln!(
        svg,
        "<text x='{}' y='{}'>{:.0}</text><text x='{}' y='{}' text-anchor='end'>{:.0}</text>",
        x0 + PAD,
        y0 + 14.0,
        scale.xmin,
        x0 + W - PAD / 2.0,
        y0 + 14.0,
        scale.xmax
    )
    .ok();
    writeln!(
        svg,
        "<text x='{}' y='{}' text-anchor='end'>{:.1}</text>",
        x0 + PAD - 4.0,
        scale.y(scale.ymax / 1.05) + 4.0,
        scale.ymax / 1.05
    )
    .ok();
}
