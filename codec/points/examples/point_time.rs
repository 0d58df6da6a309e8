//! Encode and decode time of each point-stream version on a cloud sampled
//! on a mesh's triangles (the sample of `point_bytes`), positions only, and
//! a hash of each stream's bytes (to check that a faster coder writes the
//! same bytes):
//!
//! ```sh
//! cargo run --release -p vitrine-points --example point_time -- MESH [POINTS] [RUNS] [VERSIONS]
//! ```
//! Prints, for 12 and 14 bits and each version (VERSIONS: a comma list,
//! default all; e.g. `3` alone to count one version's instructions under
//! callgrind): bytes, fnv1a64 of the bytes, encode and decode ms (median of
//! RUNS, default 7, the versions interleaved run by run so that load on a
//! shared machine falls on all), and decode time against the first listed.

use std::time::Instant;

use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_points::stream::{decode, encode, EncodeOptions, Limits, VERSIONS};
use vitrine_points::testing::sample_triangles;
use vitrine_points::PointCloud;

fn fnv1a64(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

fn ms(f: impl FnOnce()) -> f64 {
    let s = Instant::now();
    f();
    s.elapsed().as_secs_f64() * 1e3
}

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .expect("usage: point_time MESH [POINTS] [RUNS]");
    let n: usize = args.get(1).map_or(300_000, |a| a.parse().expect("POINTS"));
    let runs: usize = args.get(2).map_or(7, |a| a.parse().expect("RUNS"));
    let versions: Vec<u8> = args.get(3).map_or(VERSIONS.collect(), |a| {
        a.split(',').map(|v| v.parse().expect("VERSIONS")).collect()
    });
    let mesh = import_path(path.as_ref(), &ImportOptions::default()).expect("import");
    let cloud = PointCloud::from_positions(sample_triangles(
        &mesh.positions,
        &mesh.triangles,
        n,
        0x5eed,
    ));
    let name = std::path::Path::new(path)
        .file_stem()
        .unwrap()
        .to_string_lossy()
        .to_string();
    println!("cloud\tpoints\tbits\tversion\tbytes\tfnv1a64\tencode_ms\tdecode_ms\tdecode_vs_first");
    for bits in [12u8, 14] {
        let opts = |version| EncodeOptions {
            bits,
            version,
            ..Default::default()
        };
        let streams: Vec<_> = versions
            .iter()
            .map(|&v| encode(&cloud, &opts(v)).expect("encode"))
            .collect();
        for s in &streams {
            let d = decode(&s.bytes, None, Limits::default()).expect("decode");
            assert_eq!(d.quantized(), &s.quantized[..], "round trip");
        }
        let mut enc_ms = vec![Vec::new(); streams.len()];
        let mut dec_ms = vec![Vec::new(); streams.len()];
        for _ in 0..runs {
            for (i, &v) in versions.iter().enumerate() {
                enc_ms[i].push(ms(|| {
                    std::hint::black_box(encode(&cloud, &opts(v)).expect("encode"));
                }));
                dec_ms[i].push(ms(|| {
                    let d = decode(&streams[i].bytes, None, Limits::default()).expect("decode");
                    std::hint::black_box(d.point_count());
                }));
            }
        }
        let first_decode = median(dec_ms[0].clone());
        for (i, v) in versions.iter().enumerate() {
            let decode_ms = median(dec_ms[i].clone());
            println!(
                "{name}\t{n}\t{bits}\tv{v}\t{}\t{:016x}\t{:.0}\t{decode_ms:.0}\t{:.2}",
                streams[i].bytes.len(),
                fnv1a64(&streams[i].bytes),
                median(enc_ms[i].clone()),
                decode_ms / first_decode,
            );
        }
    }
}
