//! `vitrine ingest <mesh|cloud> --db … --slug … --title …`: a mesh, or a
//! point cloud (a PLY without faces, LAS, LAZ) stored as a point stream.

use super::charts::ChartsArg;
use super::guard::GuardArgs;
use crate::database::open_storage;
use crate::ingest::points::{detect_kind, ingest_points, load_cloud};
use crate::ingest::{
    ingest_coloured, IngestOptions, IngestReport, MeasuredQuality, ModelMeta, SourceInfo,
};
use crate::source::load_coloured_frame;
use crate::storage::{
    parse_credit, parse_licence, ConnectOptions, Licence, ModelKind, OnExisting, Rights, UpAxis,
};
use std::path::PathBuf;
use std::time::Duration;
use vitrine_codec::EncodeOptions;
use vitrine_colour::ccc::CccOptions;
use vitrine_colour::ColourMode;
use vitrine_points::stream::EncodeOptions as PointEncodeOptions;
use vitrine_quality::QualityOptions;

#[derive(clap::Args, Clone, Debug)]
pub struct IngestArgs {
    /// Mesh file (PLY, OBJ, OFF, glTF, GLB or MD2) or point cloud (PLY
    /// without faces, LAS, LAZ).
    pub mesh: PathBuf,
    /// What the file is stored as: `mesh`, or `points` (a progressive point
    /// stream; a mesh PLY's vertices are taken as the points). Default:
    /// `points` for LAS, LAZ and a PLY that declares no faces, else `mesh`.
    #[arg(long, value_enum)]
    pub kind: Option<ModelKind>,
    /// MD2: the animation frame the stream carries (its skin becomes the
    /// texture the cell complex samples).
    #[arg(long, default_value_t = 0)]
    pub frame: usize,
    /// Database URL: `sqlite:vitrine.db` or `postgres://user@host/db`.
    #[arg(long, env = "VITRINE_DB", default_value = "sqlite:vitrine.db")]
    pub db: String,
    /// URL name of the model: 1–64 of a-z, 0-9 and '-'.
    #[arg(long)]
    pub slug: String,
    #[arg(long)]
    pub title: String,
    #[arg(long, default_value = "")]
    pub description: String,
    /// Audience policy: exhibition (public gets all but full resolution),
    /// open (everyone gets everything) or researchers (token holders only).
    #[arg(long, default_value = "exhibition")]
    pub policy: String,
    /// Level judged sufficient by a quality study (default: first level with
    /// 20 % of the vertices). Load caps fall toward it.
    #[arg(long)]
    pub good_enough_level: Option<u32>,
    /// If the slug exists, add a new version instead of refusing.
    #[arg(long)]
    pub new_version: bool,
    /// Position quantization: 8–16 bits for a mesh (default 12), 1–20 for
    /// a point cloud (default 14).
    #[arg(long)]
    pub quantization_bits: Option<u8>,
    /// A mesh's stream cut into charts that the viewer decodes on several
    /// cores at once (format 5): `auto` (the default: 2 charts from 100,000
    /// vertices, 4 from 200,000, a plain stream below; about 1–1.5 % more
    /// bytes, 1.3–1.5× faster to the last level with two decode workers:
    /// BENCHMARKS.md, "Charts"), `off` (format 4), 2–64, `nested`
    /// (format 6: nested charts, each part served on its own, shaped by the
    /// mesh's size) or `nested:TOP,FANOUT,PHASES` (format 6 in this shape:
    /// TOP charts, each split into FANOUT children at each of PHASES − 1
    /// splits).
    #[arg(long, default_value = "auto")]
    pub charts: ChartsArg,
    /// How colour travels: `ccc` (a cubic cell complex: a cell texture and
    /// a colour texture shared by every level, sampled from the file's
    /// colour texture (OBJ, glTF) or else its per-vertex colour; the stream
    /// carries geometry only), `vertex`, `vertex-metric` (per-vertex colour
    /// in the stream, the latter with the colour-metric decimation guard) or
    /// `none`. Default: `ccc` for a textured scan (OBJ+MTL, glTF, MD2 skin),
    /// `vertex` when the mesh has per-vertex colour only, else `none`.
    #[arg(long)]
    pub colour: Option<ColourMode>,
    /// Measure every level against the original before storing and store the
    /// curve with the model version (symmetric Hausdorff over the bounding-box
    /// diagonal, Roy colour RMSE, Lindstrom–Turk image RMSE over 24 views; the
    /// manifest's `quality`, the model page's chart). Off by default: it costs
    /// about a second per level at 50k vertices.
    #[arg(long)]
    pub quality: bool,
    /// Side in pixels of the image metric's 24 snapshots with --quality. The
    /// default, 256, keeps ingest fast; `vitrine inspect --original` uses 512.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(16..=4096))]
    pub quality_image_size: u32,
    /// Which model axis points up: x, y, z, -x, -y or -z. Default: detected
    /// (glTF/GLB: y; MD2: z; PLY, OFF, OBJ: z when the box is more than 10 %
    /// taller along z than along y, else y).
    #[arg(long, allow_hyphen_values = true)]
    pub up: Option<UpAxis>,
    /// The unit of the file's coordinates: mm, cm, m or in (the viewer's
    /// measurements are given in it).
    #[arg(long, value_parser = ["mm", "cm", "m", "in"])]
    pub unit: Option<String>,
    /// Credit line shown under the model and carried by its downloads
    /// ("Scan: Museo Nacional, 2019"); one line, at most 300 bytes.
    #[arg(long, value_parser = credit_arg)]
    pub credit: Option<String>,
    /// Licence or rights statement: CC0-1.0, PDM-1.0, CC-BY-4.0,
    /// CC-BY-SA-4.0, CC-BY-NC-4.0, CC-BY-NC-SA-4.0, CC-BY-ND-4.0,
    /// CC-BY-NC-ND-4.0, InC, InC-EDU, InC-NC, NoC-NC, NKC or CNE.
    #[arg(long, value_parser = licence_arg)]
    pub licence: Option<&'static Licence>,
    /// The language of --title, --description and --credit, as a BCP 47
    /// tag (pt, pt-BR, en): pages and the manifest mark them with it, and
    /// a visitor in another language sees a translation where one was
    /// given (`vitrine texts`), these texts otherwise.
    #[arg(long, value_parser = language_arg)]
    pub language: Option<String>,
    /// Do not measure every level's Hausdorff distance (sampled, on by
    /// default: the manifest's `hausdorff`, the viewer's "± error at this
    /// level"). It costs about levels × vertices point queries.
    #[arg(long, conflicts_with = "quality")]
    pub no_hausdorff: bool,
    #[command(flatten)]
    pub ccc: CccArgs,
    #[command(flatten)]
    pub guard: GuardArgs,
    /// Test hook: pause inside the transaction before committing.
    #[arg(long, hide = true, env = "VITRINE_TEST_PAUSE_BEFORE_COMMIT_MS")]
    pub pause_before_commit_ms: Option<u64>,
}

