//! Point-stream size and native decode time for the vertices of PLY/LAS
//! files, positions only (and with normals where the file has them):
//!
//! ```sh
//! cargo run --release -p vitrine-points --example stream_size -- 12 [--write DIR] scan.ply ...
//! ```
//! Prints: file, points, bits, bytes, bits per point, decode ms (median of 5).
//! With `--write DIR`, also writes DIR/scan.vpts (positions only) and
//! DIR/scan.f32 (the imported positions, x y z little-endian f32), which
//! `scripts/peer_draco_points.py` encodes with Draco for
//! `web/bench/points-decode.mjs`.

use std::time::Instant;

use vitrine_points::import::import_path;
use vitrine_points::stream::{decode, encode, EncodeOptions, Limits};

fn main() {
    let mut args = std::env::args().skip(1);
    let bits: u8 = args
        .next()
        .and_then(|a| a.parse().ok())
        .expect("usage: stream_size BITS FILE...");
    let mut paths: Vec<String> = args.collect();
    let write = paths.iter().position(|a| a == "--write").map(|i| {
        let dir = paths.get(i + 1).expect("--write DIR").clone();
        paths.drain(i..i + 2);
        std::path::PathBuf::from(dir)
    });
    println!("file\tpoints\tbits\tattrs\tbytes\tbits_per_point\tdecode_ms");
    for path in paths {
        let cloud = import_path(path.as_ref(), 100_000_000).expect("import");
        let name = std::path::Path::new(&path)
            .file_name()
            .unwrap()
            .to_string_lossy()
            .to_string();
        let mut variants = vec![("positions", false)];
        if cloud.normals.is_some() {
            variants.push(("normals", true));
        }
        for (label, normals) in variants {
            let opts = EncodeOptions {
                bits,
                normals,
                colours: false,
                ..Default::default()
            };
            let enc = encode(&cloud, &opts).expect("encode");
            if let (Some(dir), false) = (&write, normals) {
                let stem = dir.join(std::path::Path::new(&name).with_extension(""));
                std::fs::write(stem.with_extension("vpts"), &enc.bytes).expect("write");
                let raw: Vec<u8> = cloud
                    .positions
                    .iter()
                    .flatten()
                    .flat_map(|v| v.to_le_bytes())
                    .collect();
                std::fs::write(stem.with_extension("f32"), raw).expect("write");
            }
            let mut times: Vec<f64> = (0..5)
                .map(|_| {
                    let t = Instant::now();
                    let d = decode(&enc.bytes, None, Limits::default()).expect("decode");
                    std::hint::black_box(d.point_count());
                    t.elapsed().as_secs_f64() * 1e3
                })
                .collect();
            times.sort_by(f64::total_cmp);
            println!(
                "{name}\t{}\t{bits}\t{label}\t{}\t{:.2}\t{:.1}",
                cloud.len(),
                enc.bytes.len(),
                enc.bytes.len() as f64 * 8.0 / cloud.len() as f64,
                times[2]
            );
        }
    }
}
