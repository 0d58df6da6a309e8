//! Geodesic distance on a decoded level, for the viewer's measurement tool
//! (`vitrine_geodesic`): the level's positions and indices go in once, then
//! any number of measurements between picked points.
//!
//! 1. `geodesic_positions(len) -> ptr` and `geodesic_indices(len) -> ptr`:
//!    JS copies the level's f32 positions and u32 indices there.
//! 2. `geodesic_new() -> handle` (0 on error, see `error_ptr`).
//! 3. `geodesic_distance(handle, method, from xyz, to xyz) -> f64`: along the
//!    surface between the surface points nearest to the two positions
//!    (+∞ across components, NaN on error); `method` 0 = Dijkstra, 1 = fast
//!    marching.
//! 4. `geodesic_field(handle, method, xyz) -> ptr` to one f64 distance per
//!    vertex (length `geodesic_field_len`), valid until the next call.

use std::cell::RefCell;

use glam::DVec3;
use vitrine_geodesic::{distance_field, point_distance, Method, Surface, SurfacePoint};

use crate::fail;

thread_local! {
    static POSITIONS: RefCell<Vec<f32>> = const { RefCell::new(Vec::new()) };
    static INDICES: RefCell<Vec<u32>> = const { RefCell::new(Vec::new()) };
    static SURFACES: RefCell<Vec<Option<Surface>>> = const { RefCell::new(Vec::new()) };
    static FIELD: RefCell<Vec<f64>> = const { RefCell::new(Vec::new()) };
}

fn reserve<T: Copy + Default>(buffer: &RefCell<Vec<T>>, len: u32) -> u32 {
    let mut b = buffer.borrow_mut();
    b.clear();
    b.resize(len as usize, T::default());
    b.as_ptr() as usize as u32
}

/// Room for `len` f32 coordinates (three per vertex).
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_positions(len: u32) -> u32 {
    POSITIONS.with(|p| reserve(p, len))
}

/// Room for `len` u32 indices (three per face).
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_indices(len: u32) -> u32 {
    INDICES.with(|i| reserve(i, len))
}

/// The surface of the buffers above; a handle > 0, or 0 on a bad mesh.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_new() -> u32 {
    let built = POSITIONS.with(|p| {
        INDICES.with(|i| {
            let (p, i) = (p.borrow(), i.borrow());
            if p.len() % 3 != 0 || i.len() % 3 != 0 {
                return Err("positions and indices must come in threes".to_string());
            }
            let positions: Vec<[f32; 3]> = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            let triangles: Vec<[u32; 3]> = i.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
            Surface::from_parts(&positions, &triangles).map_err(|e| e.to_string())
        })
    });
    match built {
        Ok(s) => SURFACES.with(|ss| {
            let mut ss = ss.borrow_mut();
            ss.push(Some(s));
            ss.len() as u32
        }),
        Err(e) => {
            fail(e);
            0
        }
    }
}

fn method(code: u32) -> Option<Method> {
    match code {
        0 => Some(Method::Dijkstra),
        1 => Some(Method::FastMarching),
        _ => None,
    }
}

fn with_surface<T>(
    handle: u32,
    f: impl FnOnce(&Surface) -> Result<T, String>,
) -> Result<T, String> {
    SURFACES.with(|ss| {
        let ss = ss.borrow();
        let s = (handle as usize)
            .checked_sub(1)
            .and_then(|i| ss.get(i))
            .and_then(Option::as_ref)
            .ok_or_else(|| format!("no surface with handle {handle}"))?;
        f(s)
    })
}

fn nearest(s: &Surface, x: f64, y: f64, z: f64) -> Result<SurfacePoint, String> {
    SurfacePoint::nearest(s, DVec3::new(x, y, z))
        .ok_or_else(|| "no point: the surface has no faces or the position is not finite".into())
}

/// Geodesic distance between the surface points nearest to two positions.
#[allow(unsafe_code, clippy::too_many_arguments)]
#[no_mangle]
pub extern "C" fn geodesic_distance(
    handle: u32,
    method_code: u32,
    fx: f64,
    fy: f64,
    fz: f64,
    tx: f64,
    ty: f64,
    tz: f64,
) -> f64 {
    let result = with_surface(handle, |s| {
        let m = method(method_code).ok_or_else(|| format!("no method {method_code}"))?;
        let (from, to) = (nearest(s, fx, fy, fz)?, nearest(s, tx, ty, tz)?);
        Ok(point_distance(s, &from, &to, m))
    });
    result.unwrap_or_else(|e| {
        fail(e);
        f64::NAN
    })
}

/// Distance from the surface point nearest to a position to every vertex;
/// a pointer to the f64s, or 0 on error.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_field(handle: u32, method_code: u32, x: f64, y: f64, z: f64) -> u32 {
    let result = with_surface(handle, |s| {
        let m = method(method_code).ok_or_else(|| format!("no method {method_code}"))?;
        Ok(distance_field(s, &nearest(s, x, y, z)?, m))
    });
    match result {
        Ok(field) => FIELD.with(|f| {
            *f.borrow_mut() = field;
            f.borrow().as_ptr() as usize as u32
        }),
        Err(e) => {
            fail(e);
            0
        }
    }
}

/// Length of the last field, in f64s.
#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_field_len() -> u32 {
    FIELD.with(|f| f.borrow().len() as u32)
}

#[allow(unsafe_code)]
#[no_mangle]
pub extern "C" fn geodesic_free(handle: u32) {
    SURFACES.with(|ss| {
        if let Some(slot) = ss.borrow_mut().get_mut((handle as usize).wrapping_sub(1)) {
            *slot = None;
        }
    });
}
