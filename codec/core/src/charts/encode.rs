//! The encoder's side of a charted stream: fine layers inside each chart,
//! global layers over what they leave, then the parted batches.

use super::{canonical_faces, cut, encode_labels, partition::partition};
use crate::encoder::{
    number_layers, plain_chunks, simplify, write_pass, EncodeOptions, EncodeProgress, Encoded,
    Layer, PatchGuard, QuantizedMesh,
};
use crate::format::{
    write_section, write_varint, ChunkHeader, Header, LevelInfo, CHARTED_VERSION, PARTED_TAG,
};
use crate::halfedge::{Connectivity, NONE};
use crate::quantize::Quantization;
use crate::{Error, Result};

/// A chart's fine layers stop once it has 1/`chart_reduction` of its
/// vertices left (or a layer removes too little): what remains, cut
/// vertices and coarse interiors, goes to the global layers, which every
/// member of a decoding pool runs in full before its charts. A large
/// chart's cut is a small part of it, so it can go further for little
/// size, and the pool saves far more time: at `--charts auto` (charts of
/// 50 k vertices or more), 1/8 → 1/16 took igea +1.05 → +1.42 % over the
/// plain stream and its 2 M upsample +1.32 → +1.52 %, and the slowest
/// member's decode 55.9 → 48.8 ms and 564 → 477 ms (1/32: +1.67 % and
/// +1.80 %, 46.9 and 464 ms). Charts of 9–34 k vertices paid +0.2 to
/// +1.8 points at 1/16, so they stop at 1/8.
/// docs/bench-log/2026-12-04-session-20-bounds.md
fn chart_reduction(vertices: usize) -> usize {
    if vertices >= LARGE_CHART {
        16
    } else {
        8
    }
}

/// Vertices from which a chart counts as large ([`chart_reduction`]).
const LARGE_CHART: usize = 50_000;

/// A chart after its layers.
pub(super) struct ChartLayers {
    /// Input vertex of each chart vertex (the chart's simplification input).
    pub vertices: Vec<u32>,
    /// Its coarse faces, in input vertex ids.
    pub coarse: Vec<[u32; 3]>,
    /// Finest first.
    pub layers: Vec<Layer>,
}

