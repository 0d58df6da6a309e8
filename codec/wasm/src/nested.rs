//! View-dependent decoding of a nested-chart stream (format 6, issue 41)
//! over the same pointer+length ABI as [`crate::view`]: each chart of the
//! tree refines by its own parts, and a chart that has had all its phase's
//! parts splits into its children ([`vitrine_codec::NestedView`]).
//!
//! 1. `nested_layout(len)` on each parted batch in stream order, in the
//!    input buffer (`nested_layouts_clear()` first for a new stream): 0 for
//!    a global batch, else the phase's chart count `n`, and at `sizes_ptr()`
//!    the u32s `level, phase, begins (0/1), head_start, head_end, s` then
//!    `children, start, end` for each of the `s` split entries (in a
//!    phase's first batch after phase 0: one per chart of the phase before)
//!    and `start, end` per chart (byte ranges within the batch). The
//!    layouts are kept for step 2.
//!    A viewer that fetches heads and parts, never whole batches, calls
//!    `nested_layout_declare(level, phase, charts, splits)` instead, from
//!    the part index's facts, with the `splits` children counts as u32s
//!    (little-endian) in the input buffer: the same layouts without their
//!    byte ranges, all that step 2 reads.
//! 2. `nested_new(decoder, len)` with the first parted batch's head in the
//!    input buffer turns a decoder (its global batches applied) into a view
//!    of the kept layouts; the decoder handle is spent, the layouts cleared.
//! 3. `nested_apply_part(view, phase, chart, len)` with the chart's next
//!    part; `nested_split(view, phase, chart, len)` with its split entry;
//!    `nested_drop(view, phase, chart)`.
//! 4. `nested_buffer_ptr/len(view, phase, chart, kind)`: one chart's
//!    positions (f32), colours (u8) or triangles in its own vertex ids
//!    (u32), or (kind `FIRST_IDS`) the ids of its first vertices where it
//!    was cut from (u32).
#![allow(unsafe_code)] // `#[no_mangle]` only, as in lib.rs

use crate::{fail, take_decoder, COLOURS, INDICES, INPUT, POSITIONS, SIZES};
use std::cell::RefCell;
use vitrine_codec::{NestedLayout, NestedView};

/// A chart's first vertices' ids where it was cut from, for
/// [`nested_buffer_ptr`] only.
pub const FIRST_IDS: u32 = 4;

thread_local! {
    static VIEWS: RefCell<Vec<Option<NestedView>>> = const { RefCell::new(Vec::new()) };
    static LAYOUTS: RefCell<Vec<NestedLayout>> = const { RefCell::new(Vec::new()) };
}

fn with_view<T>(handle: u32, f: impl FnOnce(&mut NestedView) -> T) -> Option<T> {
    VIEWS.with(|vs| {
        let mut vs = vs.borrow_mut();
        let slot = vs.get_mut((handle as usize).checked_sub(1)?)?;
        slot.as_mut().map(f)
    })
}

fn input<T>(len: u32, f: impl FnOnce(&[u8]) -> T) -> T {
    INPUT.with(|i| {
        let i = i.borrow();
        f(&i[..(len as usize).min(i.len())])
    })
}

/// Forgets the layouts kept for a view not made.
#[no_mangle]
pub extern "C" fn nested_layouts_clear() {
    LAYOUTS.with(|l| l.borrow_mut().clear());
}

/// The layout of the batch in the input buffer, read after the layouts
/// kept so far (see the module's notes): the chart count, 0 for a global
/// batch, −1 for a malformed one (not kept).
#[no_mangle]
pub extern "C" fn nested_layout(len: u32) -> i32 {
    let parsed =
        LAYOUTS.with(|l| input(len, |chunk| NestedLayout::parse(chunk, l.borrow().last())));
    match parsed {
        Ok(None) => 0,
        Ok(Some(layout)) => {
            SIZES.with(|s| {
                let mut s = s.borrow_mut();
                s.clear();
                s.extend(
                    [layout.level, layout.phase, usize::from(layout.begins)].map(|v| v as u32),
                );
                s.extend([layout.head.start as u32, layout.head.end as u32]);
                s.push(layout.splits.len() as u32);
                for (children, r) in &layout.splits {
                    s.extend([*children as u32, r.start as u32, r.end as u32]);
                }
                for r in &layout.parts {
                    s.extend([r.start as u32, r.end as u32]);
                }
            });
            let charts = layout.parts.len() as i32;
            LAYOUTS.with(|l| l.borrow_mut().push(layout));
            charts
        }
        Err(e) => fail(e.to_string()),
    }
}

/// Declares the next parted batch's layout from a part index's facts (see
/// the module's notes): the chart count, or −1 (not kept) when it does not
/// follow the layouts kept so far or its children do not add up.
#[no_mangle]
pub extern "C" fn nested_layout_declare(level: u32, phase: u32, charts: u32, splits: u32) -> i32 {
    let children: Vec<usize> = input(splits.saturating_mul(4), |bytes| {
        bytes
            .chunks_exact(4)
            .map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]]) as usize)
            .collect()
    });
    if children.len() != splits as usize {
        return fail(format!(
            "{splits} children counts expected in the input buffer"
        ));
    }
    let declared = LAYOUTS.with(|l| {
        let previous = l.borrow().last().map(|p| (p.phase, p.parts.len()));
        NestedLayout::declare(
            level as usize,
            phase as usize,
            charts as usize,
            &children,
            previous,
        )
    });
    match declared {
        Ok(layout) => {
            LAYOUTS.with(|l| l.borrow_mut().push(layout));
            charts as i32
        }
        Err(e) => fail(e.to_string()),
    }
}

