//! Parts as the unit of streaming (issue 41): where each chart's part of a
//! parted batch lies, read from the lengths the format already writes
//! (FORMAT.md, "Charted streams"), and the table a server keeps of them with
//! the geometric error each part removes.

mod error;
mod nested_table;
mod table;

use std::ops::Range;

use crate::format::{ChunkHeader, Reader, BATCH_TAG, NESTED_VERSION, PARTED_TAG};
use crate::{Error, Result};
pub use error::BULK_SHARE;
pub use nested_table::{nested_part_table, NestedPartTable, SplitRecord};
pub use table::{part_table, PartRecord};

/// Where the pieces of one parted batch lie in its chunk: a server slices a
/// part out of the stored batch with these ranges alone, decoding nothing.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PartedLayout {
    /// The batch's level (1 = the first batch after the base).
    pub level: usize,
    /// The payload up to the end of the chart labels (the first parted
    /// batch's; just the chart count in later ones): what
    /// [`crate::Decoder::into_view`] takes.
    pub head: Range<usize>,
    /// Chart *k*'s part (its passes, without the length before them);
    /// empty when the chart sits the batch out.
    pub parts: Vec<Range<usize>>,
}

impl PartedLayout {
    /// The layout of a batch chunk as [`crate::StreamIndex::batches`]
    /// delimits one; `None` for a whole-mesh batch (format 4, or the global
    /// batches of format 5).
    pub fn parse(chunk: &[u8]) -> Result<Option<PartedLayout>> {
        let (header, payload) = ChunkHeader::parse(chunk, &[BATCH_TAG, PARTED_TAG])?;
        if header.tag != PARTED_TAG {
            return Ok(None);
        }
        // The payload is a slice of `chunk`: where it starts.
        let start = payload.as_ptr() as usize - chunk.as_ptr() as usize;
        if start + payload.len() != chunk.len() {
            return Err(Error::stream("trailing bytes after a parted batch"));
        }
        if header.version >= NESTED_VERSION {
            return Err(Error::stream(format!(
                "a version {} stream's parts are nested: read them with NestedLayout::parse",
                header.version
            )));
        }
        let mut r = Reader::new(payload);
        let at = |r: &Reader| start + payload.len() - r.remaining();
        let charts = crate::decoder::read_chart_count(&mut r)?;
        let first = chunk_is_first(&mut r, charts)?;
        if first {
            r.section()?;
        }
        let head = start..at(&r);
        let mut parts = Vec::with_capacity(charts);
        for _ in 0..charts {
            let bytes = r.section()?;
            let end = at(&r);
            parts.push(end - bytes.len()..end);
        }
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the batch's parts"));
        }
        Ok(Some(PartedLayout {
            level: header.level as usize,
            head,
            parts,
        }))
    }
}

/// Whether a parted batch's payload carries the labels (the first parted
/// batch does): the format tells it only by position in the stream, so this
/// reads ahead: after the labels come exactly `charts` sections.
fn chunk_is_first(r: &mut Reader, charts: usize) -> Result<bool> {
    let mut probe = r.clone();
    let mut sections = 0;
    while probe.remaining() > 0 {
        probe.section()?;
        sections += 1;
    }
    match sections {
        n if n == charts => Ok(false),
        n if n == charts + 1 => Ok(true),
        n => Err(Error::stream(format!(
            "a parted batch of {charts} charts holds {n} sections"
        ))),
    }
}

/// Where the pieces of one parted batch of a nested stream (format 6) lie
/// in its chunk, read from the lengths alone.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NestedLayout {
    /// The batch's level (1 = the first batch after the base).
    pub level: usize,
    /// Its phase: 0 for the top charts, d for the charts of the d-th split.
    pub phase: usize,
    /// The payload up to the end of its head: the deferred-precision byte,
    /// phase and chart count, and in a phase's first batch the head section.
    pub head: Range<usize>,
    /// Whether this batch begins its phase (carries the labels or the split).
    pub begins: bool,
    /// In the first batch of a phase after the first: for each chart of
    /// the previous phase, its children's number and where its entry (the
    /// count and, over 1 child, the labels section) lies.
    pub splits: Vec<(usize, Range<usize>)>,
    /// Chart *k*'s part (its passes, without the length before them);
    /// empty when the chart sits the batch out.
    pub parts: Vec<Range<usize>>,
}

