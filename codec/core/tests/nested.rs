//! Nested-chart streams (format 6): lossless, every level as the header
//! says, the same on any number of threads, and hostile batches refused.

use vitrine_codec::{
    decode, encode, Charts, Decoder, EncodeOptions, Encoded, IndexedMesh, Limits, StreamIndex,
    NESTED_VERSION,
};
use vitrine_samples::{add_noise, merge, paint, plate_with_tunnels, punch_holes, torus};

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

/// A painted, noisy torus of 24 k vertices with holes (borders) in it.
fn scan_like() -> IndexedMesh {
    let mut mesh = torus(240, 100, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 17);
    let mut mesh = punch_holes(&mesh, &[[1.35, 0.0, 0.0], [-0.65, 0.0, 0.0]], 0.12);
    paint(&mut mesh);
    mesh
}

/// A level's quantized positions, indices and colours.
type LevelBuffers = (Vec<[i32; 3]>, Vec<u32>, Option<Vec<u8>>);

/// Every level's buffers, decoded on `threads` threads, each checked
/// against the level table.
fn levels(bytes: &[u8], threads: usize) -> Vec<LevelBuffers> {
    let index = StreamIndex::parse(bytes).unwrap();
    let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
    d.set_threads(threads);
    let mut out = Vec::new();
    for (k, range) in index.batches.iter().enumerate() {
        d.apply_batch(&bytes[range.clone()])
            .unwrap_or_else(|e| panic!("batch {k}: {e}"));
        let level = index.header.levels[k + 1];
        assert_eq!(d.vertex_count(), level.vertices as usize, "level {k}");
        assert_eq!(d.face_count(), level.faces as usize, "level {k}");
        out.push((
            d.quantized_positions().to_vec(),
            d.indices().to_vec(),
            d.colours().map(<[u8]>::to_vec),
        ));
    }
    out
}

fn assert_lossless(mesh: &IndexedMesh, encoded: &Encoded) {
    let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
    if let Some(diff) = vitrine_samples::final_level_mismatch(mesh, 12, &d, &encoded.vertex_order) {
        panic!("final level differs from the quantized input: {diff}");
    }
}

/// The phase of each parted batch (the byte after its deferred-precision
/// byte), `None` for a global batch.
fn phases(encoded: &Encoded) -> Vec<Option<u8>> {
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    index
        .batches
        .iter()
        .map(|r| {
            let chunk = &encoded.bytes[r.clone()];
            let batch = vitrine_codec::BatchChunk::parse(chunk).unwrap();
            (chunk[0] == b'P').then(|| batch.payload[1])
        })
        .collect()
}

#[test]
fn a_nested_stream_is_lossless_and_the_same_on_any_number_of_threads() {
    let mesh = scan_like();
    let encoded = encode(&mesh, &nested(2, 3, 3)).unwrap();
    assert_eq!(encoded.header.version, NESTED_VERSION);
    assert_eq!(
        encode(&mesh, &nested(2, 3, 3)).unwrap().bytes,
        encoded.bytes
    );
    assert_lossless(&mesh, &encoded);
    // Global batches, then phases 0, 1 and 2 in order.
    let phases = phases(&encoded);
    let parted: Vec<u8> = phases.iter().flatten().copied().collect();
    assert!(parted.windows(2).all(|w| w[0] <= w[1]), "{phases:?}");
    assert_eq!(parted.first(), Some(&0), "{phases:?}");
    assert_eq!(parted.last(), Some(&2), "{phases:?}");
    let serial = levels(&encoded.bytes, 1);
    for threads in [2, 5] {
        assert!(
            levels(&encoded.bytes, threads) == serial,
            "{threads} threads"
        );
    }
    for (k, (positions, indices, _)) in serial.iter().enumerate() {
        let mut used = vec![false; positions.len()];
        for &v in indices {
            used[v as usize] = true;
        }
        assert!(
            used.iter().all(|&u| u),
            "level {k} has a vertex without faces"
        );
    }
}

