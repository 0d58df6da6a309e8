//! The nested view's ABI driven natively, the bytes put in the input
//! buffer as JS would: a leaf refined through its ancestors is the full
//! decoder's bit for bit, and wrong pieces give −1 and a message.

use super::*;
use crate::{decoder_apply, decoder_new, error_len};
use vitrine_codec::{decode, encode, Charts, EncodeOptions, Limits, StreamIndex};
use vitrine_samples::{add_noise, torus};

fn put(bytes: &[u8]) -> u32 {
    INPUT.with(|i| *i.borrow_mut() = bytes.to_vec());
    bytes.len() as u32
}

fn sizes() -> Vec<u32> {
    SIZES.with(|s| s.borrow().clone())
}

#[test]
fn a_leaf_through_the_abi_is_the_full_decoders() {
    let mut mesh = torus(160, 64, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 9);
    let options = EncodeOptions {
        charts: Charts::NestedShape {
            top: 2,
            fanout: 3,
            phases: 2,
        },
        ..EncodeOptions::default()
    };
    let stream = encode(&mesh, &options).unwrap().bytes;
    let index = StreamIndex::parse(&stream).unwrap();
    let decoder = decoder_new(put(&stream[index.base.clone()]));
    assert!(decoder > 0);
    nested_layouts_clear();
    // Each parted batch's chunk and its u32 layout.
    let mut parted: Vec<(&[u8], Vec<u32>)> = Vec::new();
    for r in &index.batches {
        let chunk = &stream[r.clone()];
        match nested_layout(put(chunk)) {
            0 => assert_eq!(decoder_apply(decoder, put(chunk)), 0),
            n => {
                assert!(n > 0);
                parted.push((chunk, sizes()));
            }
        }
    }
    let (first, l0) = &parted[0];
    let head = &first[l0[3] as usize..l0[4] as usize];
    let view = nested_new(decoder, put(head));
    assert!(view > 0);
    assert_eq!(nested_phases(view), 2);
    assert_eq!(nested_charts(view, 1), 6);
    // A layout's pieces: the split entries' and the parts' ranges.
    let splits = |l: &[u32]| -> Vec<(u32, std::ops::Range<usize>)> {
        (0..l[5] as usize)
            .map(|k| (l[6 + 3 * k], l[7 + 3 * k] as usize..l[8 + 3 * k] as usize))
            .collect()
    };
    let part = |l: &[u32], chart: usize| {
        let at = 6 + 3 * l[5] as usize + 2 * chart;
        l[at] as usize..l[at + 1] as usize
    };
    let top = 1;
    for (chunk, l) in parted.iter().filter(|(_, l)| l[1] == 0) {
        assert_eq!(nested_apply_part(view, 0, top, put(&chunk[part(l, 1)])), 0);
    }
    assert_eq!(
        nested_depth(view, 0, top) as u32,
        nested_phase_batches(view, 0)
    );
    let (chunk, l) = parted.iter().find(|(_, l)| l[1] == 1 && l[2] == 1).unwrap();
    let (count, entry) = splits(l)[top as usize].clone();
    assert_eq!(count, nested_children(view, 0, top));
    assert_eq!(nested_split(view, 0, top, put(&chunk[entry])), 0);
    let leaf = nested_first_child(view, 0, top) + count - 1;
    assert_eq!(nested_parent(view, 1, leaf), top as i32);
    for (chunk, l) in parted.iter().filter(|(_, l)| l[1] == 1) {
        let bytes = &chunk[part(l, leaf as usize)];
        assert_eq!(nested_apply_part(view, 1, leaf, put(bytes)), 0);
    }
    let full = decode(&stream, None, Limits::default()).unwrap();
    let theirs = full.chart(leaf as usize).unwrap();
    with_view(view, |v| {
        let ours = v.chart(1, leaf as usize).unwrap();
        assert!(ours.quantized == theirs.quantized && ours.indices == theirs.indices);
    })
    .unwrap();
    assert_eq!(
        nested_buffer_len(view, 1, leaf, INDICES) as usize,
        theirs.indices.len()
    );
    assert_eq!(
        nested_buffer_len(view, 1, leaf, POSITIONS) as usize,
        theirs.positions.len()
    );
    assert!(nested_buffer_len(view, 1, leaf, FIRST_IDS) > 0);
    assert!(nested_resident(view) > 0);
    // Out of turn, unknown, or damaged: −1 and a message, never a panic.
    assert_eq!(nested_apply_part(view, 0, top, put(&[])), -1);
    assert!(error_len() > 0);
    assert_eq!(nested_split(view, 0, 0, put(&[7])), -1);
    assert_eq!(nested_apply_part(view + 9, 0, 0, put(&[])), -1);
    assert_eq!(nested_depth(view, 1, 0), -1);
    nested_drop(view, 1, leaf);
    assert_eq!(nested_depth(view, 1, leaf), -1);
    assert_eq!(nested_layout(put(&chunk[..chunk.len() / 2])), -1);
    nested_layouts_clear();
    assert_eq!(nested_new(decoder, put(head)), 0);
    nested_free(view);
    assert_eq!(nested_phases(view), 0);
}

/// A chart held: its phase, position, quantized positions, colours and triangles.
type ChartSnapshot = (usize, usize, Vec<[i32; 3]>, Vec<u8>, Vec<u32>);

