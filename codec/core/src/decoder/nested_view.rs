//! View-dependent decoding of a nested-chart stream (format 6): every
//! chart of the tree refines by its own parts, and a chart that has had
//! all its phase's parts splits into its children, which refine on. A
//! viewer fetches and keeps only the path to the charts it shows closely.
//!
//! Why it stays watertight: a phase's cut is frozen in its charts and in
//! all their descendants, and no layer joins two vertices of its phase's
//! cut, so two charts shown at different depths share every vertex and
//! edge of their common border bit for bit (`tests/nested.rs` checks it).

use super::charted::{read_part, Chart, Charted};
use super::{read_precision, Decoder};
use crate::format::{Reader, NESTED_VERSION};
use crate::room::Growth;
use crate::{ChartLevel, Error, Header, Limits, NestedLayout, Result, MAX_CHARTS};

/// A nested-chart stream's tree of charts, each refined to its own depth.
///
/// Charts are named by their phase and their index in the phase
/// ([`NestedLayout::parts`]). Phase 0's charts exist from the start;
/// a chart of phase *d* > 0 exists once its parent, having had every part
/// of phase *d* − 1, is [split](NestedView::split). A parent stays as it
/// was when it splits (a viewer shows either it or its children).
pub struct NestedView {
    header: Header,
    limits: Limits,
    growth: Growth,
    /// Parted batches in each phase.
    batches: Vec<usize>,
    /// Each phase's charts: the parent's index and the children's range.
    parents: Vec<Vec<usize>>,
    children: Vec<Vec<std::ops::Range<usize>>>,
    /// Each phase's charts that exist, with the parts each has had.
    charts: Vec<Vec<Option<(Chart, usize)>>>,
    /// Vertices of every chart held, each counting its own copy.
    resident: usize,
}

impl Decoder {
    /// Turns a decoder at the level where a nested stream's charts begin
    /// (every global batch applied, no parted one) into a [`NestedView`].
    /// `layouts`: the layouts of every parted batch of the stream, in
    /// order ([`NestedLayout::parse`]); `head`: the first one's head bytes
    /// ([`NestedLayout::head`]).
    pub fn into_nested_view(self, head: &[u8], layouts: &[NestedLayout]) -> Result<NestedView> {
        if self.header.version != NESTED_VERSION {
            return Err(Error::stream(format!(
                "a version {} stream has no nested charts",
                self.header.version
            )));
        }
        if self.broken || self.charted.is_some() {
            return Err(Error::stream(
                "the view starts where the charts begin, before any parted batch",
            ));
        }
        if layouts.len() != self.header.batch_count() - self.applied {
            return Err(Error::stream(
                "the layouts are not those of the parted batches left",
            ));
        }
        let Some(last) = layouts.last() else {
            return Err(Error::stream("no parted batch follows this level"));
        };
        let phases = last.phase + 1;
        let mut batches = vec![0; phases];
        let mut parents: Vec<Vec<usize>> = vec![Vec::new(); phases];
        let mut children: Vec<Vec<std::ops::Range<usize>>> = vec![Vec::new(); phases];
        for (i, l) in layouts.iter().enumerate() {
            let expected = match i {
                0 => 0,
                _ => layouts[i - 1].phase + usize::from(l.begins),
            };
            if l.phase != expected || l.begins != (i == 0 || l.phase != layouts[i - 1].phase) {
                return Err(Error::stream("the layouts' phases are out of order"));
            }
            batches[l.phase] += 1;
            if l.begins {
                if l.phase == 0 {
                    parents[0] = vec![0; l.parts.len()];
                } else {
                    let mut first = 0;
                    for (p, &(count, _)) in l.splits.iter().enumerate() {
                        parents[l.phase].extend(std::iter::repeat_n(p, count));
                        children[l.phase - 1].push(first..first + count);
                        first += count;
                    }
                }
            }
            if parents[l.phase].len() != l.parts.len() {
                return Err(Error::stream("a phase's batches differ in their charts"));
            }
        }
        let mut r = Reader::new(head);
        read_precision(&mut r)?;
        let (phase, count) = (r.varint()?, r.varint()? as usize);
        if phase != 0 || count != parents[0].len() {
            return Err(Error::stream("the head is not the first parted batch's"));
        }
        let top = Charted::cut(&self.level, r.section()?, count, None)?;
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the labels"));
        }
        let mut charts: Vec<Vec<Option<(Chart, usize)>>> = parents
            .iter()
            .map(|p| (0..p.len()).map(|_| None).collect())
            .collect();
        let mut resident = 0;
        for (slot, chart) in charts[0].iter_mut().zip(top.into_charts()) {
            resident += chart.vertex_count();
            *slot = Some((chart, 0));
        }
        Ok(NestedView {
            growth: Growth {
                now: self.level.vertex_count(),
                last: self.header.final_level().vertices as usize,
            },
            header: self.header,
            limits: self.limits,
            batches,
            parents,
            children,
            charts,
            resident,
        })
    }
}

