//! The feature guard on real scans, guarded against unguarded, at the first
//! level with at least 5 % of the vertices: RMS distance from the
//! original's top-5 %-θ vertices to that level's surface, the 24-view image
//! RMSE, and the connectivity bits of the whole stream.
//!
//!     cargo run --release -p vitrine-simplify --example feature_guard_bench -- [--variant SHARE[:GATE]]… MESH…
//!
//! Each `--variant` is measured against the same plain stream (default:
//! the guard's defaults); `--share S` is `--variant S`.

use std::time::Instant;

use glam::DVec3;
use vitrine_codec::{
    breakdown, EncodeOptions, Encoder, IndexedMesh, Limits, Quantization, StreamIndex,
};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_quality::metrics::{
    distances_to_surface, ConstantColour, ImageReference, RenderOptions,
};
use vitrine_simplify::{normal_deviation, FeatureGuard, FeatureThreshold};

struct Measured {
    level: usize,
    vertices: usize,
    feature_rms: f64,
    image_rmse: f64,
    connectivity_bits: u64,
}

/// The first level with at least 5 % of the vertices, decoded.
fn level_at_five_percent(stream: &[u8], full: usize) -> (usize, IndexedMesh) {
    let index = StreamIndex::parse(stream).expect("stream");
    let level = index
        .header
        .levels
        .iter()
        .position(|l| l.vertices as usize * 20 >= full)
        .expect("the final level has every vertex");
    let mut d =
        vitrine_codec::Decoder::new(&stream[index.base.clone()], Limits::default()).expect("base");
    for range in &index.batches[..level] {
        d.apply_batch(&stream[range.clone()]).expect("batch");
    }
    let mesh = IndexedMesh {
        positions: d
            .positions()
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect(),
        colors: None,
        triangles: d
            .indices()
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    };
    (level, mesh)
}

/// The feature RMS of every level with 2–20 % of the vertices, as
/// (vertices, RMS): the plain stream's curve, to read it at the guarded
/// level's vertex count (the two streams' levels do not line up).
fn rms_curve(stream: &[u8], full: usize, features: &[DVec3]) -> Vec<(f64, f64)> {
    let index = StreamIndex::parse(stream).expect("stream");
    let mut d =
        vitrine_codec::Decoder::new(&stream[index.base.clone()], Limits::default()).expect("base");
    let mut curve = Vec::new();
    for level in 0..index.header.levels.len() {
        if level > 0 {
            d.apply_batch(&stream[index.batches[level - 1].clone()])
                .expect("batch");
        }
        let n = index.header.levels[level].vertices as usize;
        if n * 50 < full || n * 5 > full {
            continue;
        }
        let mesh = IndexedMesh {
            positions: d
                .positions()
                .chunks_exact(3)
                .map(|p| [p[0], p[1], p[2]])
                .collect(),
            colors: None,
            triangles: d
                .indices()
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
        };
        let dist = distances_to_surface(features, &mesh);
        let rms = (dist.iter().map(|x| x * x).sum::<f64>() / dist.len().max(1) as f64).sqrt();
        curve.push((n as f64, rms));
    }
    curve
}

/// `curve` read at `vertices`, linear in log–log between its neighbours
/// (clamped to its ends).
fn at_vertices(curve: &[(f64, f64)], vertices: f64) -> f64 {
    let Some(&first) = curve.first() else {
        return f64::NAN;
    };
    if vertices <= first.0 {
        return first.1;
    }
    for w in curve.windows(2) {
        let ((n0, r0), (n1, r1)) = (w[0], w[1]);
        if vertices <= n1 {
            let t = (vertices.ln() - n0.ln()) / (n1.ln() - n0.ln());
            return (r0.ln() + t * (r1.ln() - r0.ln())).exp();
        }
    }
    curve.last().map_or(f64::NAN, |l| l.1)
}

fn measure(stream: &[u8], full: usize, features: &[DVec3], images: &ImageReference) -> Measured {
    let (level, mesh) = level_at_five_percent(stream, full);
    let d = distances_to_surface(features, &mesh);
    let feature_rms = (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt();
    let connectivity_bits = breakdown(stream)
        .expect("breakdown")
        .iter()
        .map(|l| 8 * u64::from(l.connectivity))
        .sum();
    Measured {
        level,
        vertices: mesh.positions.len(),
        feature_rms,
        image_rmse: images.rmse(&mesh, &ConstantColour::CLAY),
        connectivity_bits,
    }
}

/// A guard setting to measure: the share of a level features may hold,
/// and the relief gate (none: every ranked feature vertex is kept).
#[derive(Clone, Copy)]
struct Variant {
    share: f64,
    gate: Option<f64>,
}

impl std::str::FromStr for Variant {
    type Err = Box<dyn std::error::Error>;

    /// `SHARE` or `SHARE:GATE`, e.g. `0.05` or `0.15:0.1`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let (share, gate) = match s.split_once(':') {
            Some((a, b)) => (a.parse()?, Some(b.parse()?)),
            None => (s.parse()?, None),
        };
        Ok(Variant { share, gate })
    }
}

