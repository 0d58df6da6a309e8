//! A tiny pointer+length ABI over [`vitrine_codec::Decoder`] for WebAssembly.
//!
//! Hand-written rather than wasm-bindgen: the surface is eight functions on
//! integers, the JS side (`web/src/codec.js`) is forty lines, and the build
//! needs only `cargo build --target wasm32-unknown-unknown` — no CLI whose
//! version must match a crate's. The calling pattern:
//!
//! 1. `input_reserve(len) -> ptr`; JS copies the bytes to `memory[ptr..]`.
//! 2. `decoder_new(len) -> handle` (0 on error) or `decoder_apply(handle, len) -> 0 | -1`.
//! 3. `buffer_ptr(handle, kind)` / `buffer_len(handle, kind)`: views on the
//!    level's positions (f32), colours (u8) or indices (u32); copy them
//!    before the next call, which may move memory.
//! 4. On error `error_ptr()` / `error_len()` give a UTF-8 message.
//!
//! A charted stream (format 5) can be decoded by a pool of workers, each
//! with its own instance: `decoder_chart_sizes(handle, len)` reads how big
//! each chart of a first parted batch will be (then `sizes_ptr()`, u32s);
//! `decoder_refine_only(handle, lo, hi)` before the next parted batch makes
//! a decoder refine only the charts in the 64-bit mask; `decoder_charts`,
//! `chart_new_from`, `chart_buffer_ptr` and `chart_buffer_len` read one
//! chart (`web/src/decode-pool.js` merges them).
//!
//! [`view`] decodes a charted stream part by part, each chart to its own
//! depth (issue 41); [`nested`] does the same for a nested stream's tree
//! of charts (format 6). [`geodesic`] adds distance along the surface of a decoded level, for
//! the viewer's measurement tool; [`points`] decodes point streams and
//! preprocesses splats.
//!
//! Exported symbols need `#[no_mangle]`, which the `unsafe_code` lint flags;
//! nothing here dereferences a raw pointer: all memory is Rust-owned `Vec`s.
#![deny(unsafe_code)]

pub mod geodesic;
pub mod nested;
pub mod points;
pub mod view;

use std::cell::RefCell;
use vitrine_codec::{Decoder, Limits};

thread_local! {
    pub(crate) static INPUT: RefCell<Vec<u8>> = const { RefCell::new(Vec::new()) };
    static ERROR: RefCell<String> = const { RefCell::new(String::new()) };
    static DECODERS: RefCell<Vec<Option<Decoder>>> = const { RefCell::new(Vec::new()) };
    pub(crate) static SIZES: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
}

/// Buffer kinds for [`buffer_ptr`] and [`buffer_len`].
pub const POSITIONS: u32 = 0;
pub const COLOURS: u32 = 1;
pub const INDICES: u32 = 2;
/// A chart's triangles in level ids (u32, `ChartLevel::level_indices`),
/// for [`chart_buffer_ptr`] only.
pub const LEVEL_INDICES: u32 = 3;

pub(crate) fn fail(message: String) -> i32 {
    ERROR.with(|e| *e.borrow_mut() = message);
    -1
}

/// Makes room for `len` input bytes and returns where JS should write them.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn input_reserve(len: u32) -> u32 {
    INPUT.with(|i| {
        let mut i = i.borrow_mut();
        i.clear();
        i.resize(len as usize, 0);
        i.as_ptr() as usize as u32
    })
}

/// Starts a decoder on the header + base mesh in the input buffer; returns a handle > 0.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_new(len: u32) -> u32 {
    let result = INPUT.with(|i| {
        let i = i.borrow();
        Decoder::new(&i[..(len as usize).min(i.len())], Limits::default())
    });
    match result {
        Ok(d) => DECODERS.with(|ds| {
            let mut ds = ds.borrow_mut();
            ds.push(Some(d));
            ds.len() as u32
        }),
        Err(e) => {
            fail(e.to_string());
            0
        }
    }
}

/// Takes decoder `handle` out of its slot (for [`view::view_new`]).
pub(crate) fn take_decoder(handle: u32) -> Option<Decoder> {
    DECODERS.with(|ds| {
        let mut ds = ds.borrow_mut();
        ds.get_mut((handle as usize).checked_sub(1)?)?.take()
    })
}

fn with_decoder<T>(handle: u32, f: impl FnOnce(&mut Decoder) -> T) -> Option<T> {
    DECODERS.with(|ds| {
        let mut ds = ds.borrow_mut();
        let slot = ds.get_mut((handle as usize).checked_sub(1)?)?;
        slot.as_mut().map(f)
    })
}

