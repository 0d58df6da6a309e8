//! Bits per point of the point stream's normals and colours, coded against
//! the parent's representative (flag bit 2 off) and against the decoded
//! neighbourhood (on), and decode time of both, on the clouds of issue 42:
//!
//! ```sh
//! cargo run --release -p vitrine-points --example point_attrs -- DATA [--points N] [--runs R] [--normal-bits B] [--write DIR]
//! ```
//! DATA is `shared/data/meshes`. Clouds: N points (default 300,000) sampled
//! on `lucy-100k.ply` with normals estimated as at ingest; the vertices of
//! `nefertiti-rgb-10k.off` with their colours (and estimated normals); N/3
//! points sampled on `banana/` with the texture's colour (nearest texel)
//! and estimated normals; the golden sphere (5,000 points, exact normals,
//! colours from the position). For each, at 12 and 14 bits, version 1,
//! B octahedral bits per normal component (default 11, as ingest):
//! positions-only bytes, the bytes normals add and colours add (old, new),
//! as bits per point, and the whole stream's decode ms (median of R, old
//! and new interleaved). `--write DIR` writes DIR/NAME.f32 (positions),
//! NAME.nrm.f32 (normals) and NAME.rgb (colours) for
//! `scripts/peer_draco_attrs.py`, and the streams with both attributes,
//! NAME-BITS-old.vpts and NAME-BITS-new.vpts, for
//! `web/bench/points-attrs-decode.mjs`. `--decode-loop K [--old]` only decodes the
//! first cloud's 12-bit stream (new coding, or old) K times, for a profiler. The time normal estimation takes on the
//! cloud (what a visitor pays for a stream without normals) goes to stderr.

use std::path::{Path, PathBuf};
use std::time::Instant;

use vitrine_mesh::import::{import_path, import_path_textured, ImportOptions};
use vitrine_points::stream::{decode, encode, EncodeOptions, Limits};
use vitrine_points::testing::{sample_triangles_where, sphere};
use vitrine_points::{estimate_normals, PointCloud, DEFAULT_K};

