//! The chart-parallel stream (format 5) against the plain one (format 4):
//! size, encode time, and native decode time on 1, 2 and 4 threads, with
//! every charted stream checked lossless against the input.
//!
//! `cargo run --release -p vitrine-mesh --example charts_bench -- [--per N]... [--runs R] mesh...`
//! (`--per`: one chart per N vertices, repeatable, 0 for `--charts auto`;
//! `--count K`: K charts; default `--per 0`).
use std::time::Instant;
use vitrine_codec::{decode, encode, Charts, Decoder, EncodeOptions, Limits, StreamIndex};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};

fn median(mut times: Vec<f64>) -> f64 {
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// Median seconds to decode every level on `threads` threads.
fn decode_time(bytes: &[u8], threads: usize, runs: usize) -> f64 {
    let index = StreamIndex::parse(bytes).unwrap();
    median(
        (0..runs)
            .map(|_| {
                let t = Instant::now();
                let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
                d.set_threads(threads);
                for r in &index.batches {
                    d.apply_batch(&bytes[r.clone()]).unwrap();
                }
                std::hint::black_box(d.vertex_count());
                t.elapsed().as_secs_f64()
            })
            .collect(),
    )
}

/// The final level in input ids: quantized positions and canonical faces.
fn final_level(bytes: &[u8], order: &[u32]) -> (Vec<[i32; 3]>, Vec<[u32; 3]>) {
    let d = decode(bytes, None, Limits::default()).unwrap();
    let mut positions = vec![[0; 3]; order.len()];
    for (i, &v) in order.iter().enumerate() {
        positions[v as usize] = d.quantized_positions()[i];
    }
    let mut faces: Vec<[u32; 3]> = d
        .indices()
        .chunks_exact(3)
        .map(|t| {
            let t = [
                order[t[0] as usize],
                order[t[1] as usize],
                order[t[2] as usize],
            ];
            let i = (0..3).min_by_key(|&i| t[i]).unwrap();
            [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
        })
        .collect();
    faces.sort_unstable();
    (positions, faces)
}

fn main() {
    let mut per = Vec::new();
    let mut runs = 7;
    let mut paths = Vec::new();
    // `--twin`: each mesh beside a copy of itself along z, so that two
    // charts can fall exactly on the two copies (no cut): what charts cost
    // without a cut.
    let mut twin = false;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--per" => per.push(args.next().expect("--per N").parse::<u32>().unwrap()),
            // `--count K`: K charts whatever the size (stored as u32::MAX - K).
            "--count" => {
                per.push(u32::MAX - args.next().expect("--count K").parse::<u32>().unwrap())
            }
            "--runs" => runs = args.next().expect("--runs R").parse().unwrap(),
            "--twin" => twin = true,
            _ => paths.push(a),
        }
    }
    if per.is_empty() {
        per = vec![0];
    }
    println!("| mesh | vertices | stream | charts | bytes | vs format 4 | encode s | decode 1T ms | 2T ms | 4T ms |");
    println!("|---|---:|---|---:|---:|---:|---:|---:|---:|---:|");
    for path in &paths {
        let mesh = prepare(
            import_path(path.as_ref(), &ImportOptions::default()).unwrap(),
            &RepairOptions::default(),
        )
        .unwrap()
        .0;
        let mesh = if twin { beside_itself(mesh) } else { mesh };
        let name = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy();
        let n = mesh.positions.len();
        let t = Instant::now();
        let plain = encode(&mesh, &EncodeOptions::default()).unwrap();
        let plain_encode = t.elapsed().as_secs_f64();
        let reference = final_level(&plain.bytes, &plain.vertex_order);
        let plain_1 = decode_time(&plain.bytes, 1, runs);
        println!(
            "| {name} | {n} | format 4 | – | {} | 1 | {plain_encode:.2} | {:.1} | – | – |",
            plain.bytes.len(),
            plain_1 * 1e3
        );
        for &p in &per {
            // `--per 0`: what `--charts auto` makes.
            let setting = match p {
                0 => Charts::Auto,
                p if p > u32::MAX - 65 => Charts::Count(u32::MAX - p),
                p => Charts::PerVertices(p),
            };
            let options = EncodeOptions {
                charts: setting,
                ..EncodeOptions::default()
            };
            let t = Instant::now();
            let charted = encode(&mesh, &options).unwrap();
            let encode_s = t.elapsed().as_secs_f64();
            if charted.header.version == plain.header.version {
                println!("| {name} | {n} | {setting:?} | 1 | (plain) | | | | | |");
                continue;
            }
            assert!(
                final_level(&charted.bytes, &charted.vertex_order) == reference,
                "{name}: the charted stream is not lossless"
            );
            let charts = setting.count(n);
            if std::env::var_os("LEVELS").is_some() {
                let index = StreamIndex::parse(&charted.bytes).unwrap();
                let parted = index
                    .batches
                    .iter()
                    .position(|r| charted.bytes[r.start] == b'P')
                    .unwrap_or(0);
                let levels: Vec<String> = charted
                    .header
                    .levels
                    .iter()
                    .enumerate()
                    .map(|(k, l)| {
                        format!("{}{}", if k == parted + 1 { "| " } else { "" }, l.vertices)
                    })
                    .collect();
                let plain_levels: Vec<String> = plain
                    .header
                    .levels
                    .iter()
                    .map(|l| l.vertices.to_string())
                    .collect();
                eprintln!("{name} charted levels: {}", levels.join(" "));
                eprintln!("{name} plain levels:   {}", plain_levels.join(" "));
            }
            if std::env::var_os("STAGES").is_some() {
                for threads in [1, 2] {
                    let index = StreamIndex::parse(&charted.bytes).unwrap();
                    let mut d = Decoder::new(&charted.bytes[index.base.clone()], Limits::default())
                        .unwrap();
                    d.set_threads(threads);
                    let mut stages = Vec::new();
                    for r in &index.batches {
                        let t = Instant::now();
                        d.apply_batch(&charted.bytes[r.clone()]).unwrap();
                        stages.push(format!(
                            "{}{:.1}",
                            if charted.bytes[r.start] == b'P' {
                                "P"
                            } else {
                                ""
                            },
                            t.elapsed().as_secs_f64() * 1e3
                        ));
                    }
                    eprintln!("{name} {threads}T batches ms: {}", stages.join(" "));
                }
            }
            let times: Vec<f64> = [1, 2, 4]
                .iter()
                .map(|&t| decode_time(&charted.bytes, t, runs))
                .collect();
            println!(
                "| {name} | {n} | {setting:?} | {charts} | {} | {:.4} | {encode_s:.2} | {:.1} | {:.1} | {:.1} |",
                charted.bytes.len(),
                charted.bytes.len() as f64 / plain.bytes.len() as f64,
                times[0] * 1e3,
                times[1] * 1e3,
                times[2] * 1e3
            );
        }
    }
}

/// The mesh and a copy of it, moved along z past its own extent.
fn beside_itself(mut mesh: vitrine_codec::IndexedMesh) -> vitrine_codec::IndexedMesh {
    let (lo, hi) = mesh
        .positions
        .iter()
        .fold((f32::MAX, f32::MIN), |(lo, hi), p| {
            (lo.min(p[2]), hi.max(p[2]))
        });
    let shift = 1.1 * (hi - lo);
    let n = mesh.positions.len() as u32;
    let copy: Vec<[f32; 3]> = mesh
        .positions
        .iter()
        .map(|p| [p[0], p[1], p[2] + shift])
        .collect();
    mesh.positions.extend(copy);
    if let Some(c) = &mut mesh.colors {
        c.extend_from_within(..);
    }
    let faces: Vec<[u32; 3]> = mesh.triangles.iter().map(|t| t.map(|v| v + n)).collect();
    mesh.triangles.extend(faces);
    mesh
}
