//! The intrinsic Voronoi simplifier (seed 001) measured three ways:
//!
//! - `hausdorff [--peer scripts/peer_quadric.py] [--radius R]… [--sharp D] MESH…`: at
//!   each radius (default 0.02 and 0.05 of the diagonal), our output's
//!   faces, then the quadric-error peer (fast-simplification) asked for as
//!   many faces, on the very same repaired mesh; symmetric Hausdorff over
//!   the bounding-box diagonal side by side.
//! - `table MESH R…`: the seed's Tabela 4.2 configurations (Dijkstra or
//!   fast marching × incremental, farthest or curvature order) at each r:
//!   output triangles, refinement rounds and time per stage.
//! - `timing [FACES|MESH [CODE R]]`: a generated torus of FACES triangles
//!   (default 150 000) or a mesh file, every configuration at r = 0.02 and
//!   0.05, or only CODE (DI, DD, …) at R, so that `time` can give its CPU
//!   seconds.
//!
//! `plate` in place of a mesh is the generated genus-3 plate (sharp creases).
//!
//! Run as:
//!
//!     pip install fast-simplification plyfile numpy
//!     cargo run --release -p vitrine-simplify --example voronoi_bench -- hausdorff \
//!         --peer scripts/peer_quadric.py ../shared/data/meshes/bunny.ply

use std::time::Instant;

use vitrine_codec::IndexedMesh;
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::{
    simplify_voronoi, Distance, Order, Radius, VoronoiOptions, VoronoiSimplified,
};

#[path = "support/mod.rs"]
mod support;
use support::{load, name, peer, ratio, Failure, SAMPLES};

const CONFIGURATIONS: [(&str, Distance, Order); 6] = [
    ("DI", Distance::Dijkstra, Order::Incremental),
    ("DD", Distance::Dijkstra, Order::Farthest),
    ("DC", Distance::Dijkstra, Order::Curvature),
    ("FI", Distance::FastMarching, Order::Incremental),
    ("FD", Distance::FastMarching, Order::Farthest),
    ("FC", Distance::FastMarching, Order::Curvature),
];

fn ours(
    mesh: &IndexedMesh,
    distance: Distance,
    order: Order,
    r: f64,
    sharp_degrees: Option<f64>,
) -> Result<(VoronoiSimplified, f64), Failure> {
    let options = VoronoiOptions {
        distance,
        order,
        radius: Radius::Fraction(r),
        sharp_degrees,
        ..VoronoiOptions::default()
    };
    let t = Instant::now();
    let out = simplify_voronoi(mesh, &options)?;
    Ok((out, t.elapsed().as_secs_f64()))
}

fn hausdorff_table(mut args: Vec<String>) -> Result<(), Failure> {
    let mut script = None;
    let mut radii = Vec::new();
    let mut sharp = VoronoiOptions::default().sharp_degrees;
    while args.len() > 1 && args[0].starts_with("--") {
        match args[0].as_str() {
            "--peer" => script = Some(args[1].clone()),
            "--radius" => radii.push(args[1].parse::<f64>()?),
            // 0: the seed's cover, without creases first.
            "--sharp" => sharp = Some(args[1].parse::<f64>()?).filter(|&d| d > 0.0),
            other => return Err(format!("unknown flag {other}").into()),
        }
        args.drain(..2);
    }
    if radii.is_empty() {
        radii = vec![0.02, 0.05];
    }
    println!("| scan | faces | r | ours (DD): faces, H/diag, s | quadric: faces, H/diag, s | H ours / quadric |");
    println!("|---|---:|---:|---|---|---:|");
    for path in &args {
        let mesh = load(path)?;
        for &r in &radii {
            let (out, s) = ours(&mesh, Distance::Dijkstra, Order::Farthest, r, sharp)?;
            let faces = out.mesh.triangles.len();
            let h = hausdorff(&mesh, &out.mesh, SAMPLES).relative();
            let mut row = format!(
                "| {} | {} | {r} | {faces}, {h:.5}, {s:.2} |",
                name(path),
                mesh.triangles.len()
            );
            match &script {
                Some(script) => {
                    let fraction = faces as f64 / mesh.triangles.len() as f64;
                    let (pf, ph, ps) = peer(script, &mesh, fraction)?;
                    row += &format!(" {pf}, {ph:.5}, {ps:.2} | {} |", ratio(h, ph));
                }
                None => row += " – | – |",
            }
            println!("{row}");
        }
    }
    Ok(())
}

fn configurations(label: &str, mesh: &IndexedMesh, radii: &[f64]) -> Result<(), Failure> {
    for &r in radii {
        for (code, distance, order) in CONFIGURATIONS {
            configuration(label, mesh, code, distance, order, r)?;
        }
    }
    Ok(())
}

fn configuration(
    label: &str,
    mesh: &IndexedMesh,
    code: &str,
    distance: Distance,
    order: Order,
    r: f64,
) -> Result<(), Failure> {
    let (out, s) = ours(
        mesh,
        distance,
        order,
        r,
        VoronoiOptions::default().sharp_degrees,
    )?;
    let st = out.stages;
    println!(
        "| {label} ({}) | {code} | {r} | {} | {} → {} | {} | {:.2} | {:.2} / {:.2} / {:.2} / {:.2} |",
        mesh.triangles.len(),
        out.mesh.triangles.len(),
        out.cover_sites,
        out.sites,
        out.rounds,
        s,
        st.cover.as_secs_f64(),
        st.diagram.as_secs_f64(),
        st.refinement.as_secs_f64(),
        st.dual.as_secs_f64(),
    );
    Ok(())
}

const CONFIG_HEADER: &str = "| mesh (triangles) | method | r | output triangles | sites: cover → final | rounds | total s | cover / diagram / refinement / dual s |\n|---|---|---:|---:|---|---:|---:|---|";

fn main() -> Result<(), Failure> {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    if args.is_empty() {
        return Err("usage: voronoi_bench hausdorff|table|timing …".into());
    }
    let mode = args.remove(0);
    match mode.as_str() {
        "hausdorff" => hausdorff_table(args),
        "table" => {
            let path = args.first().ok_or("table MESH R…")?.clone();
            let radii: Vec<f64> = args[1..]
                .iter()
                .map(|a| a.parse())
                .collect::<Result<_, _>>()?;
            println!("{CONFIG_HEADER}");
            configurations(name(&path), &load(&path)?, &radii)
        }
        "timing" => {
            // FACES makes a generated torus; anything else is a mesh file.
            let first = args.first().cloned().unwrap_or_else(|| "150000".into());
            let (label, mesh) = match first.parse::<u32>() {
                Ok(faces) => {
                    // rings = 1.25 sides, 2 rings sides faces.
                    let sides = ((faces as f64 / 2.5).sqrt()).round() as u32;
                    let rings = faces / (2 * sides);
                    ("torus", vitrine_samples::torus(rings, sides, 1.0, 0.35))
                }
                Err(_) => (name(&first), load(&first)?),
            };
            println!("{CONFIG_HEADER}");
            match (args.get(1), args.get(2)) {
                (Some(code), Some(r)) => {
                    let only: Vec<_> = CONFIGURATIONS.iter().filter(|c| c.0 == code).collect();
                    let &&(code, distance, order) = only.first().ok_or("no such configuration")?;
                    configuration(label, &mesh, code, distance, order, r.parse()?)
                }
                _ => configurations(label, &mesh, &[0.02, 0.05]),
            }
        }
        other => Err(format!("unknown mode {other}").into()),
    }
}