impl std::fmt::Display for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.gate {
            Some(g) => write!(f, "share {}, relief gate {g}", self.share),
            None => write!(f, "share {}, no relief gate", self.share),
        }
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut variants: Vec<Variant> = Vec::new();
    while args
        .first()
        .is_some_and(|a| a == "--share" || a == "--variant")
        && args.len() > 1
    {
        variants.push(args[1].parse()?);
        args.drain(..2);
    }
    if variants.is_empty() {
        variants.push(Variant {
            share: vitrine_simplify::DEFAULT_FEATURE_SHARE,
            gate: vitrine_simplify::DEFAULT_RELIEF_GATE,
        });
    }
    let mut rows: Vec<Vec<String>> = vec![Vec::new(); variants.len()];
    let mut changes = vec![(0.0, 0.0, 0usize, 0usize, 0.0); variants.len()];
    for path in &args {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mut mesh, _) = prepare(mesh, &RepairOptions::default())?;
        mesh.colors = None;
        let full = mesh.positions.len();
        let options = EncodeOptions::default();
        let q = Quantization::for_positions(&mesh.positions, options.quantization_bits)?;
        let theta = normal_deviation(&mesh);
        let cut = FeatureThreshold::Percentile(95.0).radians(&theta);
        let features: Vec<DVec3> = mesh
            .positions
            .iter()
            .zip(&theta)
            .filter(|(_, &t)| t >= cut)
            .map(|(p, _)| DVec3::from(p.map(f64::from)))
            .collect();
        let images = ImageReference::new(&mesh, &ConstantColour::CLAY, &RenderOptions::square(256));
        let plain = Encoder::new(options.clone()).encode(&mesh)?.bytes;
        let p = measure(&plain, full, &features, &images);
        let plain_curve = rms_curve(&plain, full, &features);
        let diagonal = {
            let (lo, hi) = mesh
                .positions
                .iter()
                .fold((DVec3::MAX, DVec3::MIN), |(lo, hi), p| {
                    let p = DVec3::from(p.map(f64::from));
                    (lo.min(p), hi.max(p))
                });
            (hi - lo).length()
        };
        let name = std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path);
        for (k, variant) in variants.iter().enumerate() {
            let t = Instant::now();
            let guard = FeatureGuard::new(&mesh, &q, FeatureThreshold::MeanPlusTwoSigma)
                .with_share(variant.share)
                .with_relief_gate(variant.gate);
            let build = t.elapsed().as_secs_f64();
            let guarded = Encoder::new(options.clone())
                .guard(&guard)
                .encode(&mesh)?
                .bytes;
            let g = measure(&guarded, full, &features, &images);
            let change = g.feature_rms / p.feature_rms - 1.0;
            let equal = g.feature_rms / at_vertices(&plain_curve, g.vertices as f64) - 1.0;
            let connectivity = g.connectivity_bits as f64 / p.connectivity_bits as f64 - 1.0;
            let c = &mut changes[k];
            c.0 += change;
            c.1 += connectivity;
            c.2 += 1;
            c.3 += usize::from(g.image_rmse <= p.image_rmse);
            c.4 += equal;
            rows[k].push(format!(
                "| {name} | {full} | {} ({} v) / {} ({} v) | {:.5} → {:.5} | {:+.1} % | {:+.1} % | {:.4} → {:.4} | {} → {} b ({:+.2} %) | {build:.2} s, {} feature vertices |",
                p.level,
                p.vertices,
                g.level,
                g.vertices,
                p.feature_rms / diagonal,
                g.feature_rms / diagonal,
                100.0 * change,
                100.0 * equal,
                p.image_rmse,
                g.image_rmse,
                p.connectivity_bits,
                g.connectivity_bits,
                100.0 * connectivity,
                guard.feature_vertices(),
            ));
            eprintln!("{name}: {variant}: {}", rows[k].last().unwrap());
        }
    }
    for (k, variant) in variants.iter().enumerate() {
        println!("## {variant}\n");
        println!("| scan | vertices | level (plain / guarded) | feature RMS, ×diag (plain → guarded) | change | change at equal vertices | image RMSE (plain → guarded) | connectivity (plain → guarded) | guard build |");
        println!("|---|---|---|---|---|---|---|---|---|");
        for row in &rows[k] {
            println!("{row}");
        }
        let (change, connectivity, count, images_no_worse, equal) = changes[k];
        if count > 0 {
            println!(
                "\nmean change of the feature RMS: {:+.1} % (at equal vertices, against the plain stream's levels interpolated: {:+.1} %); mean connectivity {:+.2} %; image RMSE no higher on {images_no_worse} of {count}\n",
                100.0 * change / count as f64,
                100.0 * equal / count as f64,
                100.0 * connectivity / count as f64,
            );
        }
    }
    Ok(())
}