impl NestedView {
    pub fn header(&self) -> &Header {
        &self.header
    }

    /// Phases in the stream.
    pub fn phase_count(&self) -> usize {
        self.batches.len()
    }

    /// Charts in phase `phase`.
    pub fn chart_count(&self, phase: usize) -> usize {
        self.parents.get(phase).map_or(0, Vec::len)
    }

    /// Parted batches in phase `phase`: the parts a chart of it has in all.
    pub fn phase_batches(&self, phase: usize) -> usize {
        self.batches.get(phase).copied().unwrap_or(0)
    }

    /// The parent (in phase `phase − 1`) of chart `chart` of phase `phase` > 0.
    pub fn parent(&self, phase: usize, chart: usize) -> Option<usize> {
        (phase > 0).then(|| self.parents.get(phase)?.get(chart).copied())?
    }

    /// The children (in phase `phase + 1`) of chart `chart` of phase `phase`.
    pub fn children(&self, phase: usize, chart: usize) -> std::ops::Range<usize> {
        self.children
            .get(phase)
            .and_then(|c| c.get(chart))
            .cloned()
            .unwrap_or(0..0)
    }

    /// Parts applied to a chart in its phase; `None` while it does not exist.
    pub fn depth(&self, phase: usize, chart: usize) -> Option<usize> {
        Some(self.slot(phase, chart)?.1)
    }

    /// Vertices of all the charts held, each counting its own copy.
    pub fn resident_vertices(&self) -> usize {
        self.resident
    }

    fn slot(&self, phase: usize, chart: usize) -> Option<&(Chart, usize)> {
        self.charts.get(phase)?.get(chart)?.as_ref()
    }

    /// Applies the chart's next part of its phase (its bytes in the next
    /// parted batch of the phase it has not had: [`NestedLayout::parts`];
    /// empty when it sits the batch out). A part that fails part-way
    /// removes the chart (split its parent again to get it back).
    pub fn apply_part(&mut self, phase: usize, chart: usize, part: &[u8]) -> Result<()> {
        let batches = self.phase_batches(phase);
        let Some(Some((c, depth))) = self.charts.get_mut(phase).and_then(|p| p.get_mut(chart))
        else {
            return Err(Error::stream(format!(
                "no chart {chart} of phase {phase} in the view"
            )));
        };
        if *depth >= batches {
            return Err(Error::stream(format!(
                "chart {chart} of phase {phase} has had all its parts"
            )));
        }
        let part = read_part(part)?;
        let inserted = part
            .as_ref()
            .map_or(0, |(c, d, _)| c.inserted as usize + d.inserted as usize);
        if self.resident.saturating_add(inserted) > self.limits.max_vertices as usize {
            return Err(Error::Limit(format!(
                "the view would hold over {} vertices",
                self.limits.max_vertices
            )));
        }
        let before = c.vertex_count();
        let applied = c.apply(part, self.growth);
        let after = c.vertex_count();
        *depth += 1;
        self.resident = self.resident - before + after;
        if let Err(e) = applied {
            self.resident -= after;
            self.charts[phase][chart] = None;
            return Err(e);
        }
        Ok(())
    }

