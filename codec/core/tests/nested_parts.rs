//! The part table of a nested stream (format 6): every part and split
//! entry where the layouts put it, in the tree the stream declares, each
//! part's error checked against the whole decoder's charts; hostile
//! streams give errors, never panics.

use vitrine_codec::{
    encode, nested_part_table, part_table, Charts, Decoder, EncodeOptions, IndexedMesh, Limits,
    NestedLayout, StreamIndex, BULK_SHARE,
};
use vitrine_samples::{add_noise, punch_holes, torus};

fn nested(top: u8, fanout: u8, phases: u8) -> EncodeOptions {
    EncodeOptions {
        charts: Charts::NestedShape {
            top,
            fanout,
            phases,
        },
        ..EncodeOptions::default()
    }
}

/// A noisy torus of 24 k vertices with holes (borders) in it.
fn scan_like() -> IndexedMesh {
    let mut mesh = torus(240, 100, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 17);
    punch_holes(&mesh, &[[1.35, 0.0, 0.0], [-0.65, 0.0, 0.0]], 0.12)
}

/// Each parted batch's chunk start and layout.
fn layouts(stream: &[u8]) -> (StreamIndex, Vec<(usize, NestedLayout)>) {
    let index = StreamIndex::parse(stream).unwrap();
    let mut parted: Vec<(usize, NestedLayout)> = Vec::new();
    for r in &index.batches {
        let previous = parted.last().map(|(_, l)| l);
        if let Some(l) = NestedLayout::parse(&stream[r.clone()], previous).unwrap() {
            parted.push((r.start, l));
        }
    }
    (index, parted)
}

