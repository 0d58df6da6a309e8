//! Bytes per component of the point stream for a cloud sampled on a mesh's
//! triangles (area-weighted, seeded), as a positions-only scan arrives:
//!
//! ```sh
//! cargo run --release -p vitrine-points --example point_bytes -- MESH [POINTS] [--write DIR] [--positions-only]
//! ```
//! For 12 and 14 bits and each stream version, prints positions-only bytes,
//! the bytes that normals (estimated as at ingest) add, encode and decode ms
//! (median of 3), and (stderr) the time normal estimation takes. Colours: the
//! sampled cloud has none (0 bytes). With
//! `--write DIR`, writes DIR/NAME-POINTS.f32 (x y z little-endian f32) for
//! the Draco comparison. With `--positions-only`, only the positions' bytes
//! (each version's stream decoded once to check it; no normals, no times).

use std::time::Instant;

use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_points::stream::{decode, encode, EncodeOptions, EncodedPoints, Limits, VERSIONS};
use vitrine_points::testing::sample_triangles;
use vitrine_points::{estimate_normals, PointCloud, DEFAULT_K};

fn median_ms(mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..3)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[1]
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let write = args.iter().position(|a| a == "--write").map(|i| {
        let dir = args.get(i + 1).expect("--write DIR").clone();
        args.drain(i..i + 2);
        std::path::PathBuf::from(dir)
    });
    let positions_only = args.iter().position(|a| a == "--positions-only").map(|i| {
        args.remove(i);
    });
    let path = args.first().expect("usage: point_bytes MESH [POINTS]");
    let n: usize = args.get(1).map_or(300_000, |a| a.parse().expect("POINTS"));
    let mesh = import_path(path.as_ref(), &ImportOptions::default()).expect("import");
    let positions = sample_triangles(&mesh.positions, &mesh.triangles, n, 0x5eed);
    let name = std::path::Path::new(path)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .to_string();
    if let Some(dir) = &write {
        let raw: Vec<u8> = positions
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        std::fs::write(dir.join(format!("{name}-{n}.f32")), raw).expect("write");
    }
    if positions_only.is_some() {
        let cloud = PointCloud::from_positions(positions);
        println!("cloud\tpoints\tbits\tversion\tposition_bytes\tpos_bits_per_point");
        for bits in [12u8, 14] {
            for version in VERSIONS {
                let (_, pos) = round_trip(&cloud, bits, version);
                println!(
                    "{name}\t{n}\t{bits}\tv{version}\t{}\t{:.2}",
                    pos.bytes.len(),
                    pos.bytes.len() as f64 * 8.0 / n as f64,
                );
            }
        }
        return;
    }
    // What the ingest (and, for a stream without normals, the viewer's
    // WebAssembly session) spends estimating them.
    let started = Instant::now();
    let normals = estimate_normals(&positions, DEFAULT_K);
    eprintln!(
        "estimate_normals: {:.0} ms",
        started.elapsed().as_secs_f64() * 1e3
    );
    let bare = PointCloud::from_positions(positions);
    let with_normals = PointCloud {
        normals: Some(normals),
        ..bare.clone()
    };
    println!("cloud\tpoints\tbits\tversion\tposition_bytes\tpos_bits_per_point\tnormal_bytes\tencode_ms\tdecode_ms");
    for bits in [12u8, 14] {
        for version in VERSIONS {
            let (opts, pos) = round_trip(&bare, bits, version);
            let encode_ms = median_ms(|| {
                std::hint::black_box(encode(&bare, &opts).expect("encode"));
            });
            let decode_ms = median_ms(|| {
                let d = decode(&pos.bytes, None, Limits::default()).expect("decode");
                std::hint::black_box(d.point_count());
            });
            let all = encode(&with_normals, &opts).expect("encode");
            println!(
                "{name}\t{n}\t{bits}\tv{version}\t{}\t{:.2}\t{}\t{encode_ms:.0}\t{decode_ms:.0}",
                pos.bytes.len(),
                pos.bytes.len() as f64 * 8.0 / n as f64,
                all.bytes.len() - pos.bytes.len(),
            );
        }
    }
}

/// The cloud encoded at `bits` in `version`, checked to decode to the same
/// grid points.
fn round_trip(cloud: &PointCloud, bits: u8, version: u8) -> (EncodeOptions, EncodedPoints) {
    let opts = EncodeOptions {
        bits,
        version,
        ..Default::default()
    };
    let pos = encode(cloud, &opts).expect("encode");
    let d = decode(&pos.bytes, None, Limits::default()).expect("decode");
    assert_eq!(d.quantized(), &pos.quantized[..], "round trip");
    (opts, pos)
}
