use glam::DVec3;
use vitrine_quality::metrics::distances_to_surface;
use vitrine_quality::metrics::hausdorff;
use vitrine_simplify::*;
#[path = "support/mod.rs"]
mod support;
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mesh = support::load(&a[0]).unwrap();
    let fraction: f64 = a[1].parse().unwrap();
    let spacing: VoronoiSpacing = a[2].parse().unwrap();
    let used = mesh.positions.len();
    let want = (fraction * used as f64).round() as usize;
    let o = VoronoiOptions { radius: Radius::TargetVertices(want), placement: VoronoiPlacement::Quadric, spacing, ..VoronoiOptions::default() };
    let out = simplify_voronoi(&mesh, &o).unwrap();
    let h = hausdorff(&mesh, &out.mesh, support::SAMPLES);
    println!("H {:.5} a->b {:.5} b->a {:.5} diag {:.3} r {:.5} sites {} cover {} splits {} rounds {}", h.relative(), h.a_to_b / h.diagonal, h.b_to_a / h.diagonal, h.diagonal, out.radius_fraction, out.sites, out.cover_sites, out.splits, out.rounds);
    let pts: Vec<DVec3> = mesh.positions.iter().map(|p| DVec3::from_array(p.map(f64::from))).collect();
    let d = distances_to_surface(&pts, &out.mesh);
    let mut idx: Vec<usize> = (0..d.len()).collect();
    idx.sort_by(|&x, &y| d[y].total_cmp(&d[x]));
    for &i in idx.iter().take(8) { println!("in->out v{i} {:.5} at {:?}", d[i] / h.diagonal, mesh.positions[i]); }
    let pts: Vec<DVec3> = out.mesh.positions.iter().map(|p| DVec3::from_array(p.map(f64::from))).collect();
    let d = distances_to_surface(&pts, &mesh);
    let mut idx: Vec<usize> = (0..d.len()).collect();
    idx.sort_by(|&x, &y| d[y].total_cmp(&d[x]));
    for &i in idx.iter().take(4) { println!("out->in o{i} {:.5} at {:?}", d[i] / h.diagonal, out.mesh.positions[i]); }
}
