//! `vitrine simplify`: a mesh file down to a vertex count, by one of the
//! simplifiers (`--method`), written as PLY, OBJ or GLB, with one report for
//! every method: sizes, symmetric Hausdorff distance to the input, passes,
//! why it stopped, time (`--json` for benchmarks).

use super::mesh_format::MeshFormat;
use crate::source::{describe_repair, load_coloured_mesh};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::{Path, PathBuf};
use std::time::Instant;
use vitrine_codec::IndexedMesh;
use vitrine_colour::vertex_colours_from_texture;
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::melax::{melax_simplify, MelaxCost};
use vitrine_simplify::{
    simplify, Collapse, FeatureThreshold, Features, Placement, SimplifyOptions, StopReason, Target,
};

/// A simplifier.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Method {
    /// Collapses of the vertices off the borders and away from sharp
    /// features (average normal deviation θ, seed 004), each checked for
    /// the link condition and flips, to an exact vertex count.
    NormalDeviation,
    /// Melax's edge collapses (seed 003): each vertex into its cheapest
    /// neighbour (distance times the crease it leaves), cheapest first,
    /// borders locked, link condition and flips checked; positions never
    /// move.
    Melax,
    /// Geodesic discs, their intrinsic Voronoi diagram refined to the
    /// closed-ball property, and its dual (seed 001): input vertices only,
    /// genus, components and borders kept (`--distance`, `--order`,
    /// `--radius`).
    Voronoi,
}

impl Method {
    /// As `--method` spells it.
    pub fn name(self) -> &'static str {
        match self {
            Method::NormalDeviation => "normal-deviation",
            Method::Melax => "melax",
            Method::Voronoi => "voronoi",
        }
    }
}

/// Where `normal-deviation` puts a merged vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PlacementKind {
    /// The seed's midpoints and centroids, vertices in ascending θ.
    Seed,
    /// The least error under the merged patch's quadric (Garland–Heckbert),
    /// cheapest merges first.
    Quadric,
}

/// What `normal-deviation` does with feature vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum FeaturesKind {
    /// Never removed (the seed): may stop short of the target.
    Keep,
    /// Removed last, least sharp first, once nothing else can go.
    Last,
}

/// Melax's crease term, for `--method melax` and `vitrine lod`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum MelaxCostKind {
    /// ‖u − v‖·sin(θ/2) for the crease angle θ: first order in θ, so a
    /// smooth scan does not pile its collapses into one patch.
    Sine,
    /// The seed's ‖u − v‖·(1 − f·n)/2 = ‖u − v‖·sin²(θ/2), as Melax wrote it.
    Seed,
}

impl From<MelaxCostKind> for MelaxCost {
    fn from(kind: MelaxCostKind) -> MelaxCost {
        match kind {
            MelaxCostKind::Sine => MelaxCost::Sine,
            MelaxCostKind::Seed => MelaxCost::Seed,
        }
    }
}

/// How `normal-deviation` removes vertices.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum CollapseKind {
    /// Both ends of an edge to its midpoint.
    Edge,
    /// One end of an edge into the other, which stays put.
    HalfEdge,
    /// A face's three corners to its centroid.
    Triangle,
}

#[derive(Args, Debug)]
pub struct SimplifyArgs {
    /// Input mesh: .ply, .obj, .off, .gltf, .glb or .md2.
    pub input: PathBuf,
    /// Output mesh; the extension picks the format: .ply, .obj, .glb or .md2.
    #[arg(short, long)]
    pub output: PathBuf,
    /// The simplifier.
    #[arg(long, value_enum)]
    pub method: Method,
    #[command(flatten)]
    pub target: TargetArgs,
    /// normal-deviation: how a pass removes vertices.
    #[arg(long, value_enum, default_value_t = CollapseKind::Edge)]
    pub collapse: CollapseKind,
    /// normal-deviation: where a feature starts: `mean+2sigma` of θ, an
    /// angle in degrees (`12` or `12deg`) or a percentile (`p95`).
    #[arg(long, value_name = "mean+2sigma|DEG|pP", default_value = "mean+2sigma")]
    pub feature_threshold: FeatureThreshold,
    /// normal-deviation: where a merged vertex goes.
    #[arg(long, value_enum, default_value_t = PlacementKind::Quadric)]
    pub placement: PlacementKind,
    /// normal-deviation: whether feature vertices may go once nothing else
    /// can (the target is then always met, borders permitting).
    #[arg(long, value_enum, default_value_t = FeaturesKind::Last)]
    pub features: FeaturesKind,
    /// melax: the crease term of the collapse cost.
    #[arg(long, value_enum, default_value_t = MelaxCostKind::Sine)]
    pub melax_cost: MelaxCostKind,
    #[command(flatten)]
    pub voronoi: super::simplify_voronoi::VoronoiArgs,
    /// Area samples per mesh for the Hausdorff distance (plus every vertex).
    #[arg(long, default_value_t = 200_000)]
    pub hausdorff_samples: usize,
    /// Print the report as JSON on stdout instead of text.
    #[arg(long)]
    pub json: bool,
}

