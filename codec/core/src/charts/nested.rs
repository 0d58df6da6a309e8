//! Nested charts (format 6): the encoder's side.
//!
//! The mesh is cut into a tree of charts, top down: `top` charts over the
//! whole mesh, then each chart into up to `fanout` children, and so on,
//! `phases` levels deep. It is simplified bottom up: every leaf alone with
//! every leaf cut frozen, then every parent over its children's coarse
//! faces with only its own cut (against the other charts of its phase)
//! frozen, and so on up to the top charts; the global layers take what the
//! top charts leave down to the base. The stream codes it coarse to fine:
//! base, global batches, then one **phase** of parted batches per tree
//! level, the first batch of each later phase splitting every chart of the
//! phase before into its children (FORMAT.md, "Nested charts (version 6)").
//!
//! A phase's cut is frozen in its charts and in all their descendants, and
//! no retriangulation joins two vertices of the cut of its phase, so no two
//! charts make the same edge: charts at any mix of depths share their
//! borders bit for bit.

use super::encode::{chart_layers, ChartLayers, Tail};
use super::{canonical_faces, cut, encode_labels, partition::partition, MAX_CHARTS};
use crate::encoder::{
    number_layers, plain_chunks, simplify, EncodeOptions, Encoded, Layer, PatchGuard, QuantizedMesh,
};
use crate::format::{write_section, write_varint, NESTED_VERSION};
use crate::halfedge::{Connectivity, NONE};
use crate::quantize::Quantization;
use crate::{Error, Result};

/// The most charts one phase of a nested stream may have.
pub const MAX_PHASE_CHARTS: usize = 4096;

/// Input vertices per leaf that [`Shape::for_vertices`] aims at, at least.
pub const LEAF_VERTICES: usize = 60_000;

/// How a leaf chart is simplified: down to 1/`LEAF_REDUCTION` of its
/// vertices (or until a layer removes under 2 %).
const LEAF_REDUCTION: usize = 8;

/// How a chart above the leaves is simplified: its children's coarse
/// faces down to 1/`INNER_REDUCTION` of their vertices.
const INNER_REDUCTION: usize = 4;

/// The tree of a nested stream: `top` charts, split `phases − 1` times
/// into up to `fanout` children each.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    pub top: usize,
    pub fanout: usize,
    pub phases: usize,
}

impl Shape {
    /// A checked shape: 2..=64 top charts, 1..=64 children, at most
    /// [`MAX_PHASE_CHARTS`] leaves.
    pub fn new(top: usize, fanout: usize, phases: usize) -> Result<Shape> {
        let leaves = (1..phases).try_fold(top, |k, _| k.checked_mul(fanout));
        if !(2..=MAX_CHARTS).contains(&top)
            || !(1..=MAX_CHARTS).contains(&fanout)
            || phases == 0
            || leaves.is_none_or(|l| l > MAX_PHASE_CHARTS)
        {
            return Err(Error::Parameter(format!(
                "nested charts: {top} top charts, {fanout} children, {phases} phases is out of range"
            )));
        }
        Ok(Shape {
            top,
            fanout,
            phases,
        })
    }

    /// A binary tree whose leaves have [`LEAF_VERTICES`] input vertices
    /// or more (2 top charts at least). On igea upsampled to 2.1 M
    /// vertices, binary trees cost the fewest bytes for a close-up: 2 top
    /// charts split in 2 down to 32 leaves, +5.8 % over format 4 for a
    /// close-up of 5.9 % of the stream (16 leaves: +3.5 %, 9.5 %; 4 × 4 × 4
    /// leaves: +8.3 %, 5.2 %; docs/bench-log/2026-12-07-session-29-nested.md).
    pub fn for_vertices(vertices: usize) -> Shape {
        let leaves = vertices / LEAF_VERTICES;
        let mut phases = 1;
        let mut k = 2;
        while k * 2 <= leaves && k * 2 <= MAX_PHASE_CHARTS {
            k *= 2;
            phases += 1;
        }
        Shape {
            top: 2,
            fanout: 2,
            phases,
        }
    }
}

