//! View-dependent decoding of a charted stream (issue 41): once the charts
//! are cut, each chart refines by its own parts to its own depth, so a
//! viewer fetches and keeps only the parts of the charts it shows closely.
//!
//! Why it stays watertight: a chart's layers never remove a cut vertex (the
//! cut is a border to AD01), and every chart copies the cut's positions from
//! the level where charts begin. Two charts at different depths therefore
//! share every cut vertex and every cut edge bit for bit, whatever the
//! depths; the test `view.rs` in `tests/` checks that the union stays closed.

use super::charted::{read_part, ChartSeed, Charted};
use super::{read_chart_count, Decoder};
use crate::format::{Reader, CHARTED_VERSION};
use crate::room::Growth;
use crate::{ChartLevel, Error, Header, Limits, Result};

/// A charted stream's charts, each refined to its own depth: the decoder of
/// a viewer that streams parts, not batches.
///
/// ```
/// # fn demo(stream: &[u8]) -> vitrine_codec::Result<()> {
/// use vitrine_codec::{Decoder, Limits, PartedLayout, StreamIndex};
/// let index = StreamIndex::parse(stream)?;
/// let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
/// let mut parted = Vec::new();
/// for range in &index.batches {
///     let chunk = &stream[range.clone()];
///     match PartedLayout::parse(chunk)? {
///         Some(layout) => parted.push((chunk, layout)),
///         None => decoder.apply_batch(chunk)?, // a global batch
///     }
/// }
/// let Some((first, layout)) = parted.first() else { return Ok(()) }; // not charted
/// let mut view = decoder.into_view(&first[layout.head.clone()])?;
/// // Chart 0 to the final level; the others stay where the cut left them.
/// for (chunk, layout) in &parted {
///     view.apply_part(0, &chunk[layout.parts[0].clone()])?;
/// }
/// let chart = view.chart(0).unwrap();
/// let (_positions, _triangles) = (chart.positions, chart.indices);
/// # Ok(()) }
/// ```
pub struct ChartView {
    header: Header,
    limits: Limits,
    charted: Charted,
    seeds: Vec<ChartSeed>,
    /// Parted batches applied to each chart.
    depths: Vec<usize>,
    /// Parted batches in the stream: the depth of a chart at the final level.
    parted: usize,
    /// Vertices held by every chart together (cut vertices once per chart).
    resident: usize,
    /// The most vertices the view may hold (the device's budget).
    budget: usize,
    growth: Growth,
}

impl Decoder {
    /// Turns a decoder at the level where a charted stream's charts begin
    /// (every global batch applied, no parted one) into a [`ChartView`].
    /// `head`: the first parted batch's payload up to the end of its labels
    /// ([`crate::PartedLayout::head`]).
    pub fn into_view(self, head: &[u8]) -> Result<ChartView> {
        if self.header.version != CHARTED_VERSION {
            return Err(Error::stream(format!(
                "a version {} stream has no charts",
                self.header.version
            )));
        }
        if self.broken || self.charted.is_some() {
            return Err(Error::stream(
                "the view starts where the charts begin, before any parted batch",
            ));
        }
        let parted = self.header.batch_count() - self.applied;
        if parted == 0 {
            return Err(Error::stream("no parted batch follows this level"));
        }
        let mut r = Reader::new(head);
        let count = read_chart_count(&mut r)?;
        let charted = Charted::cut(&self.level, r.section()?, count, self.labelled)?;
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the labels"));
        }
        let seeds = charted.seeds();
        let resident = seeds.iter().map(ChartSeed::vertices).sum();
        Ok(ChartView {
            growth: Growth {
                now: self.level.vertex_count(),
                last: self.header.final_level().vertices as usize,
            },
            header: self.header,
            limits: self.limits,
            charted,
            seeds,
            depths: vec![0; count],
            parted,
            resident,
            budget: usize::MAX,
        })
    }
}

impl ChartView {
    pub fn header(&self) -> &Header {
        &self.header
    }

    pub fn chart_count(&self) -> usize {
        self.depths.len()
    }

    /// Parted batches applied to `chart` (0: as the cut left it).
    pub fn depth(&self, chart: usize) -> usize {
        self.depths.get(chart).copied().unwrap_or(0)
    }

    /// The depth of a chart at the stream's final level.
    pub fn final_depth(&self) -> usize {
        self.parted
    }

    /// The stream level a chart of depth `depth` shows: where the charts
    /// begin, plus its parted batches.
    pub fn level_of(&self, depth: usize) -> usize {
        self.header.batch_count() - self.parted + depth
    }

    /// Vertices of all charts together, each chart counting its copy of
    /// the cut: what the view keeps resident.
    pub fn resident_vertices(&self) -> usize {
        self.resident
    }

    /// The most vertices the view may hold, all charts together: a part
    /// that would pass it is refused ([`Error::Limit`]) and changes
    /// nothing, so a viewer resets charts out of view and tries again. The
    /// stream's [`Limits`] still bound it; by default they alone do.
    pub fn set_vertex_budget(&mut self, vertices: usize) {
        self.budget = vertices;
    }

    /// Applies `chart`'s next part (its bytes in the next parted batch the
    /// chart has not had: [`crate::PartedLayout::parts`]). An empty part is
    /// a batch the chart sits out. A part refused for its form or counts
    /// leaves the chart as it was; one that fails part-way puts the chart
    /// back at the cut (its earlier parts are needed again). The other
    /// charts are untouched either way.
    pub fn apply_part(&mut self, chart: usize, part: &[u8]) -> Result<()> {
        let depth = *self
            .depths
            .get(chart)
            .ok_or_else(|| Error::stream(format!("no chart {chart}")))?;
        if depth >= self.parted {
            return Err(Error::stream(format!(
                "chart {chart} is at the final level already"
            )));
        }
        let part = read_part(part)?;
        let inserted = part
            .as_ref()
            .map_or(0, |(c, d, _)| c.inserted as usize + d.inserted as usize);
        let after = self.resident.saturating_add(inserted);
        let most = self.budget.min(self.limits.max_vertices as usize);
        if after > most {
            return Err(Error::Limit(format!(
                "the view would hold {after} vertices, over its budget of {most}"
            )));
        }
        let before = self.charted.chart_vertices(chart);
        if let Err(e) = self.charted.apply_one(chart, part, self.growth) {
            self.reset(chart);
            return Err(e);
        }
        self.resident = self.resident - before + self.charted.chart_vertices(chart);
        self.depths[chart] = depth + 1;
        Ok(())
    }

    /// Puts `chart` back where the cut left it, freeing what it had grown:
    /// how a viewer makes room when its memory budget is full (the chart
    /// refines again from its first part when it comes back into view).
    pub fn reset(&mut self, chart: usize) {
        let Some(seed) = self.seeds.get(chart) else {
            return;
        };
        let before = self.charted.chart_vertices(chart);
        self.charted.restore(chart, seed);
        self.resident = self.resident - before + seed.vertices();
        self.depths[chart] = 0;
    }

    /// `chart` at its depth, in its own vertex ids
    /// ([`ChartLevel::level_indices`] is empty here).
    pub fn chart(&self, chart: usize) -> Option<ChartLevel<'_>> {
        self.charted.view_chart(chart)
    }

    /// The ids, in the level where the charts begin, of `chart`'s first
    /// vertices (the cut's and the chart interior's at that level): two
    /// charts share a vertex there exactly when they share these ids.
    pub fn cut_ids(&self, chart: usize) -> &[u32] {
        if chart >= self.depths.len() {
            return &[];
        }
        self.charted.cut_ids(chart)
    }
}