/// Where to stop: one of the two.
#[derive(Args, Debug)]
#[group(required = true, multiple = false)]
pub struct TargetArgs {
    /// Vertices in the output.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub target_vertices: Option<u64>,
    /// Fraction of the input's vertices in the output, within (0, 1].
    #[arg(long, value_name = "F", value_parser = parse_fraction)]
    pub target_fraction: Option<f64>,
    /// voronoi: the disc radius as a fraction of the bounding-box diagonal.
    #[arg(long, value_name = "R", value_parser = parse_radius)]
    pub radius: Option<f64>,
}

impl TargetArgs {
    fn target(&self) -> anyhow::Result<Target> {
        match (self.target_vertices, self.target_fraction) {
            (Some(n), _) => Ok(Target::Vertices(n as usize)),
            (None, Some(f)) => Ok(Target::Fraction(f)),
            // clap's group requires one of the three; --radius is voronoi's.
            (None, None) => anyhow::bail!("--radius applies to --method voronoi only"),
        }
    }
}

fn parse_radius(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(r) if r > 0.0 && r <= 10.0 => Ok(r),
        _ => Err(format!("must be a number within (0, 10], got {s:?}")),
    }
}

fn parse_fraction(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(f) if f > 0.0 && f <= 1.0 => Ok(f),
        _ => Err(format!("must be a number within (0, 1], got {s:?}")),
    }
}

/// The report every method gives.
#[derive(Clone, Debug, Serialize)]
pub struct SimplifyReport {
    pub method: &'static str,
    pub input: Counts,
    pub output: Counts,
    /// Symmetric Hausdorff distance between input and output over the
    /// input's bounding-box diagonal.
    pub hausdorff: f64,
    pub hausdorff_samples: usize,
    pub passes: usize,
    /// `target` (reached exactly), `no-candidate` (nothing more could be
    /// removed) or `max-passes`.
    pub stopped: &'static str,
    /// Simplification alone, not loading, writing or measuring.
    pub seconds: f64,
    /// normal-deviation's parameters.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub collapse: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub feature_threshold_degrees: Option<f64>,
    /// τ at the end, above the first when features had to go.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub final_feature_threshold_degrees: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub placement: Option<&'static str>,
    /// voronoi's parameters and counts.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub voronoi: Option<super::simplify_voronoi::VoronoiReport>,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct Counts {
    pub vertices: usize,
    pub faces: usize,
}

impl Counts {
    fn of(mesh: &IndexedMesh) -> Counts {
        Counts {
            vertices: mesh.vertex_count(),
            faces: mesh.face_count(),
        }
    }
}

/// What a method made, before it is measured.
struct Outcome {
    mesh: IndexedMesh,
    passes: usize,
    stopped: &'static str,
    collapse: Option<&'static str>,
    feature_threshold_degrees: Option<f64>,
    final_feature_threshold_degrees: Option<f64>,
    placement: Option<&'static str>,
    voronoi: Option<super::simplify_voronoi::VoronoiReport>,
}

pub fn run(args: SimplifyArgs) -> anyhow::Result<()> {
    let format = MeshFormat::from_path(&args.output)?;
    let input = load(&args.input)?;
    let started = Instant::now();
    let outcome = match args.method {
        Method::NormalDeviation => normal_deviation(&input, &args)?,
        Method::Melax => melax(&input, &args)?,
        Method::Voronoi => voronoi(&input, &args)?,
    };
    let seconds = started.elapsed().as_secs_f64();
    format.write(&outcome.mesh, &args.output)?;
    let report = measure(&input, outcome, &args, seconds);
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print_report(&report, &args.output);
    }
    Ok(())
}

/// The mesh as the other commands read it, repaired; a texture is sampled
/// at the vertices, since the simplified mesh keeps per-vertex colour only.
fn load(path: &Path) -> anyhow::Result<IndexedMesh> {
    let source = load_coloured_mesh(path)?;
    if let Some(text) = describe_repair(&source.repair) {
        eprintln!("repair: {text}");
    }
    let mut mesh = source.mesh;
    if let Some(t) = &source.texture {
        eprintln!("texture: sampled at the vertices (the output has per-vertex colour)");
        mesh.colors = Some(vertex_colours_from_texture(&mesh, t));
    }
    Ok(mesh)
}

