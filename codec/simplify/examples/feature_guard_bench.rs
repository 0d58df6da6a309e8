//! The feature guard on real scans, guarded against unguarded, at the first
//! level with at least 5 % of the vertices: RMS distance from the
//! original's top-5 %-θ vertices to that level's surface, the 24-view image
//! RMSE, and the connectivity bits of the whole stream.
//!
//!     cargo run --release -p vitrine-simplify --example feature_guard_bench -- [--variant auto|SHARE[:GATE]]… MESH…
//!
//! Each `--variant` is measured against the same plain stream; `auto` (the
//! default) is the encoder's per-scan search (`search_feature_guard`), a
//! number a fixed setting. The two streams' levels do not line up, so the
//! changes are also given against the plain stream's levels interpolated
//! (log–log) at the guarded level's vertex count.

use std::time::Instant;

use vitrine_codec::{EncodeOptions, Encoder, IndexedMesh, Quantization};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_simplify::{
    at_vertices, level_curve, search_feature_guard, FeatureGuard, FeatureProbe, FeatureThreshold,
    GuardSetting, LevelMeasure, DEFAULT_CONNECTIVITY_BUDGET,
};

/// One guard to measure.
#[derive(Clone, Copy)]
enum Variant {
    /// The encoder's per-scan search.
    Auto,
    Fixed(GuardSetting),
}

impl std::str::FromStr for Variant {
    type Err = Box<dyn std::error::Error>;

    /// `auto`, `SHARE` or `SHARE:GATE`, e.g. `0.05` or `0.15:0.1`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        if s == "auto" {
            return Ok(Variant::Auto);
        }
        let (share, relief_gate) = match s.split_once(':') {
            Some((a, b)) => (a.parse()?, Some(b.parse()?)),
            None => (s.parse()?, None),
        };
        Ok(Variant::Fixed(GuardSetting { share, relief_gate }))
    }
}

impl std::fmt::Display for Variant {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Variant::Auto => write!(f, "auto (per-scan search)"),
            Variant::Fixed(s) => s.fmt(f),
        }
    }
}

/// Sums over the scans of one variant.
#[derive(Clone, Default)]
struct Totals {
    rms_change: f64,
    rms_change_equal: f64,
    connectivity: f64,
    connectivity_max: f64,
    over_budget: usize,
    images_no_higher: usize,
    images_no_higher_equal: usize,
    scans: usize,
}

fn diagonal(mesh: &IndexedMesh) -> f64 {
    let (lo, hi) =
        mesh.positions
            .iter()
            .fold((glam::DVec3::MAX, glam::DVec3::MIN), |(lo, hi), p| {
                let p = glam::DVec3::from(p.map(f64::from));
                (lo.min(p), hi.max(p))
            });
    (hi - lo).length()
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
        variants.push(Variant::Auto);
    }
    let mut rows: Vec<Vec<String>> = vec![Vec::new(); variants.len()];
    let mut totals = vec![Totals::default(); variants.len()];
    for path in &args {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mut mesh, _) = prepare(mesh, &RepairOptions::default())?;
        mesh.colors = None;
        let full = mesh.positions.len();
        let options = EncodeOptions::default();
        let q = Quantization::for_positions(&mesh.positions, options.quantization_bits)?;
        let probe = FeatureProbe::new(&mesh);
        let plain = Encoder::new(options.clone()).encode(&mesh)?.bytes;
        let p = probe.measure(&plain)?;
        let rms_curve = level_curve(&plain, full, |m| probe.feature_rms(m))?;
        let image_curve = level_curve(&plain, full, |m| probe.image_rmse(m))?;
        let diagonal = diagonal(&mesh);
        let name = std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path);
        for (k, variant) in variants.iter().enumerate() {
            let t = Instant::now();
            let (g, setting): (LevelMeasure, String) = match variant {
                Variant::Fixed(s) => {
                    let guard = FeatureGuard::new(&mesh, &q, FeatureThreshold::MeanPlusTwoSigma)
                        .with_share(s.share)
                        .with_relief_gate(s.relief_gate);
                    let stream = Encoder::new(options.clone())
                        .guard(&guard)
                        .encode(&mesh)?
                        .bytes;
                    (probe.measure(&stream)?, s.to_string())
                }
                Variant::Auto => {
                    let base = FeatureGuard::new(&mesh, &q, FeatureThreshold::MeanPlusTwoSigma);
                    let (_, search) =
                        search_feature_guard(&mesh, &options, &base, DEFAULT_CONNECTIVITY_BUDGET)?;
                    match search.choice() {
                        Some((s, m)) => (*m, s.to_string()),
                        None => (search.plain, "declined (plain stream)".into()),
                    }
                }
            };
            let seconds = t.elapsed().as_secs_f64();
            let change = g.feature_rms / p.feature_rms - 1.0;
            let equal = g.feature_rms / at_vertices(&rms_curve, g.vertices as f64) - 1.0;
            let image_equal = at_vertices(&image_curve, g.vertices as f64);
            let connectivity = g.connectivity_bits as f64 / p.connectivity_bits as f64 - 1.0;
            let c = &mut totals[k];
            c.rms_change += change;
            c.rms_change_equal += equal;
            c.connectivity += connectivity;
            c.connectivity_max = c.connectivity_max.max(connectivity);
            c.over_budget += usize::from(connectivity > DEFAULT_CONNECTIVITY_BUDGET);
            c.images_no_higher += usize::from(g.image_rmse <= p.image_rmse);
            c.images_no_higher_equal += usize::from(g.image_rmse <= image_equal);
            c.scans += 1;
            rows[k].push(format!(
                "| {name} | {full} | {setting} | {} ({} v) / {} ({} v) | {:.5} → {:.5} | {:+.1} % | {:+.1} % | {:.4} → {:.4} (plain at equal vertices {image_equal:.4}) | {} → {} b ({:+.2} %) | {seconds:.2} s |",
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
            ));
            eprintln!("{name}: {variant}: {}", rows[k].last().unwrap());
        }
    }
    for (k, variant) in variants.iter().enumerate() {
        println!("## {variant}\n");
        println!("| scan | vertices | setting | level (plain / guarded) | feature RMS, ×diag (plain → guarded) | change | change at equal vertices | image RMSE (plain → guarded) | connectivity (plain → guarded) | guard: build and encode |");
        println!("|---|---|---|---|---|---|---|---|---|---|");
        for row in &rows[k] {
            println!("{row}");
        }
        let c = &totals[k];
        if c.scans > 0 {
            let n = c.scans as f64;
            println!(
                "\nmean change of the feature RMS: {:+.1} % (at equal vertices: {:+.1} %); connectivity mean {:+.2} %, max {:+.2} %, {} of {} over +{:.0} %; image RMSE no higher on {} of {} ({} at equal vertices)\n",
                100.0 * c.rms_change / n,
                100.0 * c.rms_change_equal / n,
                100.0 * c.connectivity / n,
                100.0 * c.connectivity_max,
                c.over_budget,
                c.scans,
                100.0 * DEFAULT_CONNECTIVITY_BUDGET,
                c.images_no_higher,
                c.scans,
                c.images_no_higher_equal,
            );
        }
    }
    Ok(())
}
