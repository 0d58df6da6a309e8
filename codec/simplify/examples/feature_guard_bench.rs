//! The feature guard on real scans, guarded against unguarded, at the first
//! level with at least 5 % of the vertices: RMS distance from the
//! original's top-5 %-θ vertices to that level's surface, the 24-view image
//! RMSE, and the connectivity bits of the whole stream.
//!
//!     cargo run --release -p vitrine-simplify --example feature_guard_bench -- [--share S] MESH…

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

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    let mut share = vitrine_simplify::DEFAULT_FEATURE_SHARE;
    if paths.first().is_some_and(|a| a == "--share") && paths.len() > 1 {
        share = paths[1].parse()?;
        paths.drain(..2);
    }
    println!("feature share {share}\n");
    println!("| scan | vertices | level (plain / guarded) | feature RMS, ×diag (plain → guarded) | change | image RMSE (plain → guarded) | connectivity (plain → guarded) | guard build |");
    println!("|---|---|---|---|---|---|---|---|");
    let (mut changes, mut count) = (0.0, 0);
    for path in &paths {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mut mesh, _) = prepare(mesh, &RepairOptions::default())?;
        mesh.colors = None;
        let full = mesh.positions.len();
        let options = EncodeOptions::default();
        let t = Instant::now();
        let q = Quantization::for_positions(&mesh.positions, options.quantization_bits)?;
        let guard =
            FeatureGuard::new(&mesh, &q, FeatureThreshold::MeanPlusTwoSigma).with_share(share);
        let build = t.elapsed().as_secs_f64();
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
        let guarded = Encoder::new(options).guard(&guard).encode(&mesh)?.bytes;
        let p = measure(&plain, full, &features, &images);
        let g = measure(&guarded, full, &features, &images);
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
        let change = g.feature_rms / p.feature_rms - 1.0;
        changes += change;
        count += 1;
        let name = std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path);
        println!(
            "| {name} | {full} | {} ({} v) / {} ({} v) | {:.5} → {:.5} | {:+.1} % | {:.4} → {:.4} | {} → {} b ({:+.2} %) | {build:.2} s, {} feature vertices |",
            p.level,
            p.vertices,
            g.level,
            g.vertices,
            p.feature_rms / diagonal,
            g.feature_rms / diagonal,
            100.0 * change,
            p.image_rmse,
            g.image_rmse,
            p.connectivity_bits,
            g.connectivity_bits,
            100.0 * (g.connectivity_bits as f64 / p.connectivity_bits as f64 - 1.0),
            guard.feature_vertices(),
        );
    }
    if count > 0 {
        println!(
            "\nmean change of the feature RMS: {:+.1} %",
            100.0 * changes / count as f64
        );
    }
    Ok(())
}