#[test]
fn nested_meshes_in_pieces_and_with_tunnels_stay_lossless() {
    let mut pieces = merge(
        &[
            torus(90, 40, 1.0, 0.3),
            plate_with_tunnels(3, 14),
            torus(60, 30, 0.5, 0.2),
        ],
        0.5,
    );
    paint(&mut pieces);
    for (top, fanout, phases) in [(2, 1, 2), (3, 4, 2), (4, 2, 4), (8, 8, 2)] {
        let encoded = encode(&pieces, &nested(top, fanout, phases)).unwrap();
        assert_lossless(&pieces, &encoded);
        let serial = levels(&encoded.bytes, 1);
        assert!(
            levels(&encoded.bytes, 3) == serial,
            "{top} × {fanout}, {phases} phases"
        );
    }
}

#[test]
fn nested_shapes_follow_the_mesh_size() {
    use vitrine_codec::NestedShape;
    let shape = |v| NestedShape::for_vertices(v);
    assert_eq!(shape(20_000).phases, 1);
    let big = shape(2_000_000);
    assert_eq!((big.top, big.fanout, big.phases), (2, 2, 5));
    assert_eq!(shape(20_000_000).phases, 8);
    assert!(vitrine_codec::NestedShape::new(1, 4, 2).is_err());
    assert!(vitrine_codec::NestedShape::new(64, 64, 3).is_err());
    // A nested option on a tiny mesh gives a valid stream either way.
    let tiny = torus(12, 8, 1.0, 0.3);
    let encoded = encode(&tiny, &nested(2, 2, 2)).unwrap();
    assert_lossless(&tiny, &encoded);
}

#[test]
fn pools_refuse_nested_streams_clearly() {
    let mesh = scan_like();
    let encoded = encode(&mesh, &nested(2, 2, 2)).unwrap();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    let mut d = Decoder::new(&encoded.bytes[index.base.clone()], Limits::default()).unwrap();
    let err = d.refine_only(1).unwrap_err().to_string();
    assert!(err.contains("one worker"), "{err}");
    let first = phases(&encoded).iter().position(Option::is_some).unwrap();
    for r in &index.batches[..first] {
        d.apply_batch(&encoded.bytes[r.clone()]).unwrap();
    }
    let err = d
        .chart_sizes(&encoded.bytes[index.batches[first].clone()])
        .unwrap_err()
        .to_string();
    assert!(err.contains("one worker"), "{err}");
    let err = d
        .into_view(&[])
        .err()
        .expect("a view of a nested stream")
        .to_string();
    assert!(err.contains("version 6"), "{err}");
}

#[test]
fn deferred_precision_is_refused_not_misread() {
    let mesh = scan_like();
    let encoded = encode(&mesh, &nested(2, 2, 2)).unwrap();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    for (k, r) in index.batches.iter().enumerate() {
        let chunk = &encoded.bytes[r.clone()];
        let batch = vitrine_codec::BatchChunk::parse(chunk).unwrap();
        assert_eq!(batch.payload[0], 0, "batch {k}");
        let mut payload = batch.payload.to_vec();
        payload[0] = 2;
        let changed = batch.with_payload(&payload).unwrap();
        let mut d = Decoder::new(&encoded.bytes[index.base.clone()], Limits::default()).unwrap();
        for r in &index.batches[..k] {
            d.apply_batch(&encoded.bytes[r.clone()]).unwrap();
        }
        let err = d.apply_batch(&changed).unwrap_err().to_string();
        assert!(err.contains("deferred precision"), "batch {k}: {err}");
    }
}

#[test]
fn hostile_nested_streams_give_errors_not_panics() {
    let mesh = scan_like();
    let encoded = encode(&mesh, &nested(2, 2, 3)).unwrap();
    let bytes = &encoded.bytes;
    // Truncations anywhere.
    for cut in (0..bytes.len()).step_by(bytes.len() / 97 + 1) {
        let _ = decode(&bytes[..cut], None, Limits::default());
    }
    // Bit flips, a few hundred of them, across the stream.
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    for _ in 0..300 {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let at = (state % bytes.len() as u64) as usize;
        let mut b = bytes.clone();
        b[at] ^= 1 << (state >> 60 & 7);
        let _ = decode(&b, None, Limits::default());
    }
    // Every parted batch's head and phase byte altered: errors.
    let index = StreamIndex::parse(bytes).unwrap();
    for (k, r) in index.batches.iter().enumerate() {
        let chunk = &bytes[r.clone()];
        if chunk[0] != b'P' {
            continue;
        }
        let batch = vitrine_codec::BatchChunk::parse(chunk).unwrap();
        for (at, value) in [(1, 7u8), (2, 0), (2, 65)] {
            let mut payload = batch.payload.to_vec();
            payload[at] = value;
            let changed = batch.with_payload(&payload).unwrap();
            let mut d = Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
            for r in &index.batches[..k] {
                d.apply_batch(&bytes[r.clone()]).unwrap();
            }
            assert!(d.apply_batch(&changed).is_err(), "batch {k}, byte {at}");
        }
    }
}