fn normal_deviation(mesh: &IndexedMesh, args: &SimplifyArgs) -> anyhow::Result<Outcome> {
    let (collapse, name) = match args.collapse {
        CollapseKind::Edge => (Collapse::Edge, "edge"),
        CollapseKind::HalfEdge => (Collapse::HalfEdge, "half-edge"),
        CollapseKind::Triangle => (Collapse::Triangle, "triangle"),
    };
    let (placement, placement_name) = match args.placement {
        PlacementKind::Seed => (Placement::Seed, "seed"),
        PlacementKind::Quadric => (Placement::Quadric, "quadric"),
    };
    let options = SimplifyOptions {
        collapse,
        target: args.target.target()?,
        threshold: args.feature_threshold,
        placement,
        features: match args.features {
            FeaturesKind::Keep => Features::Keep,
            FeaturesKind::Last => Features::Last,
        },
        ..SimplifyOptions::default()
    };
    let out = simplify(mesh, &options)?;
    Ok(Outcome {
        mesh: out.mesh,
        passes: out.passes.len(),
        stopped: match out.stopped {
            StopReason::Target => "target",
            StopReason::NoCandidate => "no-candidate",
            StopReason::MaxPasses => "max-passes",
        },
        collapse: Some(name),
        feature_threshold_degrees: Some(out.threshold_radians.to_degrees()),
        final_feature_threshold_degrees: Some(out.final_threshold_radians.to_degrees()),
        placement: Some(placement_name),
        voronoi: None,
    })
}

fn voronoi(mesh: &IndexedMesh, args: &SimplifyArgs) -> anyhow::Result<Outcome> {
    let t = &args.target;
    let flags = super::simplify_voronoi::TargetFlags {
        radius: t.radius,
        target_vertices: t.target_vertices,
        target_fraction: t.target_fraction,
    };
    let out = super::simplify_voronoi::run(mesh, &args.voronoi, flags)?;
    Ok(Outcome {
        mesh: out.mesh,
        passes: out.rounds,
        stopped: out.stopped,
        collapse: None,
        feature_threshold_degrees: None,
        final_feature_threshold_degrees: None,
        placement: None,
        voronoi: Some(out.report),
    })
}

fn melax(mesh: &IndexedMesh, args: &SimplifyArgs) -> anyhow::Result<Outcome> {
    let out = melax_simplify(mesh, args.target.target()?, args.melax_cost.into())?;
    Ok(Outcome {
        mesh: out.mesh,
        passes: 1,
        stopped: if out.reached {
            "target"
        } else {
            "no-candidate"
        },
        collapse: None,
        feature_threshold_degrees: None,
        final_feature_threshold_degrees: None,
        placement: None,
        voronoi: None,
    })
}

fn measure(
    input: &IndexedMesh,
    outcome: Outcome,
    args: &SimplifyArgs,
    seconds: f64,
) -> SimplifyReport {
    let distance = hausdorff(input, &outcome.mesh, args.hausdorff_samples);
    SimplifyReport {
        method: args.method.name(),
        input: Counts::of(input),
        output: Counts::of(&outcome.mesh),
        hausdorff: distance.relative(),
        hausdorff_samples: args.hausdorff_samples,
        passes: outcome.passes,
        stopped: outcome.stopped,
        seconds,
        collapse: outcome.collapse,
        feature_threshold_degrees: outcome.feature_threshold_degrees,
        final_feature_threshold_degrees: outcome.final_feature_threshold_degrees,
        placement: outcome.placement,
        voronoi: outcome.voronoi,
    }
}

fn print_report(r: &SimplifyReport, output: &Path) {
    println!(
        "{}: {} vertices, {} faces → {} vertices, {} faces in {:.2} s",
        output.display(),
        r.input.vertices,
        r.input.faces,
        r.output.vertices,
        r.output.faces,
        r.seconds,
    );
    let parameters = match (r.collapse, r.feature_threshold_degrees) {
        (Some(c), Some(t)) => {
            let placement = r.placement.unwrap_or("seed");
            let raised = r
                .final_feature_threshold_degrees
                .filter(|&f| f > t)
                .map_or_else(String::new, |f| {
                    format!(", raised to {f:.2}° where features merged more cheaply than the rest or the target needed them")
                });
            format!(" ({c} collapses, {placement} placement, feature threshold {t:.2}°{raised})")
        }
        _ => r
            .voronoi
            .as_ref()
            .map_or_else(String::new, super::simplify_voronoi::describe),
    };
    println!(
        "{}{parameters}: {} passes, stopped: {}",
        r.method, r.passes, r.stopped
    );
    println!(
        "Hausdorff/diagonal {:.6} ({} samples per mesh)",
        r.hausdorff, r.hausdorff_samples
    );
}
