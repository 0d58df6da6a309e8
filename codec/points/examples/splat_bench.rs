//! Times splat preprocessing (radii, grid graph, clip partners, surface ids)
//! and normal estimation on generated clouds, single-threaded (`STAGES=1`
//! times each stage, `NO_NORMALS=1` skips normal estimation):
//!
//! ```sh
//! cargo run --release -p vitrine-points --no-default-features --example splat_bench -- 1000000 5
//! ```

use std::time::Instant;

use vitrine_points::estimate_normals;
use vitrine_points::splat::{preprocess, SplatOptions};
use vitrine_points::testing::cube;

/// CPU time of this thread in seconds (Linux; the machine is shared, so
/// wall time overstates what one core needs).
fn cpu_s() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<f64>().ok())
        .map_or(f64::NAN, |ns| ns * 1e-9)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let mut args = std::env::args().skip(1);
    let n: usize = args
        .next()
        .and_then(|a| a.parse().ok())
        .unwrap_or(1_000_000);
    let runs: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(5);
    let (pos, nrm) = cube(n, 1.0, 3);
    // In the order a viewer gets them: decoded from a point stream (level
    // order, each level spatially coherent), not the sampler's random order.
    let (pos, nrm) = if std::env::var_os("RANDOM_ORDER").is_some() {
        (pos, nrm)
    } else {
        let cloud = vitrine_points::PointCloud::from_positions(pos.clone());
        let opts = vitrine_points::stream::EncodeOptions {
            bits: 16,
            ..Default::default()
        };
        let enc = vitrine_points::stream::encode(&cloud, &opts).expect("encode");
        let order = enc.order.iter().map(|&i| i as usize);
        (
            order.clone().map(|i| pos[i]).collect(),
            order.map(|i| nrm[i]).collect(),
        )
    };
    let mut splat_s = Vec::new();
    let mut normal_s = Vec::new();
    for run in 0..runs {
        if std::env::var_os("STAGES").is_some() {
            let t = cpu_s();
            let r = vitrine_points::splat::splat_radii(&pos);
            println!("radii {:.3} s CPU", cpu_s() - t);
            let t = cpu_s();
            let g = vitrine_points::splat::neighbour_graph(&pos, &r);
            println!("graph {:.3} s CPU", cpu_s() - t);
            let t = cpu_s();
            let ids = vitrine_points::splat::surface_ids(&nrm, &g, 0.9);
            println!("ids {:.3} s CPU", cpu_s() - t);
            let t = cpu_s();
            let o = SplatOptions::default();
            let input = vitrine_points::splat::ClipInput {
                positions: &pos,
                normals: &nrm,
                radii: &r,
                surface_ids: &ids,
            };
            let c = vitrine_points::splat::clip::clip_partners(input, &g, &o);
            println!("clip {:.3} s CPU", cpu_s() - t);
            std::hint::black_box((c, ids));
        }
        let (t, c) = (Instant::now(), cpu_s());
        let s = preprocess(&pos, &nrm, &SplatOptions::default());
        let dt = t.elapsed().as_secs_f64();
        let cpu = cpu_s() - c;
        splat_s.push(cpu);
        let partnered = (0..n)
            .filter(|&i| !s.clipping.partners_of(i).is_empty())
            .count();
        println!(
            "run {run}: splats {cpu:.3} s CPU, {dt:.3} s wall ({} edges, {:.1}/splat, {} sharp, {} candidates, {partnered} with partners)",
            s.graph.edge_count(),
            2.0 * s.graph.edge_count() as f64 / n as f64,
            s.sharp_edges,
            s.clipping.candidates,
        );
        if std::env::var_os("NO_NORMALS").is_some() {
            continue;
        }
        let c = cpu_s();
        let est = estimate_normals(&pos, vitrine_points::DEFAULT_K);
        normal_s.push(cpu_s() - c);
        std::hint::black_box(est);
    }
    println!(
        "{n} points, {runs} runs: splat preprocessing median {:.3} s CPU; normal estimation median {:.3} s CPU",
        median(splat_s),
        if normal_s.is_empty() { f64::NAN } else { median(normal_s) }
    );
}