/// A nested stream as a server serves it: the global batches' chunks, and
/// each parted batch's chunk with its layout.
struct Served<'a> {
    index: StreamIndex,
    global: Vec<&'a [u8]>,
    parted: Vec<(&'a [u8], vitrine_codec::NestedLayout)>,
}

fn serve(stream: &[u8]) -> Served<'_> {
    let index = StreamIndex::parse(stream).unwrap();
    let (mut global, mut parted) = (Vec::new(), Vec::new());
    for range in &index.batches {
        let chunk = &stream[range.clone()];
        let previous = parted.last().map(|(_, l)| l);
        match vitrine_codec::NestedLayout::parse(chunk, previous).unwrap() {
            Some(layout) => parted.push((chunk, layout)),
            None => global.push(chunk),
        }
    }
    Served {
        index,
        global,
        parted,
    }
}

fn nested_view(stream: &[u8], served: &Served) -> vitrine_codec::NestedView {
    let mut d = Decoder::new(&stream[served.index.base.clone()], Limits::default()).unwrap();
    for chunk in &served.global {
        d.apply_batch(chunk).unwrap();
    }
    let (first, layout) = &served.parted[0];
    let layouts: Vec<_> = served.parted.iter().map(|(_, l)| l.clone()).collect();
    d.into_nested_view(&first[layout.head.clone()], &layouts)
        .unwrap()
}

/// One chart's buffers: quantized positions, triangles, colours.
type ChartBuffers = (Vec<[i32; 3]>, Vec<u32>, Option<Vec<u8>>);

fn chart_buffers(c: vitrine_codec::ChartLevel) -> ChartBuffers {
    (
        c.quantized.to_vec(),
        c.indices.to_vec(),
        c.colours.map(<[u8]>::to_vec),
    )
}

/// Where each parted batch's part of a chart of `phase` lies.
fn parts_of<'a>(served: &'a Served, phase: usize, chart: usize) -> Vec<&'a [u8]> {
    served
        .parted
        .iter()
        .filter(|(_, l)| l.phase == phase)
        .map(|(chunk, l)| &chunk[l.parts[chart].clone()])
        .collect()
}

/// The split entry of chart `chart` of `phase` (in phase + 1's first batch).
fn entry_of<'a>(served: &'a Served, phase: usize, chart: usize) -> &'a [u8] {
    let (chunk, l) = served
        .parted
        .iter()
        .find(|(_, l)| l.phase == phase + 1 && l.begins)
        .unwrap();
    &chunk[l.splits[chart].1.clone()]
}

#[test]
fn every_chart_of_a_nested_view_is_the_full_decoders_bit_for_bit() {
    let mesh = scan_like();
    let stream = encode(&mesh, &nested(2, 3, 3)).unwrap().bytes;
    let served = serve(&stream);
    // The full decoder's charts after every parted batch.
    let mut full = Decoder::new(&stream[served.index.base.clone()], Limits::default()).unwrap();
    for chunk in &served.global {
        full.apply_batch(chunk).unwrap();
    }
    let mut expected: Vec<Vec<ChartBuffers>> = Vec::new();
    for (chunk, _) in &served.parted {
        full.apply_batch(chunk).unwrap();
        expected.push(
            (0..full.chart_count())
                .map(|k| chart_buffers(full.chart(k).unwrap()))
                .collect(),
        );
    }
    let mut view = nested_view(&stream, &served);
    assert_eq!(view.phase_count(), 3);
    let mut batch = 0;
    for phase in 0..view.phase_count() {
        if phase > 0 {
            for parent in 0..view.chart_count(phase - 1) {
                view.split(phase - 1, parent, entry_of(&served, phase - 1, parent))
                    .unwrap();
            }
        }
        for j in 0..view.phase_batches(phase) {
            assert_eq!(expected[batch + j].len(), view.chart_count(phase));
            for (k, charts) in expected[batch + j].iter().enumerate() {
                view.apply_part(phase, k, parts_of(&served, phase, k)[j])
                    .unwrap();
                assert!(
                    chart_buffers(view.chart(phase, k).unwrap()) == *charts,
                    "phase {phase}, chart {k}, part {j}"
                );
            }
        }
        batch += view.phase_batches(phase);
    }
    assert_eq!(batch, served.parted.len());
    // Parts and splits out of turn are refused.
    assert!(view.apply_part(0, 0, &[]).is_err());
    assert!(view.split(2, 0, &[1]).is_err());
    assert!(view.apply_part(5, 0, &[]).is_err());
}

