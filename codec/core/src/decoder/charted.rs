//! A charted stream (format 5) once its charts are cut: one level per chart,
//! each refined by its part of every parted batch, on its own thread where
//! threads exist, then merged into the level the caller sees.

use std::ops::Range;

use super::conquest::{PassInput, Scratch};
use super::{read_pass, Level};
use crate::charts::{
    canonical_level, chart_connectivity, cut, decode_labels, CanonicalLevel, MAX_CHARTS,
};
use crate::format::Reader;
use crate::gates::PassKind;
use crate::room::{self, Growth};
use crate::{Error, Result};

pub(super) struct Charted {
    charts: Vec<Chart>,
    /// The merged level's triangle list, in the level's vertex ids (as
    /// when the decoder stopped merging, once it refines only some charts).
    pub indices: Vec<u32>,
    /// The triangles of the charts this decoder refines, in level ids,
    /// once it refines only some.
    owned: Vec<u32>,
    /// Where each chart's triangles are in `indices`, or in `owned` once
    /// the decoder refines only some (empty for the others).
    ranges: Vec<Range<usize>>,
    /// The decoder refines only some charts: `owned` and `ranges` hold theirs.
    some: bool,
    /// A nested stream's phase (format 6): how many splits made the charts.
    phase: usize,
}

pub(super) struct Chart {
    level: Level,
    scratch: Scratch,
    /// The level's id of each chart vertex.
    global: Vec<u32>,
    /// Chart vertices before the last batch applied: those after it are
    /// the batch's insertions.
    before_last: usize,
}

/// One chart of a charted level, in the chart's own vertex ids (see
/// [`crate::Decoder::chart`]).
#[derive(Clone, Copy, Debug)]
pub struct ChartLevel<'a> {
    /// `x, y, z` per chart vertex, in model units.
    pub positions: &'a [f32],
    /// `r, g, b` per chart vertex, when the stream has colour.
    pub colours: Option<&'a [u8]>,
    /// The chart's triangles, three chart vertex ids each.
    pub indices: &'a [u32],
    /// The same triangles in the level's vertex ids (empty for a chart the
    /// decoder leaves to others, and in a [`crate::ChartView`]).
    pub level_indices: &'a [u32],
    /// Quantized positions per chart vertex: exactly the encoder's input.
    pub quantized: &'a [[i32; 3]],
    /// The chart's vertices before the last batch: the ones from here on
    /// are that batch's insertions, in order, and their level ids follow
    /// each other (those of earlier charts' insertions before them).
    pub new_from: usize,
}

/// One chart's part of a parted batch: its cleaning and decimating passes
/// and its size in bytes; `None` when the chart sits the batch out.
pub(super) type Part<'a> = Option<(PassInput<'a>, PassInput<'a>, usize)>;

impl Charted {
    /// Cuts `level` (where the global batches left it) into `charts` charts
    /// by the labels coded in `labels`; `level` is not changed.
    /// `labelled`: what [`Charted::labelled`] made of the same labels, if
    /// it was asked before.
    pub(super) fn cut(
        level: &Level,
        labels: &[u8],
        charts: usize,
        labelled: Option<Labelled>,
    ) -> Result<Charted> {
        let (canonical, labels) = match labelled {
            Some(l) if l.bytes == labels && l.charts == charts => (l.level, l.labels),
            _ => labelled_faces(level, labels, charts)?,
        };
        let count = charts;
        let cuts = cut(canonical.faces(), &labels, charts, level.vertex_count());
        let pick = |v: &u32| *v as usize;
        let charts = chart_connectivity(cuts, &labels, &canonical.adjacency)
            .map_err(|e| Error::stream(format!("a chart is not a manifold: {e}")))?
            .into_iter()
            .map(|(global, conn)| Chart {
                level: Level {
                    conn,
                    quantization: level.quantization,
                    positions_q: global.iter().map(|v| level.positions_q[pick(v)]).collect(),
                    positions: global.iter().map(|v| level.positions[pick(v)]).collect(),
                    colours: level
                        .colours
                        .as_ref()
                        .map(|colours| global.iter().map(|v| colours[pick(v)]).collect()),
                },
                scratch: Scratch::default(),
                before_last: global.len(),
                global,
            })
            .collect();
        Ok(Charted {
            charts,
            indices: level.conn.origin.clone(),
            owned: Vec::new(),
            ranges: vec![0..0; count],
            some: false,
            phase: 0,
        })
    }

