//! Profiling aid: `cargo run --release --example decode_loop mesh.ply [decode-runs] [encode-runs]`,
//! or `decode_loop stream.vtr [decode-runs]` to time decoding a stream written before.
//! Encoding runs on one core (as `vitrine bench` times it) unless
//! `VITRINE_PIPELINED=1`.
use std::time::Instant;
use vitrine_codec::import::{import_path, ImportOptions};
use vitrine_codec::repair::{prepare, RepairOptions};
use vitrine_codec::{decode, encode, EncodeOptions, Limits};

fn main() {
    let path = std::env::args().nth(1).expect("mesh path");
    let runs: usize = std::env::args().nth(2).map_or(10, |s| s.parse().unwrap());
    if path.ends_with(".vtr") {
        // A stream written before: decode only (compares decoders on the same bytes).
        let bytes = std::fs::read(&path).unwrap();
        let mut times = Vec::new();
        let mut n = 0;
        for _ in 0..runs.max(1) {
            let t = Instant::now();
            let d = decode(&bytes, None, Limits::default()).unwrap();
            times.push(t.elapsed().as_secs_f64());
            n = d.vertex_count();
        }
        times.sort_by(f64::total_cmp);
        let median = times[times.len() / 2];
        println!(
            "decode median {:.1} ms = {:.2} Mv/s",
            median * 1e3,
            n as f64 / median / 1e6
        );
        return;
    }
    let mesh = prepare(
        import_path(path.as_ref(), &ImportOptions::default()).unwrap(),
        &RepairOptions::default(),
    )
    .unwrap()
    .0;
    let encode_runs: usize = std::env::args().nth(3).map_or(1, |s| s.parse().unwrap());
    let options = EncodeOptions {
        pipelined: std::env::var_os("VITRINE_PIPELINED").is_some(),
        ..EncodeOptions::default()
    };
    let mut encode_times = Vec::new();
    let mut e = None;
    for _ in 0..encode_runs.max(1) {
        let t = Instant::now();
        e = Some(encode(&mesh, &options).unwrap());
        encode_times.push(t.elapsed().as_secs_f64());
    }
    let e = e.unwrap();
    encode_times.sort_by(f64::total_cmp);
    let median = encode_times[encode_times.len() / 2];
    println!(
        "encode median {:.1} ms = {:.2} Mv/s",
        median * 1e3,
        mesh.positions.len() as f64 / median / 1e6
    );
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let d = decode(&e.bytes, None, Limits::default()).unwrap();
        times.push(t.elapsed().as_secs_f64());
        std::hint::black_box(d.indices().len());
    }
    if runs == 0 {
        return;
    }
    times.sort_by(f64::total_cmp);
    let n = mesh.positions.len() as f64;
    println!(
        "decode median {:.1} ms = {:.2} Mv/s",
        times[runs / 2] * 1e3,
        n / times[runs / 2] / 1e6
    );
}