/// `n` points uniformly on the triangles (area-weighted), seeded (the
/// sample of `point_bytes`), with each point's triangle and barycentrics.
fn sample(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> Vec<([f32; 3], usize, f64, f64)> {
    sample_triangles_where(positions, triangles, n, seed)
        .into_iter()
        .map(|s| (s.point, s.triangle, s.barycentric[0], s.barycentric[1]))
        .collect()
}

fn with_estimated_normals(name: &str, mut cloud: PointCloud) -> PointCloud {
    let started = Instant::now();
    cloud.normals = Some(estimate_normals(&cloud.positions, DEFAULT_K));
    eprintln!(
        "{name}: estimate_normals on {} points: {:.0} ms",
        cloud.len(),
        started.elapsed().as_secs_f64() * 1e3
    );
    cloud
}

fn clouds(data: &Path, n: usize) -> Vec<(String, PointCloud)> {
    let mut out = Vec::new();
    let lucy = import_path(&data.join("lucy-100k.ply"), &ImportOptions::default()).expect("lucy");
    let pos = sample(&lucy.positions, &lucy.triangles, n, 0x5eed)
        .into_iter()
        .map(|s| s.0)
        .collect();
    let name = format!("lucy-{n}");
    out.push((
        name.clone(),
        with_estimated_normals(&name, PointCloud::from_positions(pos)),
    ));
    let nef = import_path(
        &data.join("nefertiti-rgb-10k.off"),
        &ImportOptions::default(),
    )
    .expect("nefertiti");
    let cloud = PointCloud {
        colours: nef.colors.clone(),
        ..PointCloud::from_positions(nef.positions.clone())
    };
    out.push((
        "nefertiti-rgb-10k".into(),
        with_estimated_normals("nefertiti", cloud),
    ));
    let banana = import_path_textured(
        &data.join("banana/textured_simple_reoriented.obj"),
        &ImportOptions::default(),
    )
    .expect("banana");
    if let Some(tex) = banana.texture {
        let (w, h) = (tex.image.width(), tex.image.height());
        let m = n / 3;
        let samples = sample(&tex.positions, &tex.triangles, m, 0xba7a7a);
        let colours = samples
            .iter()
            .map(|&(_, ti, e1, e2)| {
                let t = tex.triangles[ti].map(|i| tex.uvs[i as usize].map(f64::from));
                let uv =
                    [0, 1].map(|k| t[0][k] + e1 * (t[1][k] - t[0][k]) + e2 * (t[2][k] - t[0][k]));
                let x = (uv[0].rem_euclid(1.0) * f64::from(w)) as u32;
                let y = (uv[1].rem_euclid(1.0) * f64::from(h)) as u32;
                tex.image.get_pixel(x.min(w - 1), y.min(h - 1)).0
            })
            .collect();
        let cloud = PointCloud {
            colours: Some(colours),
            ..PointCloud::from_positions(samples.iter().map(|s| s.0).collect())
        };
        let name = format!("banana-{m}");
        out.push((name.clone(), with_estimated_normals(&name, cloud)));
    }
    // The golden sphere (tests/golden.rs).
    let (pos, nrm) = sphere(5000, [0.0; 3], 1.0, 42);
    let colours = pos
        .iter()
        .map(|p| p.map(|v| (v * 100.0 + 128.0) as u8))
        .collect();
    out.push((
        "golden-sphere-5000".into(),
        PointCloud {
            origin: [10.0, 20.0, 30.0],
            positions: pos,
            normals: Some(nrm),
            colours: Some(colours),
        },
    ));
    out
}

fn median(mut t: Vec<f64>) -> f64 {
    t.sort_by(f64::total_cmp);
    t[t.len() / 2]
}

fn write_for_draco(dir: &Path, name: &str, cloud: &PointCloud) {
    let f32s =
        |v: &[[f32; 3]]| -> Vec<u8> { v.iter().flatten().flat_map(|x| x.to_le_bytes()).collect() };
    std::fs::write(dir.join(format!("{name}.f32")), f32s(&cloud.positions)).expect("write");
    if let Some(n) = &cloud.normals {
        std::fs::write(dir.join(format!("{name}.nrm.f32")), f32s(n)).expect("write");
    }
    if let Some(c) = &cloud.colours {
        std::fs::write(dir.join(format!("{name}.rgb")), c.concat()).expect("write");
    }
}

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut take = |flag: &str| {
        let i = args.iter().position(|a| a == flag)?;
        let v = args.get(i + 1).expect("flag value").clone();
        args.drain(i..i + 2);
        Some(v)
    };
    let n: usize = take("--points").map_or(300_000, |v| v.parse().expect("N"));
    let runs: usize = take("--runs").map_or(5, |v| v.parse().expect("R"));
    let normal_bits: u8 = take("--normal-bits").map_or(11, |v| v.parse().expect("B"));
    let write = take("--write").map(PathBuf::from);
    let decode_loop: Option<usize> = take("--decode-loop").map(|v| v.parse().expect("K"));
    let old = args
        .iter()
        .position(|a| a == "--old")
        .map(|i| args.remove(i));
    let data = PathBuf::from(args.first().expect("usage: point_attrs DATA"));
    println!("cloud\tpoints\tbits\tpos_bytes\tnormal_b/p_old\tnormal_b/p_new\tcolour_b/p_old\tcolour_b/p_new\tattr_bytes_old\tattr_bytes_new\tdecode_ms_old\tdecode_ms_new");
    for (name, cloud) in clouds(&data, n) {
        if let Some(k) = decode_loop {
            // For a profiler: the first cloud's 12-bit stream, K decodes.
            let opts = EncodeOptions {
                bits: 12,
                predict_attributes: old.is_none(),
                ..Default::default()
            };
            let s = encode(&cloud, &opts).expect("encode");
            for _ in 0..k {
                let d = decode(&s.bytes, None, Limits::default()).expect("decode");
                std::hint::black_box(d.point_count());
            }
            return;
        }
        if let Some(dir) = &write {
            write_for_draco(dir, &name, &cloud);
        }
        let len = cloud.len();
        for bits in [12u8, 14] {
            let opts = |normals, colours, predict| EncodeOptions {
                bits,
                normal_bits,
                normals,
                colours,
                predict_attributes: predict,
                ..Default::default()
            };
            let size = |normals, colours, predict| {
                let s = encode(&cloud, &opts(normals, colours, predict)).expect("encode");
                s.bytes.len()
            };
            let pos = size(false, false, false);
            let bpp = |b: usize| (b as f64 - pos as f64) * 8.0 / len as f64;
            let has_n = cloud.normals.is_some();
            let has_c = cloud.colours.is_some();
            let (n_old, n_new) = (size(has_n, false, false), size(has_n, false, true));
            let (c_old, c_new) = (size(false, has_c, false), size(false, has_c, true));
            let streams =
                [false, true].map(|p| encode(&cloud, &opts(true, true, p)).expect("encode"));
            for s in &streams {
                let d = decode(&s.bytes, None, Limits::default()).expect("decode");
                assert_eq!(d.quantized(), &s.quantized[..], "positions");
                assert_eq!(d.normal_codes(), s.normals, "normals");
                if let Some(c) = &cloud.colours {
                    let want: Vec<[u8; 3]> = s.order.iter().map(|&i| c[i as usize]).collect();
                    assert_eq!(d.colours(), Some(&want[..]), "colours");
                }
            }
            let mut times = [Vec::new(), Vec::new()];
            for _ in 0..runs {
                for (t, s) in times.iter_mut().zip(&streams) {
                    let started = Instant::now();
                    let d = decode(&s.bytes, None, Limits::default()).expect("decode");
                    std::hint::black_box(d.point_count());
                    t.push(started.elapsed().as_secs_f64() * 1e3);
                }
            }
            let [t_old, t_new] = times.map(median);
            if let Some(dir) = &write {
                for (s, coding) in streams.iter().zip(["old", "new"]) {
                    let path = dir.join(format!("{name}-{bits}-{coding}.vpts"));
                    std::fs::write(path, &s.bytes).expect("write");
                }
            }
            println!(
                "{name}\t{len}\t{bits}\t{pos}\t{:.2}\t{:.2}\t{:.2}\t{:.2}\t{}\t{}\t{t_old:.1}\t{t_new:.1}",
                bpp(n_old),
                bpp(n_new),
                bpp(c_old),
                bpp(c_new),
                streams[0].bytes.len() - pos,
                streams[1].bytes.len() - pos,
            );
        }
    }
}
