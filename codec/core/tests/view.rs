//! View-dependent decoding (issue 41): the charts of a charted stream
//! refine each to its own depth from their parts alone, bit for bit as the
//! full decoder's, watertight at any mix of depths, and hostile parts cost
//! one chart its depth, never the view.

use vitrine_codec::{
    encode, part_table, ChartView, Charts, Decoder, EncodeOptions, IndexedMesh, Limits,
    PartedLayout, StreamIndex,
};
use vitrine_samples::{add_noise, paint, torus};

/// A painted, noisy, closed torus of 24 k vertices.
fn closed_scan() -> IndexedMesh {
    let mut mesh = torus(240, 100, 1.0, 0.35);
    add_noise(&mut mesh, 0.003, 23);
    paint(&mut mesh);
    mesh
}

fn charted(mesh: &IndexedMesh, k: u32) -> Vec<u8> {
    let options = EncodeOptions {
        charts: Charts::Count(k),
        ..EncodeOptions::default()
    };
    encode(mesh, &options).unwrap().bytes
}

/// A stream split as a server serves it: the global batches' chunks, and
/// each parted batch's chunk with its layout.
struct Served<'a> {
    index: StreamIndex,
    global: Vec<&'a [u8]>,
    parted: Vec<(&'a [u8], PartedLayout)>,
}

fn serve(stream: &[u8]) -> Served<'_> {
    let index = StreamIndex::parse(stream).unwrap();
    let (mut global, mut parted) = (Vec::new(), Vec::new());
    for range in &index.batches {
        let chunk = &stream[range.clone()];
        match PartedLayout::parse(chunk).unwrap() {
            Some(layout) => parted.push((chunk, layout)),
            None => {
                assert!(parted.is_empty(), "a whole-mesh batch after parted ones");
                global.push(chunk);
            }
        }
    }
    Served {
        index,
        global,
        parted,
    }
}

fn view_of(stream: &[u8], served: &Served, limits: Limits) -> ChartView {
    let mut d = Decoder::new(&stream[served.index.base.clone()], limits).unwrap();
    for chunk in &served.global {
        d.apply_batch(chunk).unwrap();
    }
    let (first, layout) = &served.parted[0];
    d.into_view(&first[layout.head.clone()]).unwrap()
}

/// One chart's buffers: quantized positions, triangles, colours.
type ChartBuffers = (Vec<[i32; 3]>, Vec<u32>, Option<Vec<u8>>);

fn buffers(view: &ChartView, k: usize) -> ChartBuffers {
    let c = view.chart(k).unwrap();
    (
        c.quantized.to_vec(),
        c.indices.to_vec(),
        c.colours.map(<[u8]>::to_vec),
    )
}

#[test]
fn each_chart_at_its_own_depth_is_the_full_decoders_chart_bit_for_bit() {
    let stream = charted(&closed_scan(), 6);
    let served = serve(&stream);
    let depths = served.parted.len();
    assert!(depths >= 2, "{depths} parted batches");

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
                .map(|k| {
                    let c = full.chart(k).unwrap();
                    (
                        c.quantized.to_vec(),
                        c.indices.to_vec(),
                        c.colours.map(<[u8]>::to_vec),
                    )
                })
                .collect(),
        );
    }

    // Chart k goes to depth k mod (depths + 1): some stay at the cut, one
    // reaches the final level, the rest stop in between.
    let mut view = view_of(&stream, &served, Limits::default());
    assert_eq!(view.chart_count(), 6);
    assert_eq!(view.final_depth(), depths);
    for k in 0..view.chart_count() {
        let target = k % (depths + 1);
        for (chunk, layout) in &served.parted[..target] {
            view.apply_part(k, &chunk[layout.parts[k].clone()]).unwrap();
        }
        assert_eq!(view.depth(k), target);
        if target > 0 {
            assert!(
                buffers(&view, k) == expected[target - 1][k],
                "chart {k} at depth {target} differs from the full decoder's"
            );
        }
    }
    let resident: usize = (0..6).map(|k| view.chart(k).unwrap().quantized.len()).sum();
    assert_eq!(view.resident_vertices(), resident);
}