/// How the cubic cell complex is built (`--colour ccc`); by default from the
/// geometry.
#[derive(clap::Args, Debug, Clone)]
pub struct CccArgs {
    /// Cube edge of the cell complex in model units (default: the longest
    /// side over 0.08·√vertices, at least 12 and at most 200 cubes).
    #[arg(long)]
    pub cell_size: Option<f32>,
    /// Texels per side of a tile (default: from a budget of about 4 texels per vertex).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=256))]
    pub tile_size: Option<u32>,
    /// JPEG quality of the colour atlas.
    #[arg(long, default_value_t = 90, value_parser = clap::value_parser!(u8).range(1..=100))]
    pub jpeg_quality: u8,
}

impl CccArgs {
    pub fn options(&self) -> CccOptions {
        CccOptions {
            cell_size: self.cell_size,
            tile_size: self.tile_size,
            jpeg_quality: self.jpeg_quality,
            ..CccOptions::default()
        }
    }
}

pub async fn run(args: IngestArgs) -> anyhow::Result<()> {
    super::init_tracing();
    let options = args.options()?;
    let detected = detect_kind(&args.mesh)?;
    match args.kind.unwrap_or(detected) {
        ModelKind::Points => return run_points(args, options).await,
        ModelKind::Mesh if detected == ModelKind::Points => {
            // The mesh importer would only say "contains no faces".
            anyhow::bail!(
                "{} is a point cloud (no faces): it cannot be stored as a mesh; \
                 ingest it with --kind points (the default for this file)",
                args.mesh.display()
            );
        }
        ModelKind::Mesh => {}
    }
    let (path, frame) = (args.mesh.clone(), args.frame);
    let (source, info) = tokio::task::spawn_blocking(move || -> anyhow::Result<_> {
        let source = load_coloured_frame(&path, frame)?;
        let info = SourceInfo {
            name: file_name(&path),
            vertices: source.imported_vertices as u64,
            faces: source.imported_faces as u64,
            repair: Some(source.repair.to_string()),
        };
        Ok((source, info))
    })
    .await??;
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let meta = args.meta(info);
    let slug = meta.slug.clone();
    let report = ingest_coloured(&*storage, source.mesh, source.texture, meta, &options).await?;
    print_report(&slug, &report);
    Ok(())
}