    /// The faces of `level` labelled by a first parted batch's labels,
    /// without cutting anything (see [`Labelled::sizes`]); kept for the cut.
    pub(super) fn labelled(level: &Level, labels: &[u8], charts: usize) -> Result<Labelled> {
        let (canonical, l) = labelled_faces(level, labels, charts)?;
        Ok(Labelled {
            bytes: labels.to_vec(),
            charts,
            level: canonical,
            labels: l,
        })
    }

    pub(super) fn phase(&self) -> usize {
        self.phase
    }

    /// Splits every chart into the children `head` declares (format 6,
    /// the first parted batch of a phase): for each chart in order, its
    /// child count, and when over 1 the children's labels over its faces
    /// in canonical order; `charts` children in all. A chart of one child
    /// stays as it is. The merged level is not changed.
    pub(super) fn split(&mut self, head: &[u8], charts: usize) -> Result<()> {
        let mut r = Reader::new(head);
        let mut children = Vec::with_capacity(charts.min(8 * self.charts.len()));
        for parent in std::mem::take(&mut self.charts) {
            let count = r.varint()? as usize;
            if count == 0 || count > MAX_CHARTS || children.len() + count > charts {
                return Err(Error::stream(format!(
                    "a chart split into {count} children (of {charts} in the phase)"
                )));
            }
            if count == 1 {
                // The chart goes on as it is (not copied).
                children.push(Chart {
                    before_last: parent.level.vertex_count(),
                    ..parent
                });
                continue;
            }
            for mut child in parent.children(count, r.section()?)? {
                child.global = child
                    .global
                    .iter()
                    .map(|&v| parent.global[v as usize])
                    .collect();
                children.push(child);
            }
        }
        if children.len() != charts || r.remaining() != 0 {
            return Err(Error::stream(
                "a split declares a different number of charts than its batch",
            ));
        }
        self.ranges = vec![0..0; charts];
        self.charts = children;
        self.phase += 1;
        Ok(())
    }

    /// The charts, for a view that keeps them itself.
    pub(super) fn into_charts(self) -> Vec<Chart> {
        self.charts
    }

    pub(super) fn chart_count(&self) -> usize {
        self.charts.len()
    }

    pub(super) fn chart(&self, chart: usize) -> Option<ChartLevel<'_>> {
        let c = self.charts.get(chart)?;
        let range = self.ranges[chart].clone();
        Some(ChartLevel {
            positions: c.level.positions.as_flattened(),
            colours: c.level.colours.as_ref().map(|c| c.as_flattened()),
            indices: &c.level.conn.origin,
            quantized: &c.level.positions_q,
            level_indices: if self.some {
                &self.owned[range]
            } else {
                &self.indices[range]
            },
            new_from: c.before_last,
        })
    }

    /// Applies every chart's part, on up to `threads` threads; the first
    /// error in chart order, whatever the threads.
    /// `growth`: the whole level's, which each chart expects in proportion.
    pub(super) fn apply(
        &mut self,
        parts: Vec<Part<'_>>,
        growth: Growth,
        threads: usize,
    ) -> Result<()> {
        debug_assert_eq!(parts.len(), self.charts.len());
        #[cfg(not(target_arch = "wasm32"))]
        if threads > 1 && self.charts.len() > 1 {
            // Each thread takes the next chart as it frees up: charts differ
            // in size, and a fixed split would wait on the largest share.
            let workers = threads.min(self.charts.len());
            let queue = std::sync::Mutex::new(self.charts.iter_mut().zip(parts).enumerate());
            let next = || queue.lock().map(|mut q| q.next()).ok().flatten();
            let mut results: Vec<(usize, Result<()>)> = std::thread::scope(|scope| {
                let workers: Vec<_> = (0..workers)
                    .map(|_| {
                        scope.spawn(|| {
                            let mut done = Vec::new();
                            while let Some((i, (chart, part))) = next() {
                                done.push((i, chart.apply(part, growth)));
                            }
                            done
                        })
                    })
                    .collect();
                workers
                    .into_iter()
                    .flat_map(|w| w.join().unwrap_or_else(|p| std::panic::resume_unwind(p)))
                    .collect()
            });
            results.sort_by_key(|&(i, _)| i);
            return results.into_iter().try_for_each(|(_, r)| r);
        }
        let _ = threads;
        self.charts
            .iter_mut()
            .zip(parts)
            .try_for_each(|(chart, part)| chart.apply(part, growth))
    }

    /// Appends the vertices the charts gained to `level`, chart by chart in
    /// insertion order, and rebuilds the merged triangle list.
    pub(super) fn merge(&mut self, level: &mut Level, growth: Growth) {
        let n = level.vertex_count();
        let added: usize = self
            .charts
            .iter()
            .map(|c| c.level.vertex_count() - c.global.len())
            .sum();
        let (needed, target) = growth.room(n, added);
        level.reserve_vertices(needed, target);
        let faces: usize = self.charts.iter().map(|c| c.level.conn.origin.len()).sum();
        room::reserve(&mut self.indices, faces, faces + 6 * (target - needed));
        for chart in &mut self.charts {
            let new = chart.global.len()..chart.level.vertex_count();
            let first = level.positions_q.len() as u32;
            chart.global.extend(first..first + new.len() as u32);
            level
                .positions_q
                .extend_from_slice(&chart.level.positions_q[new.clone()]);
            level
                .positions
                .extend_from_slice(&chart.level.positions[new.clone()]);
            if let (Some(out), Some(colours)) = (&mut level.colours, &chart.level.colours) {
                out.extend_from_slice(&colours[new]);
            }
        }
        self.indices.clear();
        for (chart, range) in self.charts.iter().zip(&mut self.ranges) {
            *range = chart.append_level_triangles(&mut self.indices);
        }
    }

    /// For a decoder that refines only the charts in `refined`: numbers its
    /// charts' new vertices as [`Charted::merge`] would in the level (from
    /// `first`, the level's vertex count before the batch, chart by chart,
    /// counting each other chart's insertions as `inserted` declares them)
    /// and maps their triangles to level ids; the level is left alone.
    pub(super) fn number_owned(&mut self, first: usize, inserted: &[u64], refined: u64) {
        self.some = true;
        self.owned.clear();
        let mut next = first as u32;
        for (k, (chart, range)) in self.charts.iter_mut().zip(&mut self.ranges).enumerate() {
            if refined & (1 << k) == 0 {
                next = next.wrapping_add(inserted[k] as u32);
                *range = 0..0;
                continue;
            }
            for _ in chart.global.len()..chart.level.vertex_count() {
                chart.global.push(next);
                next = next.wrapping_add(1);
            }
            *range = chart.append_level_triangles(&mut self.owned);
        }
    }
}