/// Encodes a checked, quantized mesh as a charted stream of `charts`
/// charts (2..=64), down to a base of `target` vertices; `None` when the
/// charts yield no fine layer (the caller writes a plain stream instead).
#[allow(clippy::too_many_arguments)]
pub(crate) fn encode_charted(
    positions: &[[i32; 3]],
    triangles: &[[u32; 3]],
    colours: Option<&[[u8; 3]]>,
    quantization: Quantization,
    options: &EncodeOptions,
    charts: usize,
    target: usize,
    guard: Option<&dyn PatchGuard>,
    culprit: impl FnOnce(Error) -> Error,
    progress: impl FnMut(EncodeProgress),
) -> Result<Option<Encoded>> {
    let n = positions.len();
    let labels = {
        let conn = Connectivity::from_indexed_triangles(n, triangles).map_err(culprit)?;
        // A cut that leaves a chart non-manifold: the plain stream instead.
        let Ok(labels) = partition(&conn, positions, charts) else {
            return Ok(None);
        };
        labels
    };
    let mut by_chart: Vec<Vec<[u32; 3]>> = vec![Vec::new(); charts];
    // The cut: vertices with faces in two charts or more.
    let mut owner = vec![NONE; n];
    let mut shared = vec![false; n];
    for (t, &label) in triangles.iter().zip(&labels) {
        by_chart[label as usize].push(*t);
        for &v in t {
            match owner[v as usize] {
                NONE => owner[v as usize] = label,
                o if o != label => shared[v as usize] = true,
                _ => {}
            }
        }
    }
    drop(labels);
    drop(owner);
    let mut scratch = vec![NONE; n];
    let fine: Vec<ChartLayers> = by_chart
        .iter()
        .map(|faces| {
            chart_layers(
                faces,
                &shared,
                positions,
                colours,
                quantization,
                options,
                guard,
                chart_reduction,
                &mut scratch,
            )
        })
        .collect::<Result<_>>()?;
    drop(by_chart);
    let fine_levels = fine.iter().map(|c| c.layers.len()).max().unwrap_or(0);
    if fine_levels == 0 {
        return Ok(None);
    }

    // The coarse mesh the charts leave, compacted, and its global layers.
    let mut coarse_vertices = Vec::new(); // coarse id → input id
    let mut coarse_faces = Vec::new();
    let mut coarse_labels = Vec::new();
    for (k, chart) in fine.iter().enumerate() {
        for t in &chart.coarse {
            coarse_faces.push(t.map(|v| {
                let slot = &mut scratch[v as usize];
                if *slot == NONE {
                    *slot = coarse_vertices.len() as u32;
                    coarse_vertices.push(v);
                }
                *slot
            }));
            coarse_labels.push(k as u32);
        }
    }
    for &v in &coarse_vertices {
        scratch[v as usize] = NONE;
    }
    let coarse_positions: Vec<[i32; 3]> = coarse_vertices
        .iter()
        .map(|&v| positions[v as usize])
        .collect();
    let coarse_colours: Option<Vec<[u8; 3]>> =
        colours.map(|c| coarse_vertices.iter().map(|&v| c[v as usize]).collect());
    let (global, global_layers) = simplify(
        QuantizedMesh {
            positions: &coarse_positions,
            triangles: &coarse_faces,
            colours: coarse_colours.as_deref(),
            max_value: quantization.max_value(),
        },
        Vec::new(),
        options,
        target,
        guard,
        |e| e,
        progress,
    )?;
    let plain = plain_chunks(
        &global,
        &global_layers,
        quantization,
        &coarse_positions,
        coarse_colours.as_deref(),
        CHARTED_VERSION,
    );
    drop(global);

    // The level where charts begin, as the decoder will have it, and its cut.
    let level_vertices = coarse_vertices.len();
    let level_faces: Vec<[u32; 3]> = coarse_faces
        .iter()
        .map(|t| t.map(|v| plain.new_id[v as usize]))
        .collect();
    let (faces, labels) = canonical_faces(&level_faces, level_vertices, &coarse_labels);
    drop(level_faces);
    let cuts = cut(&faces, &labels, charts, level_vertices);
    let labels_bytes = encode_labels(&faces, level_vertices, &labels, charts)?;

    // Each chart's ids: its cut's vertices, then its layers' in insertion order.
    let chart_ids: Vec<Vec<u32>> = fine
        .iter()
        .zip(&cuts)
        .map(|(chart, cut)| {
            for (c, &input) in chart.vertices.iter().enumerate() {
                scratch[input as usize] = c as u32;
            }
            let mut order: Vec<u32> = cut
                .global
                .iter()
                .map(|&g| {
                    scratch[coarse_vertices[plain.vertex_order[g as usize] as usize] as usize]
                })
                .collect();
            for &input in &chart.vertices {
                scratch[input as usize] = NONE;
            }
            number_layers(&mut order, &chart.layers, chart.vertices.len())
        })
        .collect();

    let mut tail = Tail {
        vertex_order: plain
            .vertex_order
            .iter()
            .map(|&c| coarse_vertices[c as usize])
            .collect(),
        levels: plain.levels,
        bytes: plain.chunks,
        vertices: level_vertices,
        faces: faces.len(),
    };
    for j in 0..fine_levels {
        let mut payload = Vec::new();
        write_varint(&mut payload, charts as u32);
        if j == 0 {
            write_section(&mut payload, &labels_bytes);
        }
        // A chart with fewer layers than the deepest sits out the coarsest levels.
        let parts = fine.iter().zip(&chart_ids).map(|(chart, ids)| {
            let layer = chart.layers.get(fine_levels - 1 - j);
            (layer, chart.vertices.as_slice(), ids.as_slice())
        });
        tail.parted_batch(payload, CHARTED_VERSION, parts);
    }
    Ok(Some(tail.finish(
        CHARTED_VERSION,
        colours.is_some(),
        quantization,
    )))
}

/// A charted stream after its global batches, as the parted batches are
/// appended to it.
pub(super) struct Tail {
    pub levels: Vec<LevelInfo>,
    pub bytes: Vec<u8>,
    /// The input vertex of each stream vertex, in stream order.
    pub vertex_order: Vec<u32>,
    /// Vertices and faces of the last level.
    pub vertices: usize,
    pub faces: usize,
}