    /// Splits chart `chart` of phase `phase`, which has had every part of
    /// its phase, into its children of phase `phase + 1` by its split
    /// entry (`entry`: its bytes in the next phase's first batch,
    /// [`NestedLayout::splits`]). Children already there are replaced.
    pub fn split(&mut self, phase: usize, chart: usize, entry: &[u8]) -> Result<()> {
        let range = self.children(phase, chart);
        let batches = self.phase_batches(phase);
        let Some((parent, depth)) = self.slot(phase, chart) else {
            return Err(Error::stream(format!(
                "no chart {chart} of phase {phase} in the view"
            )));
        };
        if *depth != batches || range.is_empty() {
            return Err(Error::stream(format!(
                "chart {chart} of phase {phase} cannot split: it has had {depth} of its {batches} parts, or has no children"
            )));
        }
        let mut r = Reader::new(entry);
        let count = r.varint()? as usize;
        if count != range.len() || count > MAX_CHARTS {
            return Err(Error::stream(
                "a split entry declares another number of children",
            ));
        }
        let labels = if count > 1 { r.section()? } else { &[] };
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after a split entry"));
        }
        let children = parent.children(count, labels)?;
        let added: usize = children.iter().map(Chart::vertex_count).sum();
        let slots = &mut self.charts[phase + 1][range];
        let removed: usize = slots.iter().flatten().map(|(c, _)| c.vertex_count()).sum();
        if (self.resident - removed).saturating_add(added) > self.limits.max_vertices as usize {
            return Err(Error::Limit(format!(
                "the view would hold over {} vertices",
                self.limits.max_vertices
            )));
        }
        for (slot, child) in slots.iter_mut().zip(children) {
            *slot = Some((child, 0));
        }
        self.resident = self.resident - removed + added;
        Ok(())
    }

    /// Drops a chart of phase > 0 and its descendants, freeing what they
    /// held (its parent splits again to get it back).
    pub fn drop_chart(&mut self, phase: usize, chart: usize) {
        let Some(slot) = self.charts.get_mut(phase).and_then(|p| p.get_mut(chart)) else {
            return;
        };
        if phase == 0 {
            return;
        }
        if let Some((c, _)) = slot.take() {
            self.resident -= c.vertex_count();
        }
        for child in self.children(phase, chart) {
            self.drop_chart(phase + 1, child);
        }
    }

    /// Drops one chart that has split, keeping its children: what a
    /// reader that walks the whole tree once (the part table) no longer
    /// needs, so it holds about one copy of the mesh, not one per phase.
    pub(crate) fn release(&mut self, phase: usize, chart: usize) {
        if let Some(slot) = self.charts.get_mut(phase).and_then(|p| p.get_mut(chart)) {
            if let Some((c, _)) = slot.take() {
                self.resident -= c.vertex_count();
            }
        }
    }

    /// A chart at its depth, in its own vertex ids
    /// ([`ChartLevel::level_indices`] is empty here).
    pub fn chart(&self, phase: usize, chart: usize) -> Option<ChartLevel<'_>> {
        Some(self.slot(phase, chart)?.0.view_level())
    }

    /// The ids of a chart's first vertices where it was cut from: in its
    /// parent's vertex ids (phase > 0), or in the level where the charts
    /// begin (phase 0). Its other vertices are its own insertions.
    pub fn first_ids(&self, phase: usize, chart: usize) -> &[u32] {
        self.slot(phase, chart).map_or(&[], |(c, _)| c.first_ids())
    }
}
