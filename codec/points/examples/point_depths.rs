//! Where a point stream's position bits go, depth by depth (issue 42):
//!
//! ```sh
//! cargo run --release -p vitrine-points --example point_depths -- MESH POINTS BITS [VERSIONS] [--dump FILE] [--ingest-stream FILE] [--write-streams DIR]
//! ```
//! POINTS > 0 samples that many points on the mesh's triangles (as
//! `point_bytes`); 0 takes the mesh's vertices as the cloud (a scan's own
//! samples). The stream is written with one level per depth (a base of one
//! point) until the count stops growing, so each level's bytes are that
//! depth's. Per level: new points, bytes, bits per new point and per point
//! so far, occupied cells at the level's last depth, the share of them
//! holding one point, and the share with no occupied cell among their 26
//! neighbours. VERSIONS is a comma list (default `1,3`). `--dump FILE`
//! writes the quantized positions (u32 × 3, little-endian, stream order) for
//! `scripts/points-bound.py`; `--ingest-stream FILE` writes the cloud as
//! ingest stores it (normals estimated, default options) for
//! `web/bench/splat-levels.mjs`; `--write-streams DIR` writes, for each
//! version, DIR/NAME-vV.vpts (positions only, default options but `BITS`)
//! and DIR/NAME-vV.f32 (the cloud, x y z little-endian f32) for
//! `scripts/peer_draco_points.py` and `web/bench/points-decode.mjs`.
//! Every stream is decoded and compared.

use std::collections::HashMap;

use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_points::stream::{decode, encode, EncodeOptions, Limits};
use vitrine_points::testing::sample_triangles;
use vitrine_points::{estimate_normals, PointCloud, DEFAULT_K};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let dump = args.iter().position(|a| a == "--dump").map(|i| {
        let file = args.get(i + 1).expect("--dump FILE").clone();
        args.drain(i..i + 2);
        file
    });
    let ingest_stream = args.iter().position(|a| a == "--ingest-stream").map(|i| {
        let file = args.get(i + 1).expect("--ingest-stream FILE").clone();
        args.drain(i..i + 2);
        file
    });
    let write_streams = args.iter().position(|a| a == "--write-streams").map(|i| {
        let dir = args.get(i + 1).expect("--write-streams DIR").clone();
        args.drain(i..i + 2);
        std::path::PathBuf::from(dir)
    });
    let usage =
        "usage: point_depths MESH POINTS BITS [VERSIONS] [--dump FILE] [--ingest-stream FILE] [--write-streams DIR]";
    let path = args.first().expect(usage);
    let n: usize = args.get(1).expect(usage).parse().expect("POINTS");
    let bits: u8 = args.get(2).expect(usage).parse().expect("BITS");
    let versions: Vec<u8> = args
        .get(3)
        .map_or("1,3", String::as_str)
        .split(',')
        .map(|v| v.parse().expect("VERSIONS"))
        .collect();
    let mesh = import_path(path.as_ref(), &ImportOptions::default()).expect("import");
    let positions = if n == 0 {
        mesh.positions.clone()
    } else {
        sample_triangles(&mesh.positions, &mesh.triangles, n, 0x5eed)
    };
    let cloud = PointCloud::from_positions(positions);
    if let Some(file) = &ingest_stream {
        let with_normals = PointCloud {
            normals: Some(estimate_normals(&cloud.positions, DEFAULT_K)),
            ..cloud.clone()
        };
        let encoded = encode(&with_normals, &EncodeOptions::default()).expect("encode");
        std::fs::write(file, &encoded.bytes).expect("write the stream");
        println!(
            "{file}: {} bytes, points per level {:?}",
            encoded.bytes.len(),
            encoded.level_points
        );
    }
    let name = std::path::Path::new(path)
        .file_stem()
        .expect("a file name")
        .to_string_lossy()
        .to_string();
    for (i, &version) in versions.iter().enumerate() {
        if let Some(dir) = &write_streams {
            let options = EncodeOptions {
                bits,
                version,
                ..Default::default()
            };
            let encoded = encode(&cloud, &options).expect("encode");
            let stem = dir.join(format!("{name}-v{version}"));
            std::fs::write(stem.with_extension("vpts"), &encoded.bytes).expect("write");
            let raw: Vec<u8> = cloud
                .positions
                .iter()
                .flatten()
                .flat_map(|v| v.to_le_bytes())
                .collect();
            std::fs::write(stem.with_extension("f32"), raw).expect("write");
        }
        let options = EncodeOptions {
            bits,
            version,
            base_points: 1,
            ..Default::default()
        };
        let encoded = encode(&cloud, &options).expect("encode");
        let decoded = decode(&encoded.bytes, None, Limits::default()).expect("decode");
        assert_eq!(decoded.quantized(), &encoded.quantized[..], "round trip");
        if i == 0 {
            if let Some(file) = &dump {
                let raw: Vec<u8> = encoded
                    .quantized
                    .iter()
                    .flatten()
                    .flat_map(|v| v.to_le_bytes())
                    .collect();
                std::fs::write(file, raw).expect("write the dump");
            }
        }
        println!(
            "v{version}, {bits} bits, {} points: {} bytes",
            cloud.positions.len(),
            encoded.bytes.len()
        );
        println!("level\tdepth\tnew_points\tbytes\tbits_per_new\tbits_per_point\tcells\tsingle_pct\tisolated_pct");
        let mut before = 0u32;
        for (level, chunk) in encoded.chunks.iter().enumerate() {
            let depth = encoded.header.level_depths[level];
            let points = encoded.level_points[level];
            let bytes = chunk.len() - 8;
            let (cells, single, isolated) = occupancy(&encoded.quantized, bits - depth);
            println!(
                "{level}\t{depth}\t{}\t{bytes}\t{:.3}\t{:.3}\t{cells}\t{:.1}\t{:.1}",
                points - before,
                bytes as f64 * 8.0 / f64::from((points - before).max(1)),
                bytes as f64 * 8.0 / f64::from(points),
                100.0 * single as f64 / cells as f64,
                100.0 * isolated as f64 / cells as f64,
            );
            before = points;
        }
    }
}

/// Occupied cells of side 2^`shift`, those holding one point, and those
/// with no occupied cell among their 26 neighbours.
fn occupancy(quantized: &[[u32; 3]], shift: u8) -> (usize, usize, usize) {
    let mut cells: HashMap<[u32; 3], u32> = HashMap::new();
    for q in quantized {
        *cells.entry(q.map(|c| c >> shift)).or_default() += 1;
    }
    let single = cells.values().filter(|&&k| k == 1).count();
    let isolated = cells
        .keys()
        .filter(|c| {
            (0..27).filter(|&i| i != 13).all(|i| {
                let d = [i % 3, i / 3 % 3, i / 9].map(|x| i64::from(x) - 1);
                let at: [i64; 3] = [0, 1, 2].map(|a| i64::from(c[a]) + d[a]);
                at.iter().any(|&x| x < 0) || !cells.contains_key(&at.map(|x| x as u32))
            })
        })
        .count();
    (cells.len(), single, isolated)
}
