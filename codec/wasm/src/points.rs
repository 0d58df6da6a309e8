//! Point clouds in the viewer's worker (`vitrine_points`): decode a point
//! stream level by level and run the splat preprocessing on what has been
//! decoded. Same pointer+length pattern as the mesh decoder:
//!
//! 1. `input_reserve(len)`, JS copies the header (and possibly more) there;
//!    `points_new(len) -> handle` (0 on error, see `error_ptr`).
//! 2. Per level chunk: `input_reserve`, copy, `points_apply(handle, len)`
//!    → 0, or −1 on a truncated or corrupt chunk (the decoder then refuses
//!    further levels).
//! 3. `points_count`, `points_level`, `points_levels`; buffers by kind with
//!    `points_buffer_ptr` / `points_buffer_len` (elements): positions
//!    (f32 × 3), colours (u8 × 3), normals (f32 × 3, the stream's or, after
//!    `points_splats`, estimated).
//! 4. `points_splats(handle, sharp_threshold) -> 0 | −1`: radii (on the
//!    points decoded so far, so a prefix gets its own), graph, clip
//!    partners, surface ids; then `splat_buffer_ptr` / `splat_buffer_len`
//!    by kind: radii (f32), surface ids (u32), clip words (u32) and planes
//!    (f32 × 4), laid out as `vitrine_points::splat::clip` documents.
//!
//! The logic is in [`PointsSession`], which native tests drive directly.

use std::cell::RefCell;

use vitrine_points::splat::{preprocess, SplatOptions, Splats};
use vitrine_points::stream::{Limits, PointDecoder};
use vitrine_points::{estimate_normals, DEFAULT_K};

use crate::{fail, INPUT};

/// Point buffer kinds.
pub const POINT_POSITIONS: u32 = 0;
pub const POINT_COLOURS: u32 = 1;
pub const POINT_NORMALS: u32 = 2;
/// Splat buffer kinds.
pub const SPLAT_RADII: u32 = 0;
pub const SPLAT_SURFACE_IDS: u32 = 1;
pub const SPLAT_CLIP: u32 = 2;
pub const SPLAT_PLANES: u32 = 3;

/// One point stream being decoded, and its latest splats.
pub struct PointsSession {
    decoder: PointDecoder,
    /// Normals estimated for a stream without them (at the last splat run).
    estimated: Vec<[f32; 3]>,
    splats: Option<Splats>,
}

impl PointsSession {
    /// Starts on a stream's header.
    pub fn new(header: &[u8]) -> vitrine_points::Result<Self> {
        Ok(PointsSession {
            decoder: PointDecoder::new(header, Limits::default())?,
            estimated: Vec::new(),
            splats: None,
        })
    }

    /// Decodes one level chunk.
    pub fn apply(&mut self, chunk: &[u8]) -> vitrine_points::Result<()> {
        self.splats = None;
        self.decoder.apply_level(chunk)
    }

    pub fn decoder(&self) -> &PointDecoder {
        &self.decoder
    }

    /// The normals the splats use: the stream's, else estimated ones.
    pub fn normals(&self) -> &[[f32; 3]] {
        self.decoder.normals().unwrap_or(&self.estimated)
    }

    /// Runs the splat preprocessing on the points decoded so far.
    pub fn run_splats(&mut self, sharp_threshold: f32) -> Result<&Splats, String> {
        if !(-1.0..=1.0).contains(&sharp_threshold) {
            return Err(format!("sharp threshold {sharp_threshold} outside −1..=1"));
        }
        let positions = self.decoder.positions();
        if self.decoder.normals().is_none() {
            self.estimated = estimate_normals(positions, DEFAULT_K);
        }
        let opts = SplatOptions {
            sharp_threshold,
            ..SplatOptions::default()
        };
        let splats = preprocess(positions, self.normals(), &opts);
        Ok(self.splats.insert(splats))
    }

    pub fn splats(&self) -> Option<&Splats> {
        self.splats.as_ref()
    }

