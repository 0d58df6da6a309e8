//! Writes the viewer's splat fixture: two intersecting unit-ish spheres,
//! red (left) and blue (right), with their normals, as a point stream.
//!
//! ```sh
//! cargo run -p vitrine-points --example splat_fixture -- web/test/fixtures/two-spheres.vpts
//! ```

use vitrine_points::stream::{encode, EncodeOptions};
use vitrine_points::testing::sphere;
use vitrine_points::PointCloud;

fn main() {
    let out = std::env::args()
        .nth(1)
        .expect("usage: splat_fixture OUT.vpts");
    let n = 12_000;
    let (mut positions, mut normals) = sphere(n, [-0.35, 0.0, 0.0], 0.6, 21);
    let (p2, n2) = sphere(n, [0.35, 0.0, 0.0], 0.6, 22);
    positions.extend(p2);
    normals.extend(n2);
    let colours = (0..2 * n)
        .map(|i| if i < n { [220, 30, 30] } else { [30, 30, 220] })
        .collect();
    let cloud = PointCloud {
        origin: [0.0; 3],
        positions,
        normals: Some(normals),
        colours: Some(colours),
    };
    let opts = EncodeOptions {
        bits: 14,
        base_points: 1500,
        ..Default::default()
    };
    let enc = encode(&cloud, &opts).expect("encode");
    std::fs::write(&out, &enc.bytes).expect("write");
    println!(
        "{out}: {} bytes, {} levels, points per level {:?}",
        enc.bytes.len(),
        enc.chunks.len(),
        enc.level_points
    );
}
