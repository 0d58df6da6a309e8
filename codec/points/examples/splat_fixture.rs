//! Writes the viewer's splat fixtures as point streams, with their normals:
//! two intersecting unit-ish spheres, red (left) and blue (right); a
//! jittered cube [−0.5, 0.5]³; the L-shaped block of
//! `vitrine_points::testing::l_block_faces` (a concave crease and two inner
//! corners). The last two are clay grey.
//!
//! ```sh
//! cargo run -p vitrine-points --example splat_fixture -- web/test/fixtures/two-spheres.vpts
//! cargo run -p vitrine-points --example splat_fixture -- cube web/test/fixtures/cube.vpts
//! cargo run -p vitrine-points --example splat_fixture -- l-block web/test/fixtures/l-block.vpts
//! ```

use vitrine_points::stream::{encode, EncodeOptions};
use vitrine_points::testing::{cube, faces_sample, l_block_faces, sphere};
use vitrine_points::PointCloud;

/// Points of the L-block fixture.
const SOLID_POINTS: usize = 24_000;
/// Points of the cube fixture: its faces are larger on screen than the
/// L-block's, and at 24,000 points one pixel on an edge between two faces
/// (seed 31, one of four views) fell in a gap of the random sample, clipped
/// or not.
const CUBE_POINTS: usize = 36_000;

fn two_spheres() -> PointCloud {
    let n = 12_000;
    let (mut positions, mut normals) = sphere(n, [-0.35, 0.0, 0.0], 0.6, 21);
    let (p2, n2) = sphere(n, [0.35, 0.0, 0.0], 0.6, 22);
    positions.extend(p2);
    normals.extend(n2);
    let colours = (0..2 * n)
        .map(|i| if i < n { [220, 30, 30] } else { [30, 30, 220] })
        .collect();
    PointCloud {
        origin: [0.0; 3],
        positions,
        normals: Some(normals),
        colours: Some(colours),
    }
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (shape, out) = match args.as_slice() {
        [out] => ("spheres", out.as_str()),
        [shape, out] => (shape.as_str(), out.as_str()),
        _ => panic!("usage: splat_fixture [spheres|cube|l-block] OUT.vpts"),
    };
    let solid = |(positions, normals): (Vec<[f32; 3]>, Vec<[f32; 3]>)| PointCloud {
        origin: [0.0; 3],
        positions,
        normals: Some(normals),
        colours: None,
    };
    let cloud = match shape {
        "spheres" => two_spheres(),
        "cube" => solid(cube(CUBE_POINTS, 0.5, 31)),
        "l-block" => solid(faces_sample(&l_block_faces(), SOLID_POINTS, 32)),
        _ => panic!("unknown shape {shape}: spheres, cube or l-block"),
    };
    let opts = EncodeOptions {
        bits: 14,
        base_points: 1500,
        ..Default::default()
    };
    let enc = encode(&cloud, &opts).expect("encode");
    std::fs::write(out, &enc.bytes).expect("write");
    println!(
        "{out}: {} bytes, {} levels, points per level {:?}",
        enc.bytes.len(),
        enc.chunks.len(),
        enc.level_points
    );
}