/// One chart of the tree after its layers.
struct Node {
    /// Input vertex of each of its simplification's vertices (local ids).
    vertices: Vec<u32>,
    /// Its simplification's input faces, in input ids: a leaf's own faces,
    /// or its children's coarse faces, child by child.
    faces: Vec<[u32; 3]>,
    /// For a chart above the leaves: the child (0..) of each of `faces`.
    child_of: Vec<u32>,
    /// Its faces after its layers, in input ids.
    coarse: Vec<[u32; 3]>,
    /// Finest first.
    layers: Vec<Layer>,
    /// Its children in the next phase (empty for a leaf).
    children: std::ops::Range<usize>,
}

/// Encodes a checked, quantized mesh as a nested-chart stream of `shape`,
/// down to a base of `target` vertices; `None` when the charts cannot be
/// cut or a phase makes no layer (the caller writes a plain stream).
#[allow(clippy::too_many_arguments)]
pub(crate) fn encode_nested(
    positions: &[[i32; 3]],
    triangles: &[[u32; 3]],
    colours: Option<&[[u8; 3]]>,
    quantization: Quantization,
    options: &EncodeOptions,
    shape: Shape,
    target: usize,
    guard: Option<&dyn PatchGuard>,
    culprit: impl FnOnce(Error) -> Error,
) -> Result<Option<Encoded>> {
    let n = positions.len();
    let mut scratch = vec![NONE; n];
    // The tree, top down: each phase's chart of every input face, and each
    // phase's charts' children in the next.
    let mut labels: Vec<Vec<u32>> = Vec::with_capacity(shape.phases);
    let mut children: Vec<Vec<std::ops::Range<usize>>> = Vec::with_capacity(shape.phases);
    {
        let conn = Connectivity::from_indexed_triangles(n, triangles).map_err(culprit)?;
        let Ok(top) = partition(&conn, positions, shape.top) else {
            return Ok(None);
        };
        let top = compact_labels(top);
        if chart_count(&top) < 2 {
            return Ok(None);
        }
        labels.push(top);
    }
    for _ in 1..shape.phases {
        let parents = labels.last().expect("phase 0 above");
        let count = chart_count(parents);
        let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); count];
        for (f, &l) in parents.iter().enumerate() {
            faces_of[l as usize].push(f as u32);
        }
        let mut next = vec![0u32; triangles.len()];
        let mut ranges = Vec::with_capacity(count);
        let mut first = 0usize;
        for faces in &faces_of {
            let local = split(faces, triangles, positions, shape.fanout, &mut scratch);
            let c = chart_count(&local).max(1);
            for (&f, &l) in faces.iter().zip(&local) {
                next[f as usize] = (first + l as usize) as u32;
            }
            ranges.push(first..first + c);
            first += c;
        }
        children.push(ranges);
        labels.push(next);
    }
    children.push(Vec::new());

    // Bottom up: each phase's charts simplified over what the next left.
    let mut phases: Vec<Vec<Node>> = Vec::with_capacity(shape.phases);
    for d in (0..shape.phases).rev() {
        let count = chart_count(&labels[d]);
        let shared = shared_vertices(triangles, &labels[d], n);
        let mut inputs: Vec<(Vec<[u32; 3]>, Vec<u32>)> = vec![Default::default(); count];
        match phases.last() {
            None => {
                for (t, &l) in triangles.iter().zip(&labels[d]) {
                    inputs[l as usize].0.push(*t);
                }
            }
            Some(below) => {
                for (k, input) in inputs.iter_mut().enumerate() {
                    for (c, child) in children[d][k].clone().enumerate() {
                        let coarse = &below[child].coarse;
                        input.0.extend_from_slice(coarse);
                        input.1.extend(std::iter::repeat_n(c as u32, coarse.len()));
                    }
                }
            }
        }
        let reduction = if phases.is_empty() {
            LEAF_REDUCTION
        } else {
            INNER_REDUCTION
        };
        let nodes = inputs
            .into_iter()
            .enumerate()
            .map(|(k, (faces, child_of))| {
                let ChartLayers {
                    vertices,
                    coarse,
                    layers,
                } = chart_layers(
                    &faces,
                    &shared,
                    positions,
                    colours,
                    quantization,
                    options,
                    guard,
                    |_| reduction,
                    &mut scratch,
                )?;
                Ok(Node {
                    vertices,
                    faces,
                    child_of,
                    coarse,
                    layers,
                    children: children[d].get(k).cloned().unwrap_or(0..0),
                })
            })
            .collect::<Result<Vec<Node>>>()?;
        if nodes.iter().all(|c| c.layers.is_empty()) {
            // A phase with no batch could not carry its split.
            return Ok(None);
        }
        phases.push(nodes);
    }
    phases.reverse();
    drop(labels);

    // The coarse mesh the top charts leave, compacted, and its global layers.
    let mut coarse_vertices = Vec::new(); // coarse id → input id
    let mut coarse_faces = Vec::new();
    let mut coarse_labels = Vec::new();
    for (k, chart) in phases[0].iter().enumerate() {
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
        |_| {},
    )?;
    let plain = plain_chunks(
        &global,
        &global_layers,
        quantization,
        &coarse_positions,
        coarse_colours.as_deref(),
        NESTED_VERSION,
    );
    drop(global);

    // Phase 0 begins where the global batches leave the mesh: version 5's cut.
    let level_vertices = coarse_vertices.len();
    let level_faces: Vec<[u32; 3]> = coarse_faces
        .iter()
        .map(|t| t.map(|v| plain.new_id[v as usize]))
        .collect();
    let top = phases[0].len();
    let (faces, top_labels) = canonical_faces(&level_faces, level_vertices, &coarse_labels);
    drop(level_faces);
    let cuts = cut(&faces, &top_labels, top, level_vertices);
    let top_head = encode_labels(&faces, level_vertices, &top_labels, top)?;
    drop(faces);
    // Each chart's numbering: its first vertices (in input ids), then its
    // layers' insertions; kept as every local vertex's chart id.
    let mut chart_ids: Vec<Vec<Vec<u32>>> = Vec::with_capacity(phases.len());
    chart_ids.push(
        phases[0]
            .iter()
            .zip(&cuts)
            .map(|(node, cut)| {
                let first: Vec<u32> = cut
                    .global
                    .iter()
                    .map(|&g| coarse_vertices[plain.vertex_order[g as usize] as usize])
                    .collect();
                numbering(node, &first, &mut scratch)
            })
            .collect(),
    );
    drop(cuts);
    let mut heads = vec![top_head];
    for d in 1..phases.len() {
        let mut head = Vec::new();
        let mut ids = Vec::with_capacity(phases[d].len());
        for (parent, parent_ids) in phases[d - 1].iter().zip(&chart_ids[d - 1]) {
            let kids = &phases[d][parent.children.clone()];
            write_varint(&mut head, kids.len() as u32);
            // The parent's chart id of each of its vertices, and back.
            let mut order = vec![0u32; parent_ids.len()];
            for (local, &id) in parent_ids.iter().enumerate() {
                order[id as usize] = parent.vertices[local];
            }
            if kids.len() == 1 {
                // One child keeps its parent's ids.
                ids.push(numbering(&kids[0], &order, &mut scratch));
                continue;
            }
            for (local, &v) in parent.vertices.iter().enumerate() {
                scratch[v as usize] = parent_ids[local];
            }
            let level: Vec<[u32; 3]> = parent
                .faces
                .iter()
                .map(|t| t.map(|v| scratch[v as usize]))
                .collect();
            for &v in &parent.vertices {
                scratch[v as usize] = NONE;
            }
            let (faces, child_labels) = canonical_faces(&level, order.len(), &parent.child_of);
            write_section(
                &mut head,
                &encode_labels(&faces, order.len(), &child_labels, kids.len())?,
            );
            for (kid, c) in kids
                .iter()
                .zip(cut(&faces, &child_labels, kids.len(), order.len()))
            {
                let first: Vec<u32> = c.global.iter().map(|&g| order[g as usize]).collect();
                ids.push(numbering(kid, &first, &mut scratch));
            }
        }
        heads.push(head);
        chart_ids.push(ids);
    }

    let mut tail = Tail {
        vertex_order: plain
            .vertex_order
            .iter()
            .map(|&c| coarse_vertices[c as usize])
            .collect(),
        levels: plain.levels,
        bytes: plain.chunks,
        vertices: level_vertices,
        faces: coarse_faces.len(),
    };
    for (d, (charts, ids)) in phases.iter().zip(&chart_ids).enumerate() {
        let depth = charts.iter().map(|c| c.layers.len()).max().unwrap_or(0);
        for j in 0..depth {
            let mut payload = vec![0]; // deferred precision: none
            write_varint(&mut payload, d as u32);
            write_varint(&mut payload, charts.len() as u32);
            if j == 0 {
                write_section(&mut payload, &heads[d]);
            }
            // Charts with fewer layers sit out the phase's first batches.
            let parts = charts.iter().zip(ids).map(|(chart, ids)| {
                let layer = chart.layers.get(depth - 1 - j);
                (layer, chart.vertices.as_slice(), ids.as_slice())
            });
            tail.parted_batch(payload, NESTED_VERSION, parts);
        }
    }
    Ok(Some(tail.finish(
        NESTED_VERSION,
        colours.is_some(),
        quantization,
    )))
}

