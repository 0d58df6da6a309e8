//! Melax's collapses at 80, 60, 40 and 20 % of the vertices beside a
//! quadric-error peer at the same face count, on the same repaired mesh:
//! symmetric Hausdorff over the bounding-box diagonal, and time. Melax runs
//! its chain once (to the coarsest level it can reach) for all four levels;
//! the peer runs once per level.
//!
//!     pip install fast-simplification plyfile numpy
//!     cargo run --release -p vitrine-simplify --example melax_bench -- \
//!         [--peer scripts/peer_quadric.py] [--seed-cost] MESH…
//!
//! `--seed-cost` runs the seed's crease term sin²(θ/2) instead of sin(θ/2).

use std::time::Instant;

use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::melax::{compact, melax_chain, MelaxCost, MelaxModel};

#[path = "support/mod.rs"]
mod support;
use support::{peer, SAMPLES};

const PERCENTS: [u32; 4] = [80, 60, 40, 20];

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut paths: Vec<String> = std::env::args().skip(1).collect();
    let mut script = None;
    if paths.first().is_some_and(|a| a == "--peer") && paths.len() > 1 {
        script = Some(paths[1].clone());
        paths.drain(..2);
    }
    let mut cost = MelaxCost::Sine;
    if paths.first().is_some_and(|a| a == "--seed-cost") {
        cost = MelaxCost::Seed;
        paths.remove(0);
    }
    println!("| scan | vertices | level | Melax: vertices, faces, H/diag | quadric peer: faces, H/diag, s | H ratio |");
    println!("|---|---:|---:|---|---|---:|");
    for path in &paths {
        let mesh = import_path(path.as_ref(), &ImportOptions::default())?;
        let (mesh, _) = prepare(mesh, &RepairOptions::default())?;
        let name = std::path::Path::new(path)
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or(path);
        let frames = [mesh.positions.clone()];
        let t = Instant::now();
        let chain = melax_chain(&MelaxModel {
            triangles: &mesh.triangles,
            frames: &frames,
            corner_uvs: None,
            cost,
        })?;
        let seconds = t.elapsed().as_secs_f64();
        for p in PERCENTS {
            let want = chain.percent(p).max(chain.min_vertices());
            let level = chain.level(want)?;
            let (out, _) = compact(&mesh, &level.triangles);
            let h = hausdorff(&mesh, &out, SAMPLES).relative();
            let mut row = format!(
                "| {name} | {} | {p} % | {}, {}, {h:.5} |",
                mesh.positions.len(),
                out.positions.len(),
                out.triangles.len()
            );
            match &script {
                Some(script) => {
                    let fraction = out.triangles.len() as f64 / mesh.triangles.len() as f64;
                    let (faces, hp, s) = peer(script, &mesh, fraction)?;
                    row += &format!(" {faces}, {hp:.5}, {s:.2} | {:.2} |", h / hp);
                }
                None => row += " – | – |",
            }
            println!("{row}");
        }
        println!("| {name} | | chain | Melax, whole chain: {seconds:.2} s | | |");
    }
    Ok(())
}