impl Tail {
    /// Appends a parted batch of `version` whose payload so far is
    /// `payload` (its head), then each chart's part: its layer's two passes
    /// in the chart's ids, or an empty part where the chart has no layer in
    /// this batch. Each chart comes with its vertices' input ids and its ids.
    pub(super) fn parted_batch<'a>(
        &mut self,
        mut payload: Vec<u8>,
        version: u8,
        charts: impl Iterator<Item = (Option<&'a Layer>, &'a [u32], &'a [u32])>,
    ) {
        let mut added = 0;
        for (layer, vertices, ids) in charts {
            let Some(layer) = layer else {
                write_varint(&mut payload, 0);
                continue;
            };
            let mut part = Vec::new();
            write_pass(&mut part, &layer.cleaning, ids);
            write_pass(&mut part, &layer.decimating, ids);
            write_section(&mut payload, &part);
            for &v in layer
                .cleaning
                .removed
                .iter()
                .chain(&layer.decimating.removed)
            {
                self.vertex_order.push(vertices[v as usize]);
            }
            added += layer.cleaning.removed.len() + layer.decimating.removed.len();
        }
        let mut chunk = Vec::new();
        ChunkHeader {
            tag: PARTED_TAG,
            version,
            level: self.levels.len() as u16,
            vertices_before: self.vertices as u32,
            vertices_after: (self.vertices + added) as u32,
            faces_after: (self.faces + 2 * added) as u32,
            payload_len: payload.len() as u32,
        }
        .write(&mut chunk);
        chunk.extend_from_slice(&payload);
        self.vertices += added;
        self.faces += 2 * added;
        self.levels.push(LevelInfo {
            vertices: self.vertices as u32,
            faces: self.faces as u32,
            bytes: chunk.len() as u32,
        });
        self.bytes.extend_from_slice(&chunk);
    }

    /// The stream: its header, then every chunk.
    pub(super) fn finish(
        self,
        version: u8,
        has_colour: bool,
        quantization: Quantization,
    ) -> Encoded {
        let header = Header {
            version,
            has_colour,
            quantization,
            levels: self.levels,
        };
        let mut stream = Vec::with_capacity(header.byte_len() + self.bytes.len());
        header.write(&mut stream);
        stream.extend_from_slice(&self.bytes);
        Encoded {
            bytes: stream,
            vertex_order: self.vertex_order,
            header,
        }
    }
}

/// Simplifies one chart (its faces in input ids) with the vertices `shared`
/// marks (its cut) as borders, down to 1/`reduction(its vertices)` of its
/// vertices; `scratch` is all `NONE` on entry and on return.
#[allow(clippy::too_many_arguments)]
pub(super) fn chart_layers(
    faces: &[[u32; 3]],
    shared: &[bool],
    positions: &[[i32; 3]],
    colours: Option<&[[u8; 3]]>,
    quantization: Quantization,
    options: &EncodeOptions,
    guard: Option<&dyn PatchGuard>,
    reduction: impl Fn(usize) -> usize,
    scratch: &mut [u32],
) -> Result<ChartLayers> {
    let mut vertices = Vec::new();
    let local: Vec<[u32; 3]> = faces
        .iter()
        .map(|t| {
            t.map(|v| {
                let slot = &mut scratch[v as usize];
                if *slot == NONE {
                    *slot = vertices.len() as u32;
                    vertices.push(v);
                }
                *slot
            })
        })
        .collect();
    for &v in &vertices {
        scratch[v as usize] = NONE;
    }
    if faces.is_empty() {
        return Ok(ChartLayers {
            vertices,
            coarse: Vec::new(),
            layers: Vec::new(),
        });
    }
    let chart_positions: Vec<[i32; 3]> = vertices.iter().map(|&v| positions[v as usize]).collect();
    let chart_colours: Option<Vec<[u8; 3]>> =
        colours.map(|c| vertices.iter().map(|&v| c[v as usize]).collect());
    let (s, layers) = simplify(
        QuantizedMesh {
            positions: &chart_positions,
            triangles: &local,
            colours: chart_colours.as_deref(),
            max_value: quantization.max_value(),
        },
        vertices.iter().map(|&v| shared[v as usize]).collect(),
        options,
        vertices.len() / reduction(vertices.len()),
        guard,
        |e| e,
        |_| {},
    )?;
    let coarse = s
        .conn
        .triangles()
        .map(|t| t.map(|v| vertices[s.ids[v as usize] as usize]))
        .collect();
    Ok(ChartLayers {
        vertices,
        coarse,
        layers,
    })
}
