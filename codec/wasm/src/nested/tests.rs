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
