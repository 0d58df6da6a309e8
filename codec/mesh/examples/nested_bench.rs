//! What a viewer that refines where the visitor looks fetches (issue 41):
//! stream bytes against format 4, the *prefix* (header, base, global
//! batches and the first parted batch's head) and the *close-up* (the
//! prefix, one leaf chart's parts to the final level, its ancestors'
//! parts and the split entries on its path), median and largest over the
//! leaves, for format 5 (flat charts) and format 6 (nested charts). Every
//! charted stream is checked lossless against format 4's final level.
//!
//! `cargo run --release -p vitrine-mesh --example nested_bench -- mesh... [--v5 K|auto]... [--v6 nested|T,F,P]...`
//! (default: `--v5 auto --v5 16 --v6 nested`).
use std::time::Instant;
use vitrine_codec::{
    decode, encode, Charts, Decoder, EncodeOptions, Encoded, Limits, NestedLayout, NestedSummary,
    PartedLayout, StreamIndex, NESTED_VERSION,
};
use vitrine_mesh::import::{import_path, ImportOptions};
use vitrine_mesh::repair::{prepare, RepairOptions};

/// The final level in input ids: quantized positions and canonical faces;
/// and the seconds the whole decoder took on one thread.
fn final_level(bytes: &[u8], order: &[u32]) -> (Level, f64) {
    let t = Instant::now();
    let d = decode(bytes, None, Limits::default()).unwrap();
    let seconds = t.elapsed().as_secs_f64();
    let mut positions = vec![[0; 3]; order.len()];
    for (i, &v) in order.iter().enumerate() {
        positions[v as usize] = d.quantized_positions()[i];
    }
    let mut faces: Vec<[u32; 3]> = d
        .indices()
        .chunks_exact(3)
        .map(|t| {
            let t = t.iter().map(|&v| order[v as usize]).collect::<Vec<_>>();
            let i = (0..3).min_by_key(|&i| t[i]).unwrap();
            [t[i], t[(i + 1) % 3], t[(i + 2) % 3]]
        })
        .collect();
    faces.sort_unstable();
    ((positions, faces), seconds)
}

/// Quantized positions and canonical faces, in input ids.
type Level = (Vec<[i32; 3]>, Vec<[u32; 3]>);

/// Decodes leaf `leaf`'s path with the nested view decoder (its ancestors'
/// parts and split entries, then its own parts): the bytes it took,
/// prefix included, and the leaf's final vertex count.
fn decode_leaf_path(bytes: &[u8], leaf: usize) -> (usize, usize) {
    let index = StreamIndex::parse(bytes).unwrap();
    let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
    let mut layouts: Vec<(std::ops::Range<usize>, NestedLayout)> = Vec::new();
    for r in &index.batches {
        let previous = layouts.last().map(|(_, l)| l);
        match NestedLayout::parse(&bytes[r.clone()], previous).unwrap() {
            Some(l) => layouts.push((r.clone(), l)),
            None => d.apply_batch(&bytes[r.clone()]).unwrap(),
        }
    }
    let (first, l0) = &layouts[0];
    let all: Vec<NestedLayout> = layouts.iter().map(|(_, l)| l.clone()).collect();
    let mut view = d
        .into_nested_view(&bytes[first.clone()][l0.head.clone()], &all)
        .unwrap();
    let mut taken = first.start + l0.head.end;
    let phases = view.phase_count();
    let mut path = vec![leaf];
    for phase in (1..phases).rev() {
        path.push(view.parent(phase, *path.last().unwrap()).unwrap());
    }
    path.reverse();
    for (phase, &chart) in path.iter().enumerate() {
        if phase > 0 {
            let (r, l) = layouts
                .iter()
                .find(|(_, l)| l.phase == phase && l.begins)
                .unwrap();
            let entry = l.splits[path[phase - 1]].1.clone();
            view.split(phase - 1, path[phase - 1], &bytes[r.clone()][entry.clone()])
                .unwrap();
            taken += entry.len();
        }
        for (r, l) in layouts.iter().filter(|(_, l)| l.phase == phase) {
            let part = l.parts[chart].clone();
            view.apply_part(phase, chart, &bytes[r.clone()][part.clone()])
                .unwrap();
            taken += part.len();
        }
    }
    (taken, view.chart(phases - 1, leaf).unwrap().quantized.len())
}