impl NestedLayout {
    /// The layout of a batch chunk as [`crate::StreamIndex::batches`]
    /// delimits one; `None` for a whole-mesh batch. `previous`: the layout
    /// of the stream's parted batch before this one (`None` for the first),
    /// which tells whether this one begins a phase.
    pub fn parse(chunk: &[u8], previous: Option<&NestedLayout>) -> Result<Option<NestedLayout>> {
        Self::parse_after(chunk, previous.map(|p| (p.phase, p.parts.len())))
    }

    /// As [`NestedLayout::parse`], given only the previous parted batch's
    /// phase and chart count: what a server keeps of it (its part rows),
    /// so that it slices one batch without loading the one before.
    pub fn parse_after(
        chunk: &[u8],
        previous: Option<(usize, usize)>,
    ) -> Result<Option<NestedLayout>> {
        let (header, payload) = ChunkHeader::parse(chunk, &[BATCH_TAG, PARTED_TAG])?;
        if header.tag != PARTED_TAG {
            return Ok(None);
        }
        if header.version < NESTED_VERSION {
            return Err(Error::stream(
                "not a nested stream's batch: use PartedLayout",
            ));
        }
        let start = payload.as_ptr() as usize - chunk.as_ptr() as usize;
        let mut r = Reader::new(payload);
        let at = |r: &Reader| start + payload.len() - r.remaining();
        r.u8()?;
        let phase = r.varint()? as usize;
        let charts = r.varint()? as usize;
        if !(1..=crate::MAX_PHASE_CHARTS).contains(&charts) {
            return Err(Error::stream(format!("{charts} charts is out of range")));
        }
        let begins = begins_phase(phase, charts, previous)?;
        let mut splits = Vec::new();
        if begins {
            let section = r.section()?;
            if phase > 0 {
                let parents = previous.map_or(0, |(_, k)| k);
                let base = at(&r) - section.len();
                let mut h = Reader::new(section);
                let pos = |h: &Reader| base + section.len() - h.remaining();
                let mut total = 0;
                for _ in 0..parents {
                    let from = pos(&h);
                    let count = h.varint()? as usize;
                    if count > 1 {
                        h.section()?;
                    }
                    total += count;
                    splits.push((count, from..pos(&h)));
                }
                if total != charts || h.remaining() != 0 {
                    return Err(Error::stream(
                        "a split declares a different number of charts",
                    ));
                }
            }
        }
        let head = start..at(&r);
        let mut parts = Vec::with_capacity(charts.min(r.remaining()));
        for _ in 0..charts {
            let bytes = r.section()?;
            let end = at(&r);
            parts.push(end - bytes.len()..end);
        }
        if r.remaining() != 0 {
            return Err(Error::stream("trailing bytes after the batch's parts"));
        }
        Ok(Some(NestedLayout {
            level: header.level as usize,
            phase,
            head,
            begins,
            splits,
            parts,
        }))
    }
}

impl NestedLayout {
    /// A parted batch's layout declared from what a part index says of it
    /// (its level, phase and chart count, and in a phase's first batch
    /// after phase 0 each previous chart's number of children), without
    /// its bytes: every range is empty. Enough for
    /// [`crate::Decoder::into_nested_view`], which reads only the tree's
    /// shape, so a viewer that fetches heads and parts, never whole
    /// batches, starts a view. `previous`: the phase and chart count of the
    /// batch declared before (`None` for the first), as in
    /// [`NestedLayout::parse_after`].
    pub fn declare(
        level: usize,
        phase: usize,
        charts: usize,
        children: &[usize],
        previous: Option<(usize, usize)>,
    ) -> Result<NestedLayout> {
        if !(1..=crate::MAX_PHASE_CHARTS).contains(&charts) {
            return Err(Error::stream(format!("{charts} charts is out of range")));
        }
        let begins = begins_phase(phase, charts, previous)?;
        let parents = match previous {
            Some((_, k)) if begins && phase > 0 => k,
            _ => 0,
        };
        if children.len() != parents || (parents > 0 && children.iter().sum::<usize>() != charts) {
            return Err(Error::stream(
                "a split declares a different number of charts",
            ));
        }
        Ok(NestedLayout {
            level,
            phase,
            head: 0..0,
            begins,
            splits: children.iter().map(|&c| (c, 0..0)).collect(),
            parts: vec![0..0; charts],
        })
    }
}

