//! The part table of a nested stream (format 6): every chart's part of
//! every parted batch, addressed by its batch and its chart's position in
//! the phase, with the error it removes (as version 5's, `table.rs`), and
//! every split entry a viewer fetches to walk down the tree.

use std::ops::Range;

use super::error::removed_error;
use super::{NestedLayout, PartRecord};
use crate::format::NESTED_VERSION;
use crate::{Decoder, Error, Limits, NestedView, Result, StreamIndex};

/// One chart's split entry (FORMAT.md, "The split"): what a viewer fetches,
/// after every part of the chart's phase, to cut it into its children.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SplitRecord {
    /// The batch whose head holds it: the first of the children's phase.
    pub level: usize,
    /// The children's phase (≥ 1); the chart split is of `phase − 1`.
    pub phase: usize,
    /// The chart split, by its position in phase `phase − 1`.
    pub parent: usize,
    /// Its children, by their positions in phase `phase`.
    pub children: Range<usize>,
    /// Its bytes in the whole stream.
    pub bytes: Range<usize>,
}

/// A nested stream's parts and split entries, in stream order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NestedPartTable {
    pub parts: Vec<PartRecord>,
    pub splits: Vec<SplitRecord>,
}

/// The parts and split entries of a nested stream (format 6); empty when
/// it has no parted batch. Decodes the stream once, as a nested view that
/// walks the whole tree, measuring each part against the chart it refines
/// and letting go of each chart once it has split.
pub fn nested_part_table(stream: &[u8], limits: Limits) -> Result<NestedPartTable> {
    let index = StreamIndex::parse(stream)?;
    if index.header.version != NESTED_VERSION {
        return Err(Error::stream(format!(
            "a version {} stream has no nested charts: use part_table",
            index.header.version
        )));
    }
    let mut decoder = Decoder::new(&stream[index.base.clone()], limits)?;
    // Each parted batch's chunk start and layout.
    let mut parted: Vec<(usize, NestedLayout)> = Vec::new();
    for range in &index.batches {
        let chunk = &stream[range.clone()];
        match NestedLayout::parse(chunk, parted.last().map(|(_, l)| l))? {
            Some(layout) => parted.push((range.start, layout)),
            None if parted.is_empty() => decoder.apply_batch(chunk)?,
            None => return Err(Error::stream("a whole-mesh batch after parted ones")),
        }
    }
    let Some((start, first)) = parted.first() else {
        return Ok(NestedPartTable::default());
    };
    let head = &stream[start + first.head.start..start + first.head.end];
    let layouts: Vec<NestedLayout> = parted.iter().map(|(_, l)| l.clone()).collect();
    let mut view = decoder.into_nested_view(head, &layouts)?;
    let mut table = NestedPartTable::default();
    for (start, layout) in &parted {
        let chunk = &stream[*start..];
        if layout.begins && layout.phase > 0 {
            split_all(&mut view, chunk, *start, layout, &mut table.splits)?;
        }
        for (chart, part) in layout.parts.iter().enumerate() {
            let mut record = measure(&mut view, layout.phase, chart, &chunk[part.clone()])?;
            record.level = layout.level;
            record.bytes = start + part.start..start + part.end;
            table.parts.push(record);
        }
    }
    Ok(table)
}

/// Splits every chart of the phase before `layout`'s by its entry.
fn split_all(
    view: &mut NestedView,
    chunk: &[u8],
    start: usize,
    layout: &NestedLayout,
    splits: &mut Vec<SplitRecord>,
) -> Result<()> {
    let phase = layout.phase;
    for (parent, (_, entry)) in layout.splits.iter().enumerate() {
        let bytes = chunk
            .get(entry.clone())
            .ok_or_else(|| Error::stream("a split entry past its batch"))?;
        view.split(phase - 1, parent, bytes)?;
        view.release(phase - 1, parent);
        splits.push(SplitRecord {
            level: layout.level,
            phase,
            parent,
            children: view.children(phase - 1, parent),
            bytes: start + entry.start..start + entry.end,
        });
    }
    Ok(())
}

/// Applies one part to its chart, measuring what it removes; the record's
/// level and bytes are left for the caller.
fn measure(view: &mut NestedView, phase: usize, chart: usize, part: &[u8]) -> Result<PartRecord> {
    let (before_vertices, before_faces) = match view.chart(phase, chart) {
        Some(c) => (c.quantized.len(), c.indices.to_vec()),
        None => (0, Vec::new()),
    };
    view.apply_part(phase, chart, part)?;
    let after = view
        .chart(phase, chart)
        .ok_or_else(|| Error::stream(format!("no chart {chart} of phase {phase}")))?;
    let error = removed_error(
        after.quantized,
        before_vertices,
        &before_faces,
        after.indices,
    );
    Ok(PartRecord {
        level: 0,
        chart,
        bytes: 0..0,
        inserted: after.quantized.len() - before_vertices,
        error_steps: error.largest.ceil() as u32,
        bulk_error_steps: error.bulk.ceil() as u32,
        phase,
        parent: view.parent(phase, chart),
    })
}
