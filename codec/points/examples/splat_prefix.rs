//! Can a point stream's coarse levels reuse the final level's splat
//! preprocessing (issue 42, "preprocessing once")? A jittered cube with
//! normals, encoded as ingest encodes it (14 bits), its levels decoded;
//! each level drawn three ways by the CPU ray-cast of `testing::raycast`
//! (24 views at 512²), as silhouette error (pixels) and hole pixels:
//!
//! 1. *per level*: the whole preprocessing on the level's points (today's
//!    viewer);
//! 2. *once*: the final level's preprocessing restricted to the level —
//!    surface ids and clip partners as they are, radii scaled by
//!    `prefix_radius_scale`;
//! 3. *radii once*: the level's own clip partners, the final radii scaled.
//!
//! ```sh
//! cargo run --release -p vitrine-points --example splat_prefix -- [POINTS]
//! ```

use vitrine_points::splat::{prefix_radius_scale, preprocess, SplatOptions};
use vitrine_points::stream::{decode, encode, EncodeOptions, Limits};
use vitrine_points::testing::cube;
use vitrine_points::testing::raycast::silhouette_error;
use vitrine_points::PointCloud;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(60_000, |a| a.parse().expect("POINTS"));
    let (positions, normals) = cube(n, 1.0, 5);
    let cloud = PointCloud {
        origin: [0.0; 3],
        positions,
        normals: Some(normals),
        colours: None,
    };
    let options = EncodeOptions {
        bits: 14,
        base_points: 1500,
        ..Default::default()
    };
    let encoded = encode(&cloud, &options).expect("encode");
    let decoded = decode(&encoded.bytes, None, Limits::default()).expect("decode");
    let pos = decoded.positions();
    let nrm = decoded.normals().expect("normals");
    let opts = SplatOptions::default();
    let last = preprocess(pos, nrm, &opts);
    println!("points\tper_level_error\tper_level_holes\tonce_error\tonce_holes\tradii_once_error\tradii_once_holes");
    for &count in &encoded.level_points {
        let k = count as usize;
        let (p, q) = (&pos[..k], &nrm[..k]);
        let own = preprocess(p, q, &opts);
        let scale = prefix_radius_scale(pos.len(), k);
        let scaled: Vec<f32> = last.radii[..k].iter().map(|r| r * scale).collect();
        let (e1, h1) = silhouette_error(p, q, &own, &own.radii);
        let (e2, h2) = silhouette_error(p, q, &last, &scaled);
        let (e3, h3) = silhouette_error(p, q, &own, &scaled);
        println!("{k}\t{e1}\t{h1}\t{e2}\t{h2}\t{e3}\t{h3}");
    }
}