/// Distance from `p` to the triangle `t`: to its plane where `p` projects
/// inside, else to the nearest of its edges (clamped segments).
fn distance(p: [f64; 3], t: [[f64; 3]; 3]) -> f64 {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let dot = |a: [f64; 3], b: [f64; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    let cross = |a: [f64; 3], b: [f64; 3]| {
        [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ]
    };
    let n = cross(sub(t[1], t[0]), sub(t[2], t[0]));
    let nn = dot(n, n);
    if nn > 0.0 {
        let inside = (0..3).all(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            dot(cross(sub(b, a), sub(p, a)), n) >= 0.0
        });
        if inside {
            return dot(sub(p, t[0]), n).abs() / nn.sqrt();
        }
    }
    (0..3)
        .map(|i| {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            let ab = sub(b, a);
            let s = (dot(sub(p, a), ab) / dot(ab, ab).max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
            let q = [a[0] + ab[0] * s, a[1] + ab[1] * s, a[2] + ab[2] * s];
            dot(sub(p, q), sub(p, q)).sqrt()
        })
        .fold(f64::INFINITY, f64::min)
}

#[test]
fn the_nested_part_table_places_every_part_and_split_in_the_tree() {
    let stream = encode(&scan_like(), &nested(2, 3, 3)).unwrap().bytes;
    let (index, parted) = layouts(&stream);
    let table = nested_part_table(&stream, Limits::default()).unwrap();
    assert_eq!(part_table(&stream, Limits::default()).unwrap(), table.parts);
    // One record per chart of every parted batch, in stream order.
    let expected: usize = parted.iter().map(|(_, l)| l.parts.len()).sum();
    assert_eq!(table.parts.len(), expected);
    let mut records = table.parts.iter();
    // Each phase's charts' parents, from the split entries.
    let mut parents: Vec<Vec<usize>> = vec![Vec::new(); 3];
    let mut splits = table.splits.iter();
    for (start, l) in &parted {
        if l.begins && l.phase > 0 {
            let mut first = 0;
            for (parent, (count, entry)) in l.splits.iter().enumerate() {
                let s = splits.next().unwrap();
                assert_eq!((s.level, s.phase, s.parent), (l.level, l.phase, parent));
                assert_eq!(s.bytes, start + entry.start..start + entry.end);
                assert_eq!(s.children, first..first + count);
                parents[l.phase].extend(std::iter::repeat_n(parent, *count));
                first += count;
            }
        }
        for (chart, part) in l.parts.iter().enumerate() {
            let r = records.next().unwrap();
            assert_eq!((r.level, r.phase, r.chart), (l.level, l.phase, chart));
            assert_eq!(r.bytes, start + part.start..start + part.end);
            let parent = (l.phase > 0).then(|| parents[l.phase][chart]);
            assert_eq!(r.parent, parent, "{r:?}");
        }
    }
    assert!(splits.next().is_none());
    assert_eq!(parents[2].len(), 18);
    // Everything the charts insert, over the level where they begin.
    let first_level = parted[0].1.level;
    let cut = index.header.levels[first_level - 1].vertices as usize;
    let inserted: usize = table.parts.iter().map(|r| r.inserted).sum();
    assert_eq!(inserted, index.header.final_level().vertices as usize - cut);
    assert!(table.parts.iter().all(|r| r.error_steps < 4096));
}

#[test]
fn each_nested_parts_error_bounds_the_whole_decoders_refinement() {
    let stream = encode(&scan_like(), &nested(2, 2, 3)).unwrap().bytes;
    let (index, parted) = layouts(&stream);
    let table = nested_part_table(&stream, Limits::default()).unwrap();
    let mut full = Decoder::new(&stream[index.base.clone()], Limits::default()).unwrap();
    let mut charts: Vec<(Vec<[i32; 3]>, Vec<u32>)> = Vec::new();
    let mut checked = 0;
    for r in &index.batches {
        full.apply_batch(&stream[r.clone()]).unwrap();
        let Some((_, l)) = parted.iter().find(|(s, _)| *s == r.start) else {
            continue;
        };
        let after: Vec<(Vec<[i32; 3]>, Vec<u32>)> = (0..full.chart_count())
            .map(|k| {
                let c = full.chart(k).unwrap();
                (c.quantized.to_vec(), c.indices.to_vec())
            })
            .collect();
        assert_eq!(after.len(), l.parts.len());
        // A phase's first batch refines charts just split: their state
        // before it is the view's, not the whole decoder's.
        if !l.begins {
            for (k, ((q, faces), (old, old_faces))) in after.iter().zip(&charts).enumerate() {
                let record = table
                    .parts
                    .iter()
                    .find(|p| p.level == l.level && p.chart == k)
                    .unwrap();
                assert_eq!(record.inserted, q.len() - old.len(), "{record:?}");
                assert_eq!(record.inserted == 0, record.error_steps == 0, "{record:?}");
                assert!(q[..old.len()] == old[..] && !faces.is_empty());
                let point = |v: u32| q[v as usize].map(f64::from);
                // The nearest coarse face anywhere is no farther than the
                // nearest among the faces the vertex replaced: every vertex
                // within the part's error, and 90 % within its bulk error.
                assert!(record.bulk_error_steps <= record.error_steps, "{record:?}");
                let mut within_bulk = 0;
                for v in old.len()..q.len() {
                    let nearest = old_faces
                        .chunks_exact(3)
                        .map(|t| distance(point(v as u32), [point(t[0]), point(t[1]), point(t[2])]))
                        .fold(f64::INFINITY, f64::min);
                    assert!(
                        nearest <= f64::from(record.error_steps) + 1e-9,
                        "{record:?}: vertex {v} lies {nearest} from the coarser chart"
                    );
                    within_bulk +=
                        usize::from(nearest <= f64::from(record.bulk_error_steps) + 1e-9);
                    checked += 1;
                }
                let inserted = q.len() - old.len();
                assert!(
                    within_bulk as f64 >= BULK_SHARE * inserted as f64,
                    "{record:?}: {within_bulk} of {inserted} within the bulk error"
                );
            }
        }
        charts = after;
    }
    assert!(checked > 100, "{checked} vertices checked");
}

#[test]
fn hostile_streams_give_part_table_errors_not_panics() {
    let stream = encode(&scan_like(), &nested(2, 2, 2)).unwrap().bytes;
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    for _ in 0..40 {
        let mut b = stream.clone();
        let at = (random() % b.len() as u64) as usize;
        b[at] ^= 1 << (random() % 8);
        let _ = nested_part_table(&b, Limits::default());
        let cut = (random() % b.len() as u64) as usize;
        assert!(nested_part_table(&stream[..cut], Limits::default()).is_err());
    }
    // A layout read after a wrong previous batch is refused.
    let index = StreamIndex::parse(&stream).unwrap();
    let mut previous: Option<(usize, usize)> = None;
    for r in &index.batches {
        let chunk = &stream[r.clone()];
        let Some(l) = NestedLayout::parse_after(chunk, previous).unwrap() else {
            continue;
        };
        if let (false, Some((phase, charts))) = (l.begins, previous) {
            assert!(NestedLayout::parse_after(chunk, Some((phase, charts + 1))).is_err());
            assert!(NestedLayout::parse_after(chunk, Some((phase + 1, charts))).is_err());
        }
        previous = Some((l.phase, l.parts.len()));
    }
    // A budget below the mesh is refused, not overrun.
    let small = Limits {
        max_vertices: 2_000,
        ..Limits::default()
    };
    assert!(nested_part_table(&stream, small).is_err());
    // Flat and plain streams are not nested.
    let mesh = scan_like();
    for charts in [Charts::Count(4), Charts::Off] {
        let other = encode(
            &mesh,
            &EncodeOptions {
                charts,
                ..EncodeOptions::default()
            },
        )
        .unwrap()
        .bytes;
        let err = nested_part_table(&other, Limits::default()).unwrap_err();
        assert!(err.to_string().contains("part_table"), "{err}");
    }
}
