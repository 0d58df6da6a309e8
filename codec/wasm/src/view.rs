//! View-dependent decoding of a charted stream (issue 41) over the same
//! pointer+length ABI: each chart refines by its own parts to its own depth
//! ([`vitrine_codec::ChartView`]), so a viewer fetches and keeps only the
//! parts of the charts it shows closely and resets the others to make room.
//!
//! 1. `parted_layout(len)` on a batch in the input buffer: 0 for a global
//!    batch, else the number of charts `n`, and at `sizes_ptr()` the u32s
//!    `level, head_start, head_end, then start, end per chart` (byte ranges
//!    within the batch; an empty range is a chart that sits the batch out).
//! 2. `view_new(decoder, len)` with the first parted batch's head in the
//!    input buffer turns a decoder (its global batches applied) into a view;
//!    the decoder handle is spent.
//! 3. `view_apply_part(view, chart, len)` with the chart's next part in the
//!    input buffer; `view_reset(view, chart)`; `view_set_budget(view, n)`.
//! 4. `view_buffer_ptr/len(view, chart, kind)`: one chart's positions (f32),
//!    colours (u8) or triangles in its own vertex ids (u32).
#![allow(unsafe_code)] // `#[no_mangle]` only, as in lib.rs

use crate::{fail, take_decoder, COLOURS, INDICES, INPUT, POSITIONS, SIZES};
use std::cell::RefCell;
use vitrine_codec::{ChartView, PartedLayout};

thread_local! {
    static VIEWS: RefCell<Vec<Option<ChartView>>> = const { RefCell::new(Vec::new()) };
}

fn with_view<T>(handle: u32, f: impl FnOnce(&mut ChartView) -> T) -> Option<T> {
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

/// The layout of the batch in the input buffer (see the module's notes):
/// the chart count, 0 for a global batch, −1 for a malformed one.
#[no_mangle]
pub extern "C" fn parted_layout(len: u32) -> i32 {
    match input(len, PartedLayout::parse) {
        Ok(None) => 0,
        Ok(Some(layout)) => SIZES.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            s.push(layout.level as u32);
            for range in std::iter::once(&layout.head).chain(&layout.parts) {
                s.extend([range.start as u32, range.end as u32]);
            }
            layout.parts.len() as i32
        }),
        Err(e) => fail(e.to_string()),
    }
}

/// Turns decoder `decoder` into a view, the first parted batch's head in
/// the input buffer; a handle > 0, or 0 on error (the decoder is spent
/// either way).
#[no_mangle]
pub extern "C" fn view_new(decoder: u32, len: u32) -> u32 {
    let Some(decoder) = take_decoder(decoder) else {
        fail(format!("no decoder with handle {decoder}"));
        return 0;
    };
    match input(len, |head| decoder.into_view(head)) {
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

/// Applies `chart`'s next part, in the input buffer: 0, or −1 (the chart
/// as it was, or back at the cut; see `ChartView::apply_part`).
#[no_mangle]
pub extern "C" fn view_apply_part(view: u32, chart: u32, len: u32) -> i32 {
    let result = input(len, |part| {
        with_view(view, |v| v.apply_part(chart as usize, part))
    });
    match result {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no view with handle {view}")),
    }
}

/// Puts `chart` back where the cut left it.
#[no_mangle]
pub extern "C" fn view_reset(view: u32, chart: u32) {
    with_view(view, |v| v.reset(chart as usize));
}

/// The most vertices the view may hold, all charts together.
#[no_mangle]
pub extern "C" fn view_set_budget(view: u32, vertices: u32) {
    with_view(view, |v| v.set_vertex_budget(vertices as usize));
}

#[no_mangle]
pub extern "C" fn view_charts(view: u32) -> u32 {
    with_view(view, |v| v.chart_count() as u32).unwrap_or(0)
}

/// Parts applied to `chart` (0: as the cut left it).
#[no_mangle]
pub extern "C" fn view_depth(view: u32, chart: u32) -> u32 {
    with_view(view, |v| v.depth(chart as usize) as u32).unwrap_or(0)
}

/// The depth of every chart at the stream's final level.
#[no_mangle]
pub extern "C" fn view_final_depth(view: u32) -> u32 {
    with_view(view, |v| v.final_depth() as u32).unwrap_or(0)
}

/// Vertices held, all charts together (each with its copy of the cut).
#[no_mangle]
pub extern "C" fn view_resident(view: u32) -> u32 {
    with_view(view, |v| v.resident_vertices() as u32).unwrap_or(0)
}

fn buffer(v: &ChartView, chart: u32, kind: u32) -> (usize, usize) {
    let Some(c) = v.chart(chart as usize) else {
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
pub extern "C" fn view_buffer_ptr(view: u32, chart: u32, kind: u32) -> u32 {
    with_view(view, |v| buffer(v, chart, kind).0 as u32).unwrap_or(0)
}

/// Length of one chart's buffer in elements.
#[no_mangle]
pub extern "C" fn view_buffer_len(view: u32, chart: u32, kind: u32) -> u32 {
    with_view(view, |v| buffer(v, chart, kind).1 as u32).unwrap_or(0)
}

#[no_mangle]
pub extern "C" fn view_free(view: u32) {
    VIEWS.with(|vs| {
        if let Some(slot) = vs.borrow_mut().get_mut((view as usize).wrapping_sub(1)) {
            *slot = None;
        }
    });
}