/// Turns decoder `decoder` into a view of the kept layouts, the first
/// parted batch's head in the input buffer; a handle > 0, or 0 on error
/// (the decoder is spent and the layouts cleared either way).
#[no_mangle]
pub extern "C" fn nested_new(decoder: u32, len: u32) -> u32 {
    let layouts = LAYOUTS.with(|l| std::mem::take(&mut *l.borrow_mut()));
    let Some(decoder) = take_decoder(decoder) else {
        fail(format!("no decoder with handle {decoder}"));
        return 0;
    };
    match input(len, |head| decoder.into_nested_view(head, &layouts)) {
        Ok(view) => VIEWS.with(|vs| {
            let mut vs = vs.borrow_mut();
            vs.push(Some(view));
            vs.len() as u32
        }),
        Err(e) => {
            fail(e.to_string());
            0
        }
    }
}

fn status(view: u32, result: Option<vitrine_codec::Result<()>>) -> i32 {
    match result {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no nested view with handle {view}")),
    }
}

/// Applies a chart's next part, in the input buffer: 0, or −1 (see
/// `NestedView::apply_part`: a part that fails part-way removes the chart).
#[no_mangle]
pub extern "C" fn nested_apply_part(view: u32, phase: u32, chart: u32, len: u32) -> i32 {
    let result = input(len, |part| {
        with_view(view, |v| v.apply_part(phase as usize, chart as usize, part))
    });
    status(view, result)
}

/// Splits a chart into its children by its split entry, in the input
/// buffer: 0, or −1.
#[no_mangle]
pub extern "C" fn nested_split(view: u32, phase: u32, chart: u32, len: u32) -> i32 {
    let result = input(len, |entry| {
        with_view(view, |v| v.split(phase as usize, chart as usize, entry))
    });
    status(view, result)
}

/// Drops a chart of phase ≥ 1 and its descendants.
#[no_mangle]
pub extern "C" fn nested_drop(view: u32, phase: u32, chart: u32) {
    with_view(view, |v| v.drop_chart(phase as usize, chart as usize));
}

#[no_mangle]
pub extern "C" fn nested_phases(view: u32) -> u32 {
    with_view(view, |v| v.phase_count() as u32).unwrap_or(0)
}

#[no_mangle]
pub extern "C" fn nested_charts(view: u32, phase: u32) -> u32 {
    with_view(view, |v| v.chart_count(phase as usize) as u32).unwrap_or(0)
}

/// Parted batches in a phase: the parts each of its charts has in all.
#[no_mangle]
pub extern "C" fn nested_phase_batches(view: u32, phase: u32) -> u32 {
    with_view(view, |v| v.phase_batches(phase as usize) as u32).unwrap_or(0)
}

/// A chart's parent in the phase before; −1 in phase 0.
#[no_mangle]
pub extern "C" fn nested_parent(view: u32, phase: u32, chart: u32) -> i32 {
    with_view(view, |v| v.parent(phase as usize, chart as usize))
        .flatten()
        .map_or(-1, |p| p as i32)
}

/// A chart's first child in the phase after (see [`nested_children`]).
#[no_mangle]
pub extern "C" fn nested_first_child(view: u32, phase: u32, chart: u32) -> u32 {
    with_view(view, |v| {
        v.children(phase as usize, chart as usize).start as u32
    })
    .unwrap_or(0)
}

/// A chart's number of children (0 in the last phase).
#[no_mangle]
pub extern "C" fn nested_children(view: u32, phase: u32, chart: u32) -> u32 {
    with_view(view, |v| {
        v.children(phase as usize, chart as usize).len() as u32
    })
    .unwrap_or(0)
}

/// Parts applied to a chart in its phase; −1 while it is not in the view.
#[no_mangle]
pub extern "C" fn nested_depth(view: u32, phase: u32, chart: u32) -> i32 {
    with_view(view, |v| v.depth(phase as usize, chart as usize))
        .flatten()
        .map_or(-1, |d| d as i32)
}

/// Vertices held, all charts together, each counting its own copy.
#[no_mangle]
pub extern "C" fn nested_resident(view: u32) -> u32 {
    with_view(view, |v| v.resident_vertices() as u32).unwrap_or(0)
}

fn buffer(v: &NestedView, phase: u32, chart: u32, kind: u32) -> (usize, usize) {
    let (phase, chart) = (phase as usize, chart as usize);
    if kind == FIRST_IDS {
        let ids = v.first_ids(phase, chart);
        return (ids.as_ptr() as usize, ids.len());
    }
    let Some(c) = v.chart(phase, chart) else {
        return (0, 0);
    };
    match kind {
        POSITIONS => (c.positions.as_ptr() as usize, c.positions.len()),
        COLOURS => c.colours.map_or((0, 0), |c| (c.as_ptr() as usize, c.len())),
        INDICES => (c.indices.as_ptr() as usize, c.indices.len()),
        _ => (0, 0),
    }
}

/// Address of one chart's buffer; 0 when absent.
#[no_mangle]
pub extern "C" fn nested_buffer_ptr(view: u32, phase: u32, chart: u32, kind: u32) -> u32 {
    with_view(view, |v| buffer(v, phase, chart, kind).0 as u32).unwrap_or(0)
}

/// Length of one chart's buffer in elements.
#[no_mangle]
pub extern "C" fn nested_buffer_len(view: u32, phase: u32, chart: u32, kind: u32) -> u32 {
    with_view(view, |v| buffer(v, phase, chart, kind).1 as u32).unwrap_or(0)
}

#[no_mangle]
pub extern "C" fn nested_free(view: u32) {
    VIEWS.with(|vs| {
        if let Some(slot) = vs.borrow_mut().get_mut((view as usize).wrapping_sub(1)) {
            *slot = None;
        }
    });
}

#[cfg(test)]
mod tests;