/// Chart by chart, for a decoder whose charts refine each to its own depth
/// ([`crate::ChartView`]).
impl Charted {
    /// Chart `k`'s vertices now.
    pub(super) fn chart_vertices(&self, k: usize) -> usize {
        self.charts[k].level.vertex_count()
    }

    /// The ids, in the level where charts begin, of chart `k`'s first
    /// vertices (those the cut gave it); the rest are its own insertions.
    pub(super) fn cut_ids(&self, k: usize) -> &[u32] {
        &self.charts[k].global
    }

    /// Chart `k` in its own ids alone (no level ids: a view decoder's).
    pub(super) fn view_chart(&self, k: usize) -> Option<ChartLevel<'_>> {
        let c = self.charts.get(k)?;
        Some(ChartLevel {
            positions: c.level.positions.as_flattened(),
            colours: c.level.colours.as_ref().map(|c| c.as_flattened()),
            indices: &c.level.conn.origin,
            quantized: &c.level.positions_q,
            level_indices: &[],
            new_from: c.before_last,
        })
    }

    /// Applies chart `k`'s next part alone.
    pub(super) fn apply_one(&mut self, k: usize, part: Part<'_>, growth: Growth) -> Result<()> {
        self.charts[k].apply(part, growth)
    }

    /// A copy of every chart as it is now (the cut), to go back to.
    pub(super) fn seeds(&self) -> Vec<ChartSeed> {
        self.charts
            .iter()
            .map(|c| ChartSeed {
                level: c.level.clone(),
                global: c.global.clone(),
            })
            .collect()
    }

    /// Puts chart `k` back where `seed` left it, freeing what it had grown.
    pub(super) fn restore(&mut self, k: usize, seed: &ChartSeed) {
        self.charts[k] = Chart {
            level: seed.level.clone(),
            scratch: Scratch::default(),
            global: seed.global.clone(),
            before_last: seed.global.len(),
        };
    }
}

/// A chart as the cut made it: what a view decoder goes back to.
pub(super) struct ChartSeed {
    level: Level,
    global: Vec<u32>,
}

impl ChartSeed {
    pub(super) fn vertices(&self) -> usize {
        self.level.vertex_count()
    }
}

/// A level's faces and their charts, decoded before the cut (to tell the
/// charts' sizes) and kept so the cut need not decode them again.
pub(super) struct Labelled {
    bytes: Vec<u8>,
    charts: usize,
    level: CanonicalLevel,
    labels: Vec<u32>,
}

