//! The normal-deviation simplifier (each collapse variant, with the seed's
//! placement and with quadric placement) at 10 %, 5 % and 1 % of the faces,
//! beside a quadric-error peer on the very same repaired mesh: symmetric
//! Hausdorff over the bounding-box diagonal, and time.
//!
//!     pip install fast-simplification plyfile numpy
//!     cargo run --release -p vitrine-simplify --example simplify_bench -- \
//!         [--peer scripts/peer_quadric.py] MESH…

use std::time::Instant;

use vitrine_codec::IndexedMesh;
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::{simplify, Collapse, Placement, SimplifyOptions, StopReason, Target};

#[path = "support/mod.rs"]
mod support;
use support::{peer, SAMPLES};

const FRACTIONS: [f64; 3] = [0.10, 0.05, 0.01];

/// One simplifier's result: faces, Hausdorff over the diagonal, seconds, how it stopped.
fn ours(
    mesh: &IndexedMesh,
    collapse: Collapse,
    placement: Placement,
    fraction: f64,
) -> (usize, f64, f64, &'static str) {
    let options = SimplifyOptions {
        collapse,
        placement,
        target: Target::Fraction(fraction),
        ..SimplifyOptions::default()
    };
    let t = Instant::now();
    let out = simplify(mesh, &options).expect("simplifies");
    let seconds = t.elapsed().as_secs_f64();
    let stopped = match out.stopped {
        StopReason::Target => "target",
        StopReason::NoCandidate => "no candidate",
        StopReason::MaxPasses => "max passes",
    };
    let h = hausdorff(mesh, &out.mesh, SAMPLES).relative();
    (out.mesh.triangles.len(), h, seconds, stopped)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    let mut script = None;
    if paths.first().is_some_and(|a| a == "--peer") && paths.len() > 1 {
        script = Some(paths[1].clone());
        paths.drain(..2);
    }
    println!(
        "| scan | faces | kept | placement | edge: faces, H/diag, s | half-edge | triangle | quadric peer |"
    );
    println!("|---|---:|---:|---|---|---|---|---|");
    for path in &paths {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mesh, _) = prepare(mesh, &RepairOptions::default())?;
        let name = std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path);
        for fraction in FRACTIONS {
            let peer = match &script {
                Some(script) => {
                    let (faces, h, s) = peer(script, &mesh, fraction)?;
                    format!(" {faces}, {h:.5}, {s:.2} |")
                }
                None => " – |".to_string(),
            };
            for (placement, label) in [(Placement::Seed, "seed"), (Placement::Quadric, "quadric")] {
                let mut row = format!(
                    "| {name} | {} | {:.0} % | {label} |",
                    mesh.triangles.len(),
                    100.0 * fraction
                );
                for collapse in [Collapse::Edge, Collapse::HalfEdge, Collapse::Triangle] {
                    let (faces, h, s, stopped) = ours(&mesh, collapse, placement, fraction);
                    let note = if stopped == "target" {
                        String::new()
                    } else {
                        format!(" ({stopped})")
                    };
                    row += &format!(" {faces}, {h:.5}, {s:.2}{note} |");
                }
                println!("{row}{peer}");
            }
        }
    }
    Ok(())
}
