//! Every simplifier of the seeds beside the quadric-error peer, at 10, 5 and
//! 1 % of the faces, on the same repaired mesh (issue 45's table): the
//! normal-deviation simplifier (seed 004) with each collapse and quadric
//! placement (the CLI's default), Melax's collapses (seed 003, sine crease
//! term) and the intrinsic Voronoi simplifier (seed 001) with Dijkstra and
//! fast-marching distances (farthest-point cover, the radius searched for
//! the vertex count), its vertices at the sites (the seed) or moved by
//! their cells' quadrics. Each cell: Hausdorff over quadric's at the same
//! fraction (symmetric, over the bounding-box diagonal), then faces and
//! seconds; `stopped` where a method cannot reach the count.
//!
//!     pip install fast-simplification plyfile numpy
//!     cargo run --release -p vitrine-simplify --example simplifiers_bench -- \
//!         --peer scripts/peer_quadric.py [--fractions 0.1,0.05,0.01] \
//!         [--methods 2,6,7] [--spacing adaptive] plate MESH…
//!
//! `--methods` picks columns by their index in `METHODS` (all by default);
//! `--spacing` sets the Voronoi columns' `VoronoiSpacing` (`uniform`, the
//! seed's, by default).
//!
//! `plate` is the generated genus-3 plate (flat faces, sharp edges).

use std::time::Instant;

use vitrine_codec::IndexedMesh;
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::melax::{melax_simplify, MelaxCost};
use vitrine_simplify::{
    simplify, simplify_voronoi, Collapse, Distance, Placement, Radius, SimplifyOptions, StopReason,
    Target, VoronoiOptions, VoronoiPlacement, VoronoiSpacing,
};

#[path = "support/mod.rs"]
mod support;
use support::{load, name, peer, ratio, Failure, SAMPLES};

/// One method's output: the mesh, seconds, and whether it reached the count.
type Run = (IndexedMesh, f64, bool);

const METHODS: [&str; 8] = [
    "normal deviation, edge",
    "normal deviation, half-edge",
    "normal deviation, triangle",
    "Melax",
    "Voronoi, Dijkstra",
    "Voronoi, fast marching",
    "Voronoi, Dijkstra, quadric placement",
    "Voronoi, fast marching, quadric placement",
];

fn run(
    method: usize,
    mesh: &IndexedMesh,
    fraction: f64,
    spacing: VoronoiSpacing,
) -> Result<Run, Failure> {
    let started = Instant::now();
    let (out, reached) = match method {
        0..=2 => {
            let collapse = [Collapse::Edge, Collapse::HalfEdge, Collapse::Triangle][method];
            let options = SimplifyOptions {
                collapse,
                placement: Placement::Quadric,
                target: Target::Fraction(fraction),
                ..SimplifyOptions::default()
            };
            let out = simplify(mesh, &options)?;
            (out.mesh, out.stopped == StopReason::Target)
        }
        3 => {
            let out = melax_simplify(mesh, Target::Fraction(fraction), MelaxCost::Sine)?;
            (out.mesh, out.reached)
        }
        _ => {
            let distance = [Distance::Dijkstra, Distance::FastMarching][method % 2];
            let placement = if method >= 6 {
                VoronoiPlacement::Quadric
            } else {
                VoronoiPlacement::Sites
            };
            let used = used_vertices(mesh);
            let want = ((fraction * used as f64).round() as usize).max(4);
            let options = VoronoiOptions {
                distance,
                radius: Radius::TargetVertices(want),
                placement,
                spacing,
                ..VoronoiOptions::default()
            };
            let out = simplify_voronoi(mesh, &options)?;
            // The dual keeps the topology, so it stops near the count, not on it.
            let near = out.mesh.positions.len().abs_diff(want) * 10 <= want;
            (out.mesh, near)
        }
    };
    Ok((out, started.elapsed().as_secs_f64(), reached))
}

fn used_vertices(mesh: &IndexedMesh) -> usize {
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.triangles.iter().flatten() {
        used[v as usize] = true;
    }
    used.iter().filter(|&&u| u).count()
}

fn main() -> Result<(), Failure> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut script = None;
    let mut fractions = vec![0.10, 0.05, 0.01];
    let mut methods: Vec<usize> = (0..METHODS.len()).collect();
    let mut spacing = VoronoiSpacing::Uniform;
    while args.len() > 1 && args[0].starts_with("--") {
        match args[0].as_str() {
            "--peer" => script = Some(args[1].clone()),
            "--methods" => {
                methods = args[1]
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?
            }
            "--spacing" => spacing = args[1].parse()?,
            "--fractions" => {
                fractions = args[1]
                    .split(',')
                    .map(str::parse)
                    .collect::<Result<_, _>>()?
            }
            other => return Err(format!("unknown flag {other}").into()),
        }
        args.drain(..2);
    }
    let script =
        script.ok_or("--peer scripts/peer_quadric.py is needed: cells are ratios to it")?;
    if let Some(m) = methods.iter().find(|&&m| m >= METHODS.len()) {
        return Err(format!("no method {m}: 0–{}", METHODS.len() - 1).into());
    }
    let names: Vec<&str> = methods.iter().map(|&m| METHODS[m]).collect();
    println!(
        "| scan | kept | quadric: faces, H, s | {} |",
        names.join(" | ")
    );
    println!("|---|---:|---|{}", "---|".repeat(methods.len()));
    for path in &args {
        let mesh = load(path)?;
        for &fraction in &fractions {
            let (pf, ph, ps) = peer(&script, &mesh, fraction)?;
            let mut row = format!(
                "| {} | {:.0} % | {pf}, {ph:.5}, {ps:.2} |",
                name(path),
                100.0 * fraction
            );
            for &method in &methods {
                row += &match run(method, &mesh, fraction, spacing) {
                    Ok((out, seconds, reached)) => {
                        let h = hausdorff(&mesh, &out, SAMPLES).relative();
                        let stopped = if reached { "" } else { ", stopped" };
                        format!(
                            " {} ({}, {seconds:.2} s{stopped}) |",
                            ratio(h, ph),
                            out.triangles.len()
                        )
                    }
                    Err(e) => format!(" error: {e} |"),
                };
            }
            println!("{row}");
        }
    }
    Ok(())
}