/// Every edge of the charts shown together, with cut vertices named by
/// their id where the charts begin, lies on exactly two triangles.
fn assert_watertight(view: &ChartView) {
    let mut edges: Vec<((usize, u32), (usize, u32))> = Vec::new();
    for k in 0..view.chart_count() {
        let cut = view.cut_ids(k);
        let name = |v: u32| match cut.get(v as usize) {
            Some(&id) => (usize::MAX, id),
            None => (k, v),
        };
        for t in view.chart(k).unwrap().indices.chunks_exact(3) {
            for c in 0..3 {
                let (a, b) = (name(t[c]), name(t[(c + 1) % 3]));
                edges.push(if a < b { (a, b) } else { (b, a) });
            }
        }
    }
    edges.sort_unstable();
    let mut i = 0;
    while i < edges.len() {
        let run = edges[i..].iter().take_while(|&&e| e == edges[i]).count();
        assert_eq!(run, 2, "edge {:?} lies on {run} triangles", edges[i]);
        i += run;
    }
}

#[test]
fn charts_at_different_depths_stay_watertight_and_go_back_to_the_cut() {
    let stream = charted(&closed_scan(), 5);
    let served = serve(&stream);
    let mut view = view_of(&stream, &served, Limits::default());
    assert_watertight(&view);
    let at_cut = view.resident_vertices();
    let chart0_at_cut = buffers(&view, 0);
    for (depth, (chunk, layout)) in served.parted.iter().enumerate() {
        // Chart 0 to the end, chart 2 one batch behind, the rest stay.
        view.apply_part(0, &chunk[layout.parts[0].clone()]).unwrap();
        if depth + 1 < served.parted.len() {
            view.apply_part(2, &chunk[layout.parts[2].clone()]).unwrap();
        }
        assert_watertight(&view);
    }
    let deep = buffers(&view, 0);
    assert!(view.resident_vertices() > at_cut);

    // Back to the cut frees what chart 0 grew; refined again, the same bits.
    view.reset(0);
    assert_eq!(view.depth(0), 0);
    assert!(buffers(&view, 0) == chart0_at_cut);
    assert_watertight(&view);
    for (chunk, layout) in &served.parted {
        view.apply_part(0, &chunk[layout.parts[0].clone()]).unwrap();
    }
    assert!(buffers(&view, 0) == deep);
}