/// Every edge of the charts shown (those with no child in the view), each
/// vertex named by the chart that inserted it, lies on exactly two
/// triangles: the closed torus stays closed at any mix of depths.
#[track_caller]
fn assert_watertight(view: &vitrine_codec::NestedView) {
    // A vertex's name: (phase, chart, id) of the chart that inserted it,
    // or (usize::MAX, 0, id) for a vertex of the level where charts begin.
    fn name(
        view: &vitrine_codec::NestedView,
        phase: usize,
        chart: usize,
        v: u32,
    ) -> (usize, usize, u32) {
        match view.first_ids(phase, chart).get(v as usize) {
            Some(&up) if phase == 0 => (usize::MAX, 0, up),
            Some(&up) => name(view, phase - 1, view.parent(phase, chart).unwrap(), up),
            None => (phase, chart, v),
        }
    }
    let mut edges = Vec::new();
    let mut shown = 0;
    for phase in 0..view.phase_count() {
        for k in 0..view.chart_count(phase) {
            let Some(c) = view.chart(phase, k) else {
                continue;
            };
            let children = view.children(phase, k);
            if children
                .clone()
                .any(|child| view.chart(phase + 1, child).is_some())
            {
                continue;
            }
            shown += 1;
            for t in c.indices.chunks_exact(3) {
                for i in 0..3 {
                    let a = name(view, phase, k, t[i]);
                    let b = name(view, phase, k, t[(i + 1) % 3]);
                    edges.push(if a < b { (a, b) } else { (b, a) });
                }
            }
        }
    }
    assert!(shown >= 2, "{shown} charts shown");
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j] == edges[i] {
            j += 1;
        }
        assert_eq!(j - i, 2, "edge {:?} on {} triangles", edges[i], j - i);
        i = j;
    }
}

#[test]
fn a_nested_view_at_any_mix_of_depths_is_watertight() {
    let mut mesh = torus(240, 100, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 23);
    let stream = encode(&mesh, &nested(2, 3, 3)).unwrap().bytes;
    let served = serve(&stream);
    let mut view = nested_view(&stream, &served);
    assert_watertight(&view);
    // Down the first leaf's path; its siblings and cousins stop at
    // assorted depths, top chart 1 halfway through phase 0.
    let half = view.phase_batches(0) / 2;
    for (j, part) in parts_of(&served, 0, 1).into_iter().take(half).enumerate() {
        view.apply_part(0, 1, part).unwrap();
        assert_eq!(view.depth(0, 1), Some(j + 1));
    }
    assert_watertight(&view);
    for part in parts_of(&served, 0, 0) {
        view.apply_part(0, 0, part).unwrap();
    }
    view.split(0, 0, entry_of(&served, 0, 0)).unwrap();
    assert_watertight(&view);
    let kids = view.children(0, 0);
    for (i, k) in kids.clone().enumerate() {
        let parts = parts_of(&served, 1, k);
        let depth = if i == 0 {
            parts.len()
        } else {
            i % (parts.len() + 1)
        };
        for part in &parts[..depth] {
            view.apply_part(1, k, part).unwrap();
        }
        assert_watertight(&view);
    }
    let first = kids.start;
    view.split(1, first, entry_of(&served, 1, first)).unwrap();
    for (i, k) in view.children(1, first).enumerate() {
        let parts = parts_of(&served, 2, k);
        for part in &parts[..(parts.len() * (i + 1) / 3).min(parts.len())] {
            view.apply_part(2, k, part).unwrap();
        }
    }
    assert_watertight(&view);
    // Dropping a chart's children (and theirs) shows it again.
    let before = view.resident_vertices();
    for k in view.children(0, 0) {
        view.drop_chart(1, k);
    }
    assert!(view.chart(2, view.children(1, first).start).is_none());
    assert!(view.resident_vertices() < before);
    assert_watertight(&view);
    // A part damaged in the middle: an error, never a panic.
    let parts = parts_of(&served, 1, first);
    view.split(0, 0, entry_of(&served, 0, 0)).unwrap();
    if let Some(p) = parts.iter().find(|p| p.len() > 8) {
        let mut bad = p.to_vec();
        let at = bad.len() / 2;
        bad[at] ^= 0x5a;
        let _ = view.apply_part(1, first, &bad);
    }
    // A wrong split entry is refused.
    assert!(view.split(0, 0, &[7]).is_err());
}

