//! The library calls a measurement makes: a source point's distance to
//! every vertex, and from one surface point to another.

use glam::DVec2;

use crate::march;
use crate::point::SurfacePoint;
use crate::propagation::{Method, Propagation};
use crate::surface::Surface;

/// The geodesic distance from `source` to every vertex (`f64::INFINITY`
/// where the source's component does not reach).
pub fn distance_field(surface: &Surface, source: &SurfacePoint, method: Method) -> Vec<f64> {
    let mut front = Propagation::new(surface, method);
    seed(&mut front, source);
    front.run(f64::INFINITY);
    front.distances().to_vec()
}

/// The geodesic distance between two surface points (`f64::INFINITY`
/// across components). On one face it is the straight distance.
pub fn point_distance(
    surface: &Surface,
    from: &SurfacePoint,
    to: &SurfacePoint,
    method: Method,
) -> f64 {
    if from.face == to.face {
        return from.position.distance(to.position);
    }
    let field = distance_field(surface, from, method);
    distance_inside(surface, &field, to, method)
}

/// The source's face corners start at their straight distance: exact, as
/// the face is flat.
fn seed(front: &mut Propagation<'_>, source: &SurfacePoint) {
    let surface = front.surface();
    for v in surface.triangles()[source.face as usize] {
        front.seed(v, 0, surface.position(v).distance(source.position));
    }
}

/// A point inside a face from its corners' distances: the best of each
/// corner plus the straight segment, and (fast marching) the front across
/// each edge, the same update as at a vertex.
pub(crate) fn distance_inside(
    surface: &Surface,
    field: &[f64],
    to: &SurfacePoint,
    method: Method,
) -> f64 {
    let t = surface.triangles()[to.face as usize];
    let mut best = t
        .iter()
        .map(|&v| field[v as usize] + surface.position(v).distance(to.position))
        .fold(f64::INFINITY, f64::min);
    if method == Method::FastMarching {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            let (da, db) = (field[a as usize], field[b as usize]);
            if !(da.is_finite() && db.is_finite()) {
                continue;
            }
            let (pa, pb) = (surface.position(a), surface.position(b));
            let (x, l) = ((pb - pa).normalize_or_zero(), pa.distance(pb));
            let rel = to.position - pa;
            let px = rel.dot(x);
            let py = (rel - px * x).length();
            if py > 0.0 {
                let c2 = DVec2::new(px, py);
                if let Some(d) = march::through(DVec2::ZERO, da, DVec2::new(l, 0.0), db, c2) {
                    best = best.min(d);
                }
            }
        }
    }
    best
}
