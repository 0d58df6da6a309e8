//! Every part of a charted stream with its place in the stream and the
//! error it removes: measured once at ingest, kept by the server with the
//! part, read by the viewer to refine by screen-space error.

use std::ops::Range;

use super::error::removed_error;
use super::PartedLayout;
use crate::format::NESTED_VERSION;
use crate::{ChartView, Decoder, Error, Limits, Result, StreamIndex};

/// One chart's part of one parted batch.
#[derive(Clone, Debug, PartialEq)]
pub struct PartRecord {
    /// The batch's level (1 = the first batch after the base).
    pub level: usize,
    /// The chart, by its position in its phase (format 5: in the stream).
    pub chart: usize,
    /// Its bytes in the whole stream (empty when the chart sits it out).
    pub bytes: Range<usize>,
    /// Vertices it inserts.
    pub inserted: usize,
    /// The largest distance, in quantization steps rounded up, from a vertex
    /// it inserts to the chart's coarser surface (× the stream's step:
    /// model units).
    pub error_steps: u32,
    /// The distance, in quantization steps rounded up, within which
    /// [`super::BULK_SHARE`] of those vertices lie: what a viewer refines by
    /// (`error_steps` bounds it).
    pub bulk_error_steps: u32,
    /// Its chart's phase: 0 in a charted stream (format 5) and for a nested
    /// stream's top charts (format 6).
    pub phase: usize,
    /// Its chart's parent, by position in phase `phase − 1` (format 6,
    /// phase ≥ 1); `None` otherwise.
    pub parent: Option<usize>,
}

/// The parts of a charted stream (format 5) or of a nested one (format 6:
/// [`super::nested_part_table`]'s parts, without the split entries), batch
/// by batch and chart by chart; empty for a plain stream. Decodes the
/// stream once, as a view decoder does, measuring each part against the
/// chart it refines.
pub fn part_table(stream: &[u8], limits: Limits) -> Result<Vec<PartRecord>> {
    let index = StreamIndex::parse(stream)?;
    if index.header.version == NESTED_VERSION {
        return Ok(super::nested_part_table(stream, limits)?.parts);
    }
    // The decoder until the charts begin, then the view it turns into.
    let mut decoder = Some(Decoder::new(&stream[index.base.clone()], limits)?);
    let mut view: Option<ChartView> = None;
    let mut records = Vec::new();
    for range in &index.batches {
        let chunk = &stream[range.clone()];
        let Some(layout) = PartedLayout::parse(chunk)? else {
            decoder
                .as_mut()
                .ok_or_else(|| Error::stream("a whole-mesh batch after parted ones"))?
                .apply_batch(chunk)?;
            continue;
        };
        let view = match (&mut view, decoder.take()) {
            (Some(v), _) => v,
            (None, Some(d)) => view.insert(d.into_view(&chunk[layout.head.clone()])?),
            (None, None) => return Err(Error::stream("no decoder left for the charts")),
        };
        for (chart, part) in layout.parts.iter().enumerate() {
            let (before_vertices, before_faces) = match view.chart(chart) {
                Some(c) => (c.quantized.len(), c.indices.to_vec()),
                None => (0, Vec::new()),
            };
            view.apply_part(chart, &chunk[part.clone()])?;
            let after = view.chart(chart).expect("applied above");
            let error = removed_error(
                after.quantized,
                before_vertices,
                &before_faces,
                after.indices,
            );
            records.push(PartRecord {
                level: layout.level,
                chart,
                bytes: range.start + part.start..range.start + part.end,
                inserted: after.quantized.len() - before_vertices,
                error_steps: error.largest.ceil() as u32,
                bulk_error_steps: error.bulk.ceil() as u32,
                phase: 0,
                parent: None,
            });
        }
    }
    Ok(records)
}