#[test]
fn the_breakdown_reads_nested_batches() {
    let mesh = scan_like();
    let encoded = encode(&mesh, &nested(2, 2, 3)).unwrap();
    let levels = vitrine_codec::breakdown(&encoded.bytes).unwrap();
    assert_eq!(levels.len(), encoded.header.levels.len());
    for (k, l) in levels.iter().enumerate().skip(1) {
        assert!(l.geometry > 0 && l.connectivity > 0, "level {k}: {l:?}");
        // Chunk header, deferred-precision byte, seeds and lengths.
        assert!(l.overhead < 64 + l.bytes / 8, "level {k}: {l:?}");
        assert_eq!(
            l.connectivity + l.geometry + l.colour + l.overhead,
            l.bytes,
            "level {k}"
        );
    }
}

#[test]
fn hostile_layouts_and_views_give_errors_not_panics() {
    let mesh = scan_like();
    let stream = encode(&mesh, &nested(2, 2, 3)).unwrap().bytes;
    let served = serve(&stream);
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut random = move || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        state
    };
    // Layouts and summaries of damaged streams.
    for _ in 0..300 {
        let mut b = stream.clone();
        let at = (random() % b.len() as u64) as usize;
        b[at] ^= 1 << (random() % 8);
        let _ = vitrine_codec::NestedSummary::of(&b);
        let cut = (random() % b.len() as u64) as usize;
        let _ = vitrine_codec::NestedSummary::of(&b[..cut]);
    }
    // A view given the wrong layouts or head is refused.
    let layouts: Vec<_> = served.parted.iter().map(|(_, l)| l.clone()).collect();
    let decoder = || {
        let mut d = Decoder::new(&stream[served.index.base.clone()], Limits::default()).unwrap();
        for chunk in &served.global {
            d.apply_batch(chunk).unwrap();
        }
        d
    };
    let (first, l0) = &served.parted[0];
    let head = &first[l0.head.clone()];
    assert!(decoder().into_nested_view(head, &layouts[1..]).is_err());
    let mut shuffled = layouts.clone();
    shuffled.swap(0, layouts.len() - 1);
    assert!(decoder().into_nested_view(head, &shuffled).is_err());
    assert!(decoder()
        .into_nested_view(&head[..head.len() / 2], &layouts)
        .is_err());
    // Damaged parts and split entries: errors or other charts, no panic.
    for _ in 0..60 {
        let mut view = decoder().into_nested_view(head, &layouts).unwrap();
        for phase in 0..view.phase_count() {
            if phase > 0 {
                for parent in 0..view.chart_count(phase - 1) {
                    let mut entry = entry_of(&served, phase - 1, parent).to_vec();
                    if entry.len() > 2 && random() % 4 == 0 {
                        let at = (random() % entry.len() as u64) as usize;
                        entry[at] ^= 1 << (random() % 8);
                    }
                    let _ = view.split(phase - 1, parent, &entry);
                }
            }
            for k in 0..view.chart_count(phase) {
                for part in parts_of(&served, phase, k) {
                    let mut part = part.to_vec();
                    if !part.is_empty() && random() % 16 == 0 {
                        let at = (random() % part.len() as u64) as usize;
                        part[at] ^= 1 << (random() % 8);
                    }
                    if view.apply_part(phase, k, &part).is_err() {
                        break;
                    }
                }
            }
        }
    }
}