/// Whether a parted batch of `phase` with `charts` charts begins its phase,
/// after a batch of `previous` (phase, charts); an error when it is out of
/// its phase.
fn begins_phase(phase: usize, charts: usize, previous: Option<(usize, usize)>) -> Result<bool> {
    let begins = match previous {
        None => phase == 0,
        Some((p, _)) if p == phase => false,
        Some((p, _)) => p + 1 == phase,
    };
    if !begins && previous.is_none_or(|(p, k)| p != phase || k != charts) {
        return Err(Error::stream("a parted batch out of its phase"));
    }
    Ok(begins)
}

/// What a viewer that refines one leaf of a nested stream (format 6)
/// fetches, from the parted batches' lengths alone.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct NestedSummary {
    /// The first parted batch's level.
    pub first_level: usize,
    /// Bytes before any chart's own part: the header, base, global batches
    /// and the first parted batch's head.
    pub prefix: usize,
    /// Each phase's charts' parents (in the phase before; empty in phase 0).
    pub parents: Vec<Vec<usize>>,
    /// Each phase's charts' parts, all batches together, in bytes.
    pub part_bytes: Vec<Vec<usize>>,
    /// Each leaf's close-up: the prefix, its parts and every ancestor's,
    /// and each ancestor's split entry on its path.
    pub closeups: Vec<usize>,
}

impl NestedSummary {
    /// `None` for a stream without nested charts.
    pub fn of(stream: &[u8]) -> Result<Option<NestedSummary>> {
        let index = crate::StreamIndex::parse(stream)?;
        if index.header.version < NESTED_VERSION {
            return Ok(None);
        }
        let mut layouts: Vec<(usize, NestedLayout)> = Vec::new();
        for r in &index.batches {
            let previous = layouts.last().map(|(_, l)| l);
            if let Some(l) = NestedLayout::parse(&stream[r.clone()], previous)? {
                layouts.push((r.start, l));
            }
        }
        let (Some((start, first)), Some((_, last))) = (layouts.first(), layouts.last()) else {
            return Ok(None);
        };
        let prefix = start + first.head.end;
        let phases = last.phase + 1;
        let mut part_bytes: Vec<Vec<usize>> = vec![Vec::new(); phases];
        let mut parents: Vec<Vec<usize>> = vec![Vec::new(); phases];
        let mut entries: Vec<Vec<usize>> = vec![Vec::new(); phases];
        for (_, l) in &layouts {
            let bytes = &mut part_bytes[l.phase];
            bytes.resize(l.parts.len(), 0);
            for (k, r) in l.parts.iter().enumerate() {
                bytes[k] += r.len();
            }
            if l.begins && l.phase > 0 {
                for (k, (count, entry)) in l.splits.iter().enumerate() {
                    parents[l.phase].extend(std::iter::repeat_n(k, *count));
                    entries[l.phase - 1].push(entry.len());
                }
            }
        }
        let closeups = (0..part_bytes[phases - 1].len())
            .map(|leaf| {
                let mut total = prefix;
                let mut k = leaf;
                for d in (0..phases).rev() {
                    total += part_bytes[d][k];
                    if d > 0 {
                        k = parents[d][k];
                        total += entries[d - 1][k];
                    }
                }
                total
            })
            .collect();
        Ok(Some(NestedSummary {
            first_level: first.level,
            prefix,
            parents,
            part_bytes,
            closeups,
        }))
    }
}