/// Every chart held, phase by phase.
fn snapshot(view: u32) -> Vec<ChartSnapshot> {
    with_view(view, |v| {
        let mut charts = Vec::new();
        for phase in 0..v.phase_count() {
            for chart in 0..v.chart_count(phase) {
                if let Some(c) = v.chart(phase, chart) {
                    let colours = c.colours.map_or(Vec::new(), <[u8]>::to_vec);
                    charts.push((
                        phase,
                        chart,
                        c.quantized.to_vec(),
                        colours,
                        c.indices.to_vec(),
                    ));
                }
            }
        }
        charts
    })
    .unwrap()
}

#[test]
fn a_view_declared_from_the_index_is_the_one_from_whole_batches() {
    let mut mesh = torus(120, 48, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 4);
    let options = EncodeOptions {
        charts: Charts::NestedShape {
            top: 2,
            fanout: 2,
            phases: 3,
        },
        ..EncodeOptions::default()
    };
    let stream = encode(&mesh, &options).unwrap().bytes;
    let index = StreamIndex::parse(&stream).unwrap();
    // What the service's part index says of the stream (server/src/service/parts.rs).
    let table = vitrine_codec::nested_part_table(&stream, Limits::default()).unwrap();
    let first_level = table.parts.iter().map(|p| p.level).min().unwrap();
    let last_level = table.parts.iter().map(|p| p.level).max().unwrap();

    // One view from whole batches, the other from the index and the head.
    let whole = decoder_new(put(&stream[index.base.clone()]));
    let declared = decoder_new(put(&stream[index.base.clone()]));
    nested_layouts_clear();
    let mut chunks = Vec::new();
    for r in &index.batches {
        let chunk = &stream[r.clone()];
        if nested_layout(put(chunk)) == 0 {
            assert_eq!(decoder_apply(whole, put(chunk)), 0);
            assert_eq!(decoder_apply(declared, put(chunk)), 0);
        } else {
            chunks.push(chunk);
        }
    }
    let l0 = {
        nested_layouts_clear();
        nested_layout(put(chunks[0]));
        sizes()
    };
    let head = chunks[0][l0[3] as usize..l0[4] as usize].to_vec();
    nested_layouts_clear();
    for chunk in &chunks {
        assert!(nested_layout(put(chunk)) > 0);
    }
    let from_batches = nested_new(whole, put(&head));
    assert!(from_batches > 0);

    nested_layouts_clear();
    for level in first_level..=last_level {
        let parts: Vec<_> = table.parts.iter().filter(|p| p.level == level).collect();
        let mut splits: Vec<_> = table.splits.iter().filter(|s| s.level == level).collect();
        splits.sort_by_key(|s| s.parent);
        let children: Vec<u8> = splits
            .iter()
            .flat_map(|s| (s.children.len() as u32).to_le_bytes())
            .collect();
        put(&children);
        let charts = parts.len() as u32;
        let n = nested_layout_declare(
            level as u32,
            parts[0].phase as u32,
            charts,
            splits.len() as u32,
        );
        assert_eq!(n, charts as i32, "level {level}");
    }
    let from_index = nested_new(declared, put(&head));
    assert!(from_index > 0);
    assert_eq!(nested_phases(from_index), 3);
    assert_eq!(snapshot(from_index), snapshot(from_batches));

    // Walk the whole tree in stream order on both: every part, every split.
    // A phase's split entries lie in its first batch's head, before its parts.
    let mut splits_done = 0;
    for part in &table.parts {
        while let Some(split) = table
            .splits
            .get(splits_done)
            .filter(|s| s.level <= part.level)
        {
            let entry = &stream[split.bytes.clone()];
            let (phase, parent) = (split.phase as u32 - 1, split.parent as u32);
            for view in [from_batches, from_index] {
                assert_eq!(nested_split(view, phase, parent, put(entry)), 0);
            }
            splits_done += 1;
        }
        let bytes = &stream[part.bytes.clone()];
        for view in [from_batches, from_index] {
            let (phase, chart) = (part.phase as u32, part.chart as u32);
            assert_eq!(nested_apply_part(view, phase, chart, put(bytes)), 0);
        }
    }
    assert_eq!(splits_done, table.splits.len());
    let ours = snapshot(from_index);
    assert_eq!(
        ours.iter().filter(|c| c.0 == 2).count(),
        8,
        "every leaf decoded"
    );
    assert_eq!(ours, snapshot(from_batches));
    assert_eq!(nested_resident(from_index), nested_resident(from_batches));
    // The leaves are the full decoder's bit for bit.
    let full = decode(&stream, None, Limits::default()).unwrap();
    for leaf in 0..8 {
        let theirs = full.chart(leaf).unwrap();
        with_view(from_index, |v| {
            let c = v.chart(2, leaf).unwrap();
            assert!(c.quantized == theirs.quantized && c.indices == theirs.indices);
        })
        .unwrap();
    }

    // Declarations out of order, or whose children do not add up: −1.
    nested_layouts_clear();
    assert_eq!(nested_layout_declare(first_level as u32, 1, 2, 0), -1);
    assert_eq!(nested_layout_declare(first_level as u32, 0, 2, 0), 2);
    put(&[1, 0, 0, 0, 1, 0, 0, 0]);
    assert_eq!(nested_layout_declare(first_level as u32 + 1, 1, 4, 2), -1);
    put(&[1, 0, 0, 0]);
    assert_eq!(nested_layout_declare(first_level as u32 + 1, 1, 4, 2), -1);
    nested_layouts_clear();
    nested_free(from_index);
    nested_free(from_batches);
}
