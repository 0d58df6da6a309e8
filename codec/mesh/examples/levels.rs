//! Quick look at streams while tuning the codec:
//! `cargo run --release --example levels [mesh files…]` (generated meshes when none).
use std::time::Instant;
use vitrine_codec::{breakdown, decode, encode, EncodeOptions, IndexedMesh, Limits};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};
use vitrine_samples::{icosphere, torus};

fn main() {
    let paths: Vec<String> = std::env::args().skip(1).collect();
    let meshes: Vec<(String, IndexedMesh)> = if paths.is_empty() {
        vec![
            ("icosphere(6)".into(), icosphere(6)),
            ("torus".into(), torus(400, 160, 1.0, 0.3)),
        ]
    } else {
        paths
            .iter()
            .map(|p| {
                let m = import_path(p.as_ref(), &ImportOptions::default()).unwrap();
                (
                    p.rsplit('/').next().unwrap().to_string(),
                    prepare(m, &RepairOptions::default()).unwrap().0,
                )
            })
            .collect()
    };
    let (mut conn_sum, mut total_sum) = (0.0, 0.0);
    for (name, mesh) in &meshes {
        let t = Instant::now();
        let e = encode(mesh, &EncodeOptions::default()).unwrap();
        let enc = t.elapsed().as_secs_f64();
        let t = Instant::now();
        decode(&e.bytes, None, Limits::default()).unwrap();
        let dec = t.elapsed().as_secs_f64();
        let n = mesh.positions.len() as f64;
        let b = breakdown(&e.bytes).unwrap();
        let sum = |f: fn(&vitrine_codec::LevelBreakdown) -> u32| {
            b[1..].iter().map(f).sum::<u32>() as f64 * 8.0 / n
        };
        let conn = sum(|l| l.connectivity + l.overhead);
        if std::env::var_os("OVERHEAD").is_some() {
            println!("  overhead {:.3} b/v", sum(|l| l.overhead));
        }
        conn_sum += conn;
        total_sum += e.bytes.len() as f64 * 8.0 / n;
        println!(
            "{name:24} {:8} v {:3} levels base {:6} | conn {:5.2} geom {:5.2} col {:5.2} base {:5.2} total {:6.2} b/v | enc {:5.2} Mv/s dec {:5.2} Mv/s",
            mesh.positions.len(),
            e.header.batch_count(),
            b[0].vertices,
            conn,
            sum(|l| l.geometry),
            sum(|l| l.colour),
            b[0].bytes as f64 * 8.0 / n,
            e.bytes.len() as f64 * 8.0 / n,
            n / enc / 1e6,
            n / dec / 1e6
        );
    }
    println!(
        "mean conn {:.2} total {:.2}",
        conn_sum / meshes.len() as f64,
        total_sum / meshes.len() as f64
    );
}