/// Charts in a phase: one more than the largest label.
fn chart_count(labels: &[u32]) -> usize {
    labels.iter().max().map_or(0, |&l| l as usize + 1)
}

/// Labels renumbered 0.. in order with the empty charts left out.
fn compact_labels(mut labels: Vec<u32>) -> Vec<u32> {
    let mut used = vec![NONE; chart_count(&labels)];
    for &l in &labels {
        used[l as usize] = 0;
    }
    let mut next = 0;
    for u in &mut used {
        if *u == 0 {
            *u = next;
            next += 1;
        }
    }
    for l in &mut labels {
        *l = used[*l as usize];
    }
    labels
}

/// A chart's faces (input face ids) split into up to `fanout` children:
/// each face's child, 0.., every child a manifold; all 0 when it cannot be
/// cut. `scratch` is all `NONE` on entry and on return.
fn split(
    faces: &[u32],
    triangles: &[[u32; 3]],
    positions: &[[i32; 3]],
    fanout: usize,
    scratch: &mut [u32],
) -> Vec<u32> {
    if fanout < 2 || faces.len() < 2 * fanout {
        return vec![0; faces.len()];
    }
    let mut vertices = Vec::new();
    let local: Vec<[u32; 3]> = faces
        .iter()
        .map(|&f| {
            triangles[f as usize].map(|v| {
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
    let local_positions: Vec<[i32; 3]> = vertices.iter().map(|&v| positions[v as usize]).collect();
    let cut = Connectivity::from_indexed_triangles(vertices.len(), &local)
        .ok()
        .and_then(|conn| partition(&conn, &local_positions, fanout).ok());
    match cut {
        Some(labels) => compact_labels(labels),
        None => vec![0; faces.len()],
    }
}

/// Vertices with faces in two charts or more of `labels`.
fn shared_vertices(triangles: &[[u32; 3]], labels: &[u32], n: usize) -> Vec<bool> {
    let mut owner = vec![NONE; n];
    let mut shared = vec![false; n];
    for (t, &label) in triangles.iter().zip(labels) {
        for &v in t {
            match owner[v as usize] {
                NONE => owner[v as usize] = label,
                o if o != label => shared[v as usize] = true,
                _ => {}
            }
        }
    }
    shared
}

/// The chart id of each of `node`'s local vertices: `first` (input ids,
/// the vertices the split gave the chart) numbered 0.., then its layers'
/// insertions. `scratch` is all `NONE` on entry and on return.
fn numbering(node: &Node, first: &[u32], scratch: &mut [u32]) -> Vec<u32> {
    for (local, &v) in node.vertices.iter().enumerate() {
        scratch[v as usize] = local as u32;
    }
    let mut order: Vec<u32> = first.iter().map(|&v| scratch[v as usize]).collect();
    for &v in &node.vertices {
        scratch[v as usize] = NONE;
    }
    number_layers(&mut order, &node.layers, node.vertices.len())
}
