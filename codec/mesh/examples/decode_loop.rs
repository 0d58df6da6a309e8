//! Profiling aid: `cargo run --release -p vitrine-mesh --example decode_loop mesh.ply [decode-runs] [encode-runs]`,
//! or `decode_loop stream.vtr [decode-runs]` to time decoding a stream written before.
//! Encoding runs on one core (as `vitrine-dev bench` times it) unless
//! `VITRINE_PIPELINED=1`; `VITRINE_STREAM_OUT=path` keeps the stream (to
//! compare two builds' bytes, or time decoders on it). `MEMBERS=1` also
//! times, for a charted stream, what each member of a pool with one chart
//! each decodes on its own (`Decoder::refine_only`): the global layers, the
//! cut, and its chart's parts; the slowest is a pool's critical path on a
//! machine with a core per chart, before merging.
use std::time::Instant;
use vitrine_codec::{decode, encode, Decoder, EncodeOptions, Limits, StreamIndex};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};

/// Prints the median of `times` (seconds) and the speed it gives over `vertices`.
fn report(what: &str, mut times: Vec<f64>, vertices: usize) {
    if times.is_empty() {
        return;
    }
    times.sort_by(f64::total_cmp);
    let median = times[times.len() / 2];
    println!(
        "{what} median {:.1} ms = {:.2} Mv/s",
        median * 1e3,
        vertices as f64 / median / 1e6
    );
}

/// Decodes `bytes` (every level) `runs` times and reports the median.
fn time_decodes(bytes: &[u8], runs: usize) {
    let mut times = Vec::new();
    let mut vertices = 0;
    for _ in 0..runs {
        let t = Instant::now();
        let d = decode(bytes, None, Limits::default()).unwrap();
        times.push(t.elapsed().as_secs_f64());
        vertices = std::hint::black_box(d.vertex_count());
    }
    report("decode", times, vertices);
}

/// Every level of `bytes`, refining only the charts in `charts` once the
/// charted layers begin.
fn decode_member(bytes: &[u8], charts: u64) -> Decoder {
    let index = StreamIndex::parse(bytes).unwrap();
    let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
    d.refine_only(charts).unwrap();
    for range in &index.batches {
        d.apply_batch(&bytes[range.clone()]).unwrap();
    }
    d
}

/// Times each one-chart member of a charted stream, and the global layers alone.
fn time_members(bytes: &[u8], runs: usize) {
    let charts = decode(bytes, None, Limits::default())
        .unwrap()
        .chart_count();
    if charts == 0 {
        println!("a plain stream: no members to time");
        return;
    }
    let masks = std::iter::once(("no chart".to_string(), 0u64))
        .chain((0..charts).map(|c| (format!("chart {c}"), 1u64 << c)));
    for (what, mask) in masks {
        let mut times = Vec::new();
        for _ in 0..runs {
            let t = Instant::now();
            let d = decode_member(bytes, mask);
            times.push(t.elapsed().as_secs_f64());
            std::hint::black_box(d.level());
        }
        times.sort_by(f64::total_cmp);
        let d = decode_member(bytes, mask);
        let vertices: usize = (0..charts)
            .filter(|c| mask & (1 << c) != 0)
            .map(|c| d.chart(c).map_or(0, |chart| chart.positions.len() / 3))
            .sum();
        println!(
            "member refining {what} ({vertices} chart vertices at the end): median {:.1} ms",
            times[times.len() / 2] * 1e3
        );
    }
}

fn main() {
    let path = std::env::args().nth(1).expect("mesh path");
    let runs: usize = std::env::args().nth(2).map_or(10, |s| s.parse().unwrap());
    if path.ends_with(".vtr") {
        // A stream written before: decode only (compares decoders on the same bytes).
        let bytes = std::fs::read(&path).unwrap();
        time_decodes(&bytes, runs.max(1));
        if std::env::var_os("MEMBERS").is_some() {
            time_members(&bytes, runs.max(1));
        }
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
    report("encode", encode_times, mesh.positions.len());
    let bytes = e.unwrap().bytes;
    if let Some(out) = std::env::var_os("VITRINE_STREAM_OUT") {
        std::fs::write(out, &bytes).unwrap();
    }
    time_decodes(&bytes, runs);
}
