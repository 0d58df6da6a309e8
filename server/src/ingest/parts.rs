//! A charted or nested stream's parts for the `stream_part` table (and a
//! nested one's split entries for `stream_split`): where each lies and the
//! error it removes, measured once here so the service and the viewer never
//! decode to learn them (issue 41).

use crate::storage::{PartRecord, SplitRecord};
use anyhow::Context;
use vitrine_codec::{
    nested_part_table, part_table, Limits, StreamIndex, CHARTED_VERSION, NESTED_VERSION,
};

/// The parts and split entries of `stream` (none unless it is charted or
/// nested), measured off the runtime's threads: it decodes the whole
/// stream once.
pub(super) async fn measure(
    stream: &[u8],
    index: &StreamIndex,
) -> anyhow::Result<(Vec<PartRecord>, Vec<SplitRecord>)> {
    let version = index.header.version;
    if version != CHARTED_VERSION && version != NESTED_VERSION {
        return Ok((Vec::new(), Vec::new()));
    }
    let step = f64::from(index.header.quantization.step);
    let bytes = stream.to_vec();
    let table = tokio::task::spawn_blocking(move || match version {
        NESTED_VERSION => nested_part_table(&bytes, Limits::default()),
        _ => part_table(&bytes, Limits::default()).map(|parts| vitrine_codec::NestedPartTable {
            parts,
            splits: Vec::new(),
        }),
    })
    .await
    .context("the part measuring task failed")?
    .context("measuring the stream's parts")?;
    let narrow = |v: usize, what: &str| {
        u32::try_from(v).with_context(|| format!("a part's {what} is over 2^32"))
    };
    let parts = table
        .parts
        .into_iter()
        .map(|p| {
            Ok(PartRecord {
                iteration: narrow(p.level, "level")?,
                chart: narrow(p.chart, "chart")?,
                bytes: narrow(p.bytes.len(), "size")?,
                inserted: narrow(p.inserted, "vertex count")?,
                error: f64::from(p.error_steps) * step,
                bulk_error: Some(f64::from(p.bulk_error_steps) * step),
                phase: narrow(p.phase, "phase")?,
                parent: p.parent.map(|k| narrow(k, "parent")).transpose()?,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    let splits = table
        .splits
        .into_iter()
        .map(|s| {
            Ok(SplitRecord {
                iteration: narrow(s.level, "level")?,
                parent: narrow(s.parent, "parent")?,
                first_child: narrow(s.children.start, "child")?,
                children: narrow(s.children.len(), "child count")?,
                bytes: narrow(s.bytes.len(), "split size")?,
            })
        })
        .collect::<anyhow::Result<_>>()?;
    Ok((parts, splits))
}