#[test]
fn hostile_parts_cost_their_chart_its_depth_and_nothing_else() {
    let stream = charted(&closed_scan(), 4);
    let served = serve(&stream);
    let mut view = view_of(&stream, &served, Limits::default());
    let (chunk0, layout0) = &served.parted[0];
    let part = |k: usize| &chunk0[layout0.parts[k].clone()];
    view.apply_part(1, part(1)).unwrap();
    let chart1 = buffers(&view, 1);
    view.apply_part(0, part(0)).unwrap();

    // Chart 0's second part replaced by chart 3's first: well-formed bytes
    // that may even decode (nothing in a part names its chart); refused,
    // chart 0 is back at the cut; either way no panic and chart 1 untouched.
    match view.apply_part(0, part(3)) {
        Ok(()) => assert_eq!(view.depth(0), 2),
        Err(_) => assert!(view.depth(0) <= 1),
    }
    assert_eq!(view.depth(1), 1);
    assert!(buffers(&view, 1) == chart1);

    // Truncated parts and noise, on chart 2's first non-empty part (a
    // chart may sit the first parted batches out).
    let mut batch = 0;
    loop {
        let (chunk, layout) = &served.parted[batch];
        let p = &chunk[layout.parts[2].clone()];
        if !p.is_empty() {
            break;
        }
        view.apply_part(2, p).unwrap();
        batch += 1;
    }
    let (chunk, layout) = &served.parted[batch];
    let p = &chunk[layout.parts[2].clone()];
    for cut in [1, p.len() / 2, p.len() - 1] {
        assert!(view.apply_part(2, &p[..cut]).is_err(), "{cut} bytes");
        // Refused before it touched the chart, or part-way and back to the cut.
        let depth = view.depth(2);
        assert!(depth == batch || depth == 0, "depth {depth}");
        for (chunk, layout) in &served.parted[depth..batch] {
            view.apply_part(2, &chunk[layout.parts[2].clone()]).unwrap();
        }
    }
    assert!(view.apply_part(2, &[0xff; 64]).is_err());
    assert!(view.apply_part(9, p).is_err(), "no chart 9");
    for (chunk, layout) in &served.parted[view.depth(2)..=batch] {
        view.apply_part(2, &chunk[layout.parts[2].clone()]).unwrap();
    }

    // Past the final level.
    for (chunk, layout) in &served.parted {
        view.apply_part(3, &chunk[layout.parts[3].clone()]).unwrap();
    }
    assert!(view.apply_part(3, &[]).is_err());

    // A vertex budget the view may not pass.
    let mut small = view_of(&stream, &served, Limits::default());
    small.set_vertex_budget(small.resident_vertices() + 10);
    let before = buffers(&small, 0);
    let refused = small.apply_part(0, part(0));
    assert!(
        matches!(refused, Err(vitrine_codec::Error::Limit(_))),
        "{refused:?}"
    );
    assert!(small.depth(0) == 0 && buffers(&small, 0) == before);
    // Room made (another chart reset), the same part goes in.
    small.set_vertex_budget(usize::MAX);
    small.apply_part(0, part(0)).unwrap();

    // The head of another batch, or a plain stream, is no cut.
    let mut d = Decoder::new(&stream[served.index.base.clone()], Limits::default()).unwrap();
    for chunk in &served.global {
        d.apply_batch(chunk).unwrap();
    }
    let (chunk1, layout1) = &served.parted[1];
    assert!(d.into_view(&chunk1[layout1.head.clone()]).is_err());
    let plain = encode(&closed_scan(), &EncodeOptions::default())
        .unwrap()
        .bytes;
    let index = StreamIndex::parse(&plain).unwrap();
    let d = Decoder::new(&plain[index.base.clone()], Limits::default()).unwrap();
    assert!(d.into_view(&[2, 0]).is_err());
}

#[test]
fn the_part_table_places_every_part_and_measures_what_it_removes() {
    let mesh = closed_scan();
    let stream = charted(&mesh, 6);
    let served = serve(&stream);
    let table = part_table(&stream, Limits::default()).unwrap();
    assert_eq!(table.len(), served.parted.len() * 6);
    let first_parted = served.global.len() + 1;
    let cut_level = served.index.header.levels[first_parted - 1].vertices as usize;
    let inserted: usize = table.iter().map(|r| r.inserted).sum();
    let last = served.index.header.final_level().vertices as usize;
    assert_eq!(inserted, last - cut_level);
    for r in &table {
        let (chunk, layout) = &served.parted[r.level - first_parted];
        assert_eq!(layout.level, r.level);
        let offset = chunk.as_ptr() as usize - stream.as_ptr() as usize;
        let part = &layout.parts[r.chart];
        assert_eq!(r.bytes, offset + part.start..offset + part.end);
        assert_eq!(r.inserted == 0, r.error_steps == 0, "{r:?}");
    }
    // Coarser parts remove more: the largest error of the first parted
    // batch exceeds the last one's, and none exceeds the torus's size
    // (4,096 steps across at 12 bits).
    let worst = |level: usize| {
        table
            .iter()
            .filter(|r| r.level == level)
            .map(|r| r.error_steps)
            .max()
            .unwrap()
    };
    let last_level = served.index.header.batch_count();
    assert!(
        worst(first_parted) > worst(last_level),
        "{} then {}",
        worst(first_parted),
        worst(last_level)
    );
    assert!(table.iter().all(|r| r.error_steps < 4096));
    // A plain stream has no parts.
    let plain = encode(&mesh, &EncodeOptions::default()).unwrap().bytes;
    assert!(part_table(&plain, Limits::default()).unwrap().is_empty());
}