/// Applies the refinement batch in the input buffer. 0 on success, −1 on error.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_apply(handle: u32, len: u32) -> i32 {
    let result = INPUT.with(|i| {
        let i = i.borrow();
        with_decoder(handle, |d| d.apply_batch(&i[..(len as usize).min(i.len())]))
    });
    match result {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no decoder with handle {handle}")),
    }
}

/// Vertex count at the current level.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_vertices(handle: u32) -> u32 {
    with_decoder(handle, |d| d.vertex_count() as u32).unwrap_or(0)
}

/// Batches applied so far.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_level(handle: u32) -> u32 {
    with_decoder(handle, |d| d.level() as u32).unwrap_or(0)
}

fn buffer(d: &Decoder, kind: u32) -> (usize, usize) {
    match kind {
        POSITIONS => (d.positions().as_ptr() as usize, d.positions().len()),
        COLOURS => d
            .colours()
            .map_or((0, 0), |c| (c.as_ptr() as usize, c.len())),
        _ => (d.indices().as_ptr() as usize, d.indices().len()),
    }
}

/// Address of a level buffer (see the kinds above); 0 when absent.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn buffer_ptr(handle: u32, kind: u32) -> u32 {
    with_decoder(handle, |d| buffer(d, kind).0 as u32).unwrap_or(0)
}

/// Length of a level buffer in elements (f32, u8 or u32).
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn buffer_len(handle: u32, kind: u32) -> u32 {
    with_decoder(handle, |d| buffer(d, kind).1 as u32).unwrap_or(0)
}

/// Refine only the charts in the mask `hi << 32 | lo` from the next
/// parted batch on (see `Decoder::refine_only`). 0, or −1 when the decoder
/// refines only some charts already.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_refine_only(handle: u32, lo: u32, hi: u32) -> i32 {
    match with_decoder(handle, |d| {
        d.refine_only(u64::from(hi) << 32 | u64::from(lo))
    }) {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no decoder with handle {handle}")),
    }
}

/// The faces of each chart that the first parted batch in the input buffer
/// will cut the level into (`Decoder::chart_sizes`): returns the number of
/// charts, the sizes at [`sizes_ptr`]; −1 on error.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_chart_sizes(handle: u32, len: u32) -> i32 {
    let result = INPUT.with(|i| {
        let i = i.borrow();
        with_decoder(handle, |d| d.chart_sizes(&i[..(len as usize).min(i.len())]))
    });
    match result {
        Some(Ok(sizes)) => SIZES.with(|s| {
            let mut s = s.borrow_mut();
            s.clear();
            s.extend(sizes.iter().map(|&n| n as u32));
            s.len() as i32
        }),
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no decoder with handle {handle}")),
    }
}

/// Where the last [`decoder_chart_sizes`] left its u32s.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn sizes_ptr() -> u32 {
    SIZES.with(|s| s.borrow().as_ptr() as usize as u32)
}

/// The chart's vertices before the last batch (`ChartLevel::new_from`).
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn chart_new_from(handle: u32, chart: u32) -> u32 {
    with_decoder(handle, |d| {
        d.chart(chart as usize).map_or(0, |c| c.new_from as u32)
    })
    .unwrap_or(0)
}

/// Charts of the stream once its first parted batch is applied (else 0).
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_charts(handle: u32) -> u32 {
    with_decoder(handle, |d| d.chart_count() as u32).unwrap_or(0)
}

fn chart_buffer(d: &Decoder, chart: u32, kind: u32) -> (usize, usize) {
    let Some(c) = d.chart(chart as usize) else {
        return (0, 0);
    };
    match kind {
        POSITIONS => (c.positions.as_ptr() as usize, c.positions.len()),
        COLOURS => c.colours.map_or((0, 0), |c| (c.as_ptr() as usize, c.len())),
        INDICES => (c.indices.as_ptr() as usize, c.indices.len()),
        _ => (c.level_indices.as_ptr() as usize, c.level_indices.len()),
    }
}

/// Address of one chart's buffer (kinds as above, and [`LEVEL_INDICES`]); 0 when absent.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn chart_buffer_ptr(handle: u32, chart: u32, kind: u32) -> u32 {
    with_decoder(handle, |d| chart_buffer(d, chart, kind).0 as u32).unwrap_or(0)
}

/// Length of one chart's buffer in elements.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn chart_buffer_len(handle: u32, chart: u32, kind: u32) -> u32 {
    with_decoder(handle, |d| chart_buffer(d, chart, kind).1 as u32).unwrap_or(0)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn decoder_free(handle: u32) {
    DECODERS.with(|ds| {
        if let Some(slot) = ds.borrow_mut().get_mut((handle as usize).wrapping_sub(1)) {
            *slot = None;
        }
    });
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn error_ptr() -> u32 {
    ERROR.with(|e| e.borrow().as_ptr() as usize as u32)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn error_len() -> u32 {
    ERROR.with(|e| e.borrow().len() as u32)
}