impl Labelled {
    /// Faces of each chart: how much work each chart will be.
    pub(super) fn sizes(&self) -> Vec<usize> {
        let mut sizes = vec![0; self.charts];
        for &label in &self.labels {
            sizes[label as usize] += 1;
        }
        sizes
    }
}

/// The faces of `level` in canonical order and each one's chart, from the
/// labels section of a first parted batch.
fn labelled_faces(
    level: &Level,
    labels: &[u8],
    charts: usize,
) -> Result<(CanonicalLevel, Vec<u32>)> {
    let canonical = canonical_level(&level.conn)?;
    let labels = decode_labels(labels, &canonical.adjacency, charts)?;
    Ok((canonical, labels))
}

impl Chart {
    /// The `count` children this chart splits into by `labels` (the coded
    /// labels of its faces in canonical order; unused for one child, which
    /// is the chart as it is), each with its vertices' ids in this chart
    /// as its `global`.
    pub(super) fn children(&self, count: usize, labels: &[u8]) -> Result<Vec<Chart>> {
        if count == 1 {
            let n = self.level.vertex_count();
            return Ok(vec![Chart {
                level: self.level.clone(),
                scratch: Scratch::default(),
                global: (0..n as u32).collect(),
                before_last: n,
            }]);
        }
        let canonical = canonical_level(&self.level.conn)?;
        let labels = decode_labels(labels, &canonical.adjacency, count)?;
        let cuts = cut(canonical.faces(), &labels, count, self.level.vertex_count());
        let pick = |v: &u32| *v as usize;
        let level = &self.level;
        Ok(chart_connectivity(cuts, &labels, &canonical.adjacency)
            .map_err(|e| Error::stream(format!("a chart is not a manifold: {e}")))?
            .into_iter()
            .map(|(global, conn)| Chart {
                level: Level {
                    conn,
                    quantization: level.quantization,
                    positions_q: global.iter().map(|v| level.positions_q[pick(v)]).collect(),
                    positions: global.iter().map(|v| level.positions[pick(v)]).collect(),
                    colours: level
                        .colours
                        .as_ref()
                        .map(|colours| global.iter().map(|v| colours[pick(v)]).collect()),
                },
                scratch: Scratch::default(),
                before_last: global.len(),
                global,
            })
            .collect())
    }

    /// The chart as a view shows it (no level ids).
    pub(super) fn view_level(&self) -> ChartLevel<'_> {
        ChartLevel {
            positions: self.level.positions.as_flattened(),
            colours: self.level.colours.as_ref().map(|c| c.as_flattened()),
            indices: &self.level.conn.origin,
            quantized: &self.level.positions_q,
            level_indices: &[],
            new_from: self.before_last,
        }
    }

    pub(super) fn vertex_count(&self) -> usize {
        self.level.vertex_count()
    }

    /// The ids of the chart's first vertices where it was cut from.
    pub(super) fn first_ids(&self) -> &[u32] {
        &self.global
    }

    /// Appends the chart's triangles in level ids to `out`; where they are.
    fn append_level_triangles(&self, out: &mut Vec<u32>) -> Range<usize> {
        let start = out.len();
        out.extend(
            self.level
                .conn
                .origin
                .iter()
                .map(|&v| self.global[v as usize]),
        );
        start..out.len()
    }

    pub(super) fn apply(&mut self, part: Part<'_>, growth: Growth) -> Result<()> {
        self.before_last = self.level.vertex_count();
        let Some((cleaning, decimating, bytes)) = part else {
            return Ok(());
        };
        // Reserve no more than the part could possibly describe (a bit per vertex).
        let grow = (cleaning.inserted as usize + decimating.inserted as usize)
            .min(bytes.saturating_mul(8));
        self.level.make_room(grow, growth, &mut self.scratch);
        self.level
            .undo_batch(&cleaning, &decimating, &mut self.scratch)
    }
}

/// Reads one part: empty, or a cleaning and a decimating pass filling it.
pub(super) fn read_part(bytes: &[u8]) -> Result<Part<'_>> {
    if bytes.is_empty() {
        return Ok(None);
    }
    let mut r = Reader::new(bytes);
    let cleaning = read_pass(&mut r, PassKind::Cleaning)?;
    let decimating = read_pass(&mut r, PassKind::Decimating)?;
    if r.remaining() != 0 {
        return Err(Error::stream("trailing bytes after a chart's passes"));
    }
    Ok(Some((cleaning, decimating, bytes.len())))
}