/// Reads the file as a point cloud and stores it as a point stream.
async fn run_points(args: IngestArgs, options: IngestOptions) -> anyhow::Result<()> {
    let path = args.mesh.clone();
    let cloud = tokio::task::spawn_blocking(move || load_cloud(&path)).await??;
    let info = SourceInfo {
        name: file_name(&args.mesh),
        vertices: cloud.len() as u64,
        faces: 0,
        repair: None,
    };
    let had_normals = cloud.normals.is_some();
    let storage = open_storage(&args.db, &ConnectOptions::default(), false).await?;
    let meta = args.meta(info);
    let slug = meta.slug.clone();
    let report = ingest_points(&*storage, cloud, meta, &options).await?;
    println!(
        "ingested {slug} version {} (compression {}): point cloud, {} levels, {} → {} points, {} bytes, normals {}, encoded in {:.1} s",
        report.stored.version,
        report.stored.compression_id,
        report.levels,
        report.base_vertices,
        report.full_vertices,
        report.stream_bytes,
        if had_normals { "from the file" } else { "estimated" },
        report.encode_time.as_secs_f64(),
    );
    Ok(())
}

fn file_name(path: &std::path::Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}

impl IngestArgs {
    fn meta(&self, source: SourceInfo) -> ModelMeta {
        ModelMeta {
            slug: self.slug.clone(),
            title: self.title.clone(),
            description: self.description.clone(),
            policy: self.policy.clone(),
            good_enough_level: self.good_enough_level,
            on_existing: if self.new_version {
                OnExisting::NewVersion
            } else {
                OnExisting::Refuse
            },
            source: Some(source),
            up: self.up,
            unit: self.unit.clone(),
            rights: Rights {
                credit: self.credit.clone(),
                licence: self.licence,
            },
            language: self.language.clone(),
        }
    }

    fn options(&self) -> anyhow::Result<IngestOptions> {
        Ok(IngestOptions {
            encode: EncodeOptions {
                quantization_bits: self.quantization_bits.unwrap_or(12),
                charts: self.charts.0,
                ..EncodeOptions::default()
            },
            points: PointEncodeOptions {
                bits: self.quantization_bits.unwrap_or(14),
                ..PointEncodeOptions::default()
            },
            colour: self.colour,
            ccc: self.ccc.options(),
            guards: self.guard.options()?,
            quality: self.quality.then(|| QualityOptions {
                image_size: self.quality_image_size,
                ..QualityOptions::default()
            }),
            pause_before_commit: self.pause_before_commit_ms.map(Duration::from_millis),
            skip_hausdorff: self.no_hausdorff,
            progress: None,
        })
    }
}

fn print_report(slug: &str, report: &IngestReport) {
    println!(
        "ingested {slug} version {} (compression {}): {} levels, {} → {} vertices, {} bytes, encoded in {:.1} s",
        report.stored.version,
        report.stored.compression_id,
        report.levels,
        report.base_vertices,
        report.full_vertices,
        report.stream_bytes,
        report.encode_time.as_secs_f64(),
    );
    if let Some(t) = report.curation_time {
        println!(
            "Hausdorff distance of every level (sampled) and thumbnail in {:.2} s",
            t.as_secs_f64()
        );
    }
    if let Some(ccc) = &report.ccc {
        println!(
            "colour: {} cells, {} tiles, {:.1} % of covered texels ambiguous; cell texture {} bytes, colour texture {} bytes ({} low-resolution)",
            ccc.cells,
            ccc.tiles,
            100.0 * ccc.ambiguous_texels as f64 / ccc.covered_texels.max(1) as f64,
            ccc.cell_texture_bytes,
            ccc.colour_texture_bytes,
            ccc.colour_texture_low_bytes,
        );
    }
    if let Some(q) = &report.quality {
        print_quality(q);
    }
}

fn print_quality(q: &MeasuredQuality) {
    let (first, last) = (&q.levels[0], &q.levels[q.levels.len() - 1]);
    let roy = |r: Option<f64>| r.map_or_else(|| "—".to_string(), |r| format!("{r:.2}"));
    println!(
        "quality of {} levels measured in {:.1} s ({} px views): image RMSE {:.2} → {:.2}, Roy colour RMSE {} → {}, Hausdorff/diagonal {:.6} → {:.6}",
        q.levels.len(),
        q.time.as_secs_f64(),
        q.options.image_size,
        first.image_rmse,
        last.image_rmse,
        roy(first.roy_rmse),
        roy(last.roy_rmse),
        first.hausdorff,
        last.hausdorff,
    );
}

fn credit_arg(s: &str) -> Result<String, String> {
    parse_credit(Some(s))?.ok_or_else(|| "the credit line is blank".into())
}

fn language_arg(s: &str) -> Result<String, String> {
    crate::service::curator::annotations::parse_language(s.trim())
}

fn licence_arg(s: &str) -> Result<&'static Licence, String> {
    parse_licence(Some(s))?.ok_or_else(|| "the licence is blank".into())
}