    /// (address, length in elements) of a point buffer.
    fn point_buffer(&self, kind: u32) -> (usize, usize) {
        let d = &self.decoder;
        match kind {
            POINT_POSITIONS => flat(d.positions().as_flattened()),
            POINT_COLOURS => d.colours().map_or((0, 0), |c| flat(c.as_flattened())),
            POINT_NORMALS => flat(self.normals().as_flattened()),
            _ => (0, 0),
        }
    }

    fn splat_buffer(&self, kind: u32) -> (usize, usize) {
        let Some(s) = &self.splats else {
            return (0, 0);
        };
        match kind {
            SPLAT_RADII => flat(&s.radii),
            SPLAT_SURFACE_IDS => flat(&s.surface_ids),
            SPLAT_CLIP => flat(&s.clipping.clip),
            SPLAT_PLANES => flat(&s.clipping.planes),
            _ => (0, 0),
        }
    }
}

fn flat<T>(v: &[T]) -> (usize, usize) {
    (v.as_ptr() as usize, v.len())
}

thread_local! {
    static SESSIONS: RefCell<Vec<Option<PointsSession>>> = const { RefCell::new(Vec::new()) };
}

fn with_session<T>(handle: u32, f: impl FnOnce(&mut PointsSession) -> T) -> Option<T> {
    SESSIONS.with(|s| {
        let mut s = s.borrow_mut();
        let slot = s.get_mut((handle as usize).checked_sub(1)?)?;
        slot.as_mut().map(f)
    })
}

fn input<T>(len: u32, f: impl FnOnce(&[u8]) -> T) -> T {
    INPUT.with(|i| {
        let i = i.borrow();
        f(&i[..(len as usize).min(i.len())])
    })
}

/// Starts a point decoder on the header in the input buffer; a handle > 0.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_new(len: u32) -> u32 {
    match input(len, PointsSession::new) {
        Ok(session) => SESSIONS.with(|s| {
            let mut s = s.borrow_mut();
            s.push(Some(session));
            s.len() as u32
        }),
        Err(e) => {
            fail(e.to_string());
            0
        }
    }
}

/// Decodes the level chunk in the input buffer. 0 on success, −1 on error.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_apply(handle: u32, len: u32) -> i32 {
    match input(len, |bytes| with_session(handle, |s| s.apply(bytes))) {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e.to_string()),
        None => fail(format!("no point decoder with handle {handle}")),
    }
}

/// Points decoded so far.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_count(handle: u32) -> u32 {
    with_session(handle, |s| s.decoder().point_count() as u32).unwrap_or(0)
}

/// Levels decoded so far.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_level(handle: u32) -> u32 {
    with_session(handle, |s| s.decoder().level() as u32).unwrap_or(0)
}

/// Levels in the stream.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_levels(handle: u32) -> u32 {
    with_session(handle, |s| s.decoder().header().levels() as u32).unwrap_or(0)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_buffer_ptr(handle: u32, kind: u32) -> u32 {
    with_session(handle, |s| s.point_buffer(kind).0 as u32).unwrap_or(0)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_buffer_len(handle: u32, kind: u32) -> u32 {
    with_session(handle, |s| s.point_buffer(kind).1 as u32).unwrap_or(0)
}

/// Splat preprocessing of the points decoded so far. 0, or −1 on error.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_splats(handle: u32, sharp_threshold: f32) -> i32 {
    match with_session(handle, |s| s.run_splats(sharp_threshold).map(|_| ())) {
        Some(Ok(())) => 0,
        Some(Err(e)) => fail(e),
        None => fail(format!("no point decoder with handle {handle}")),
    }
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn splat_buffer_ptr(handle: u32, kind: u32) -> u32 {
    with_session(handle, |s| s.splat_buffer(kind).0 as u32).unwrap_or(0)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn splat_buffer_len(handle: u32, kind: u32) -> u32 {
    with_session(handle, |s| s.splat_buffer(kind).1 as u32).unwrap_or(0)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn points_free(handle: u32) {
    SESSIONS.with(|s| {
        if let Some(slot) = s.borrow_mut().get_mut((handle as usize).wrapping_sub(1)) {
            *slot = None;
        }
    });
}
