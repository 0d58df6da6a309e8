//! Profiling aid: `cargo run --release --example decode_loop mesh.ply [runs]`.
use std::time::Instant;
use vitrine_codec::import::{import_path, ImportOptions};
use vitrine_codec::repair::{prepare, RepairOptions};
use vitrine_codec::{decode, encode, EncodeOptions, Limits};

fn main() {
    let path = std::env::args().nth(1).expect("mesh path");
    let runs: usize = std::env::args().nth(2).map_or(10, |s| s.parse().unwrap());
    let mesh = prepare(
        import_path(path.as_ref(), &ImportOptions::default()).unwrap(),
        &RepairOptions::default(),
    )
    .unwrap()
    .0;
    let t = Instant::now();
    let e = encode(&mesh, &EncodeOptions::default()).unwrap();
    println!("encode {:.1} ms", t.elapsed().as_secs_f64() * 1e3);
    let mut times = Vec::new();
    for _ in 0..runs {
        let t = Instant::now();
        let d = decode(&e.bytes, None, Limits::default()).unwrap();
        times.push(t.elapsed().as_secs_f64());
        std::hint::black_box(d.indices().len());
    }
    times.sort_by(f64::total_cmp);
    let n = mesh.positions.len() as f64;
    println!(
        "decode median {:.1} ms = {:.2} Mv/s",
        times[runs / 2] * 1e3,
        n / times[runs / 2] / 1e6
    );
}