/// Prefix bytes and every leaf's close-up bytes, with a description of
/// where the charts begin; `None` for a plain stream.
fn closeups(e: &Encoded) -> Option<(usize, Vec<usize>, String)> {
    let bytes = &e.bytes;
    let index = StreamIndex::parse(bytes).unwrap();
    if let Some(summary) = NestedSummary::of(bytes).unwrap() {
        let counts: Vec<String> = summary
            .part_bytes
            .iter()
            .map(|p| p.len().to_string())
            .collect();
        return Some((
            summary.prefix,
            summary.closeups,
            format!(
                "charts {} from level {}",
                counts.join(" → "),
                summary.first_level
            ),
        ));
    }
    let mut first = None;
    let mut part_bytes: Vec<usize> = Vec::new();
    for r in &index.batches {
        if let Some(l) = PartedLayout::parse(&bytes[r.clone()]).unwrap() {
            if first.is_none() {
                first = Some((r.start + l.head.end, l.level));
            }
            part_bytes.resize(l.parts.len(), 0);
            for (k, p) in l.parts.iter().enumerate() {
                part_bytes[k] += p.len();
            }
        }
    }
    let (prefix, level) = first?;
    let charts = part_bytes.len();
    Some((
        prefix,
        part_bytes.iter().map(|b| prefix + b).collect(),
        format!("charts {charts} from level {level}"),
    ))
}

fn main() {
    let mut settings: Vec<(String, Charts)> = Vec::new();
    let mut paths = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--v5" => {
                let k = args.next().expect("--v5 K|auto");
                let c = if k == "auto" {
                    Charts::Auto
                } else {
                    Charts::Count(k.parse().unwrap())
                };
                settings.push((format!("5, {k}"), c));
            }
            "--v6" => {
                let s = args.next().expect("--v6 nested|T,F,P");
                let c = if s == "nested" {
                    Charts::Nested
                } else {
                    let v: Vec<u8> = s.split(',').map(|x| x.parse().unwrap()).collect();
                    Charts::NestedShape {
                        top: v[0],
                        fanout: v[1],
                        phases: v[2],
                    }
                };
                settings.push((format!("6, {s}"), c));
            }
            _ => paths.push(a),
        }
    }
    if settings.is_empty() {
        settings = vec![
            ("5, auto".into(), Charts::Auto),
            ("5, 16".into(), Charts::Count(16)),
            ("6, nested".into(), Charts::Nested),
        ];
    }
    println!("| mesh | format, charts | bytes | vs format 4 | where charts begin | prefix | close-up median | close-up largest | encode s | decode s |");
    println!("|---|---|---:|---:|---|---:|---:|---:|---:|---:|");
    for path in &paths {
        let mesh = prepare(
            import_path(path.as_ref(), &ImportOptions::default()).unwrap(),
            &RepairOptions::default(),
        )
        .unwrap()
        .0;
        let name = std::path::Path::new(path)
            .file_stem()
            .unwrap()
            .to_string_lossy()
            .into_owned();
        let n = mesh.positions.len();
        let t = Instant::now();
        let plain = encode(&mesh, &EncodeOptions::default()).unwrap();
        let plain_s = t.elapsed().as_secs_f64();
        let (reference, plain_decode) = final_level(&plain.bytes, &plain.vertex_order);
        let total = plain.bytes.len();
        println!(
            "| {name} ({n}) | 4 | {total} | – | – | – | – | – | {plain_s:.1} | {plain_decode:.2} |"
        );
        for (label, charts) in &settings {
            let options = EncodeOptions {
                charts: *charts,
                ..EncodeOptions::default()
            };
            let t = Instant::now();
            let e = encode(&mesh, &options).unwrap();
            let encode_s = t.elapsed().as_secs_f64();
            let (level, decode_s) = final_level(&e.bytes, &e.vertex_order);
            assert!(level == reference, "{name} {label}: not lossless");
            let len = e.bytes.len();
            let pct = |b: usize| format!("{b} ({:.1} %)", 100.0 * b as f64 / len as f64);
            let vs = format!("{:+.1} %", 100.0 * (len as f64 / total as f64 - 1.0));
            match closeups(&e) {
                Some((prefix, mut c, at)) => {
                    if e.header.version == NESTED_VERSION {
                        // The median leaf's close-up, decoded by the view.
                        let mut by_size: Vec<(usize, usize)> =
                            c.iter().copied().enumerate().map(|(k, b)| (b, k)).collect();
                        by_size.sort_unstable();
                        let (bytes, leaf) = by_size[by_size.len() / 2];
                        let (taken, vertices) = decode_leaf_path(&e.bytes, leaf);
                        assert_eq!(taken, bytes, "{name} {label}: leaf {leaf}'s close-up");
                        eprintln!("{name} {label}: leaf {leaf} decoded by its path alone, {vertices} vertices from {taken} bytes");
                    }
                    c.sort_unstable();
                    println!(
                        "| {name} | {label} (v{}) | {len} | {vs} | {at} | {} | {} | {} | {encode_s:.1} | {decode_s:.2} |",
                        e.header.version,
                        pct(prefix),
                        pct(c[c.len() / 2]),
                        pct(c[c.len() - 1]),
                    );
                }
                None => println!(
                    "| {name} | {label} (v{}, plain) | {len} | {vs} | – | – | – | – | {encode_s:.1} | {decode_s:.2} |",
                    e.header.version
                ),
            }
        }
    }
}
