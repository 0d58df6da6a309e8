//! Points on the surface (not only vertices): where a measurement starts
//! and ends, found as the nearest point of the mesh to a picked position.

use glam::DVec3;

use crate::surface::Surface;

/// A point on face `face` of a [`Surface`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    pub face: u32,
    pub position: DVec3,
}

impl SurfacePoint {
    /// The point of `surface` nearest to `p` (a linear scan of the faces:
    /// a measurement makes two), or `None` on a surface without faces or
    /// for a non-finite `p`.
    pub fn nearest(surface: &Surface, p: DVec3) -> Option<SurfacePoint> {
        if !p.is_finite() {
            return None;
        }
        let mut best: Option<(f64, SurfacePoint)> = None;
        for (f, t) in surface.triangles().iter().enumerate() {
            let corners = t.map(|v| surface.position(v));
            let q = closest_on_triangle(p, &corners);
            let d = q.distance_squared(p);
            if best.is_none_or(|(b, _)| d < b) {
                let point = SurfacePoint {
                    face: f as u32,
                    position: q,
                };
                best = Some((d, point));
            }
        }
        best.map(|(_, point)| point)
    }

    /// The point at vertex `v` (on its first face), or `None` for a vertex
    /// that no face uses or out of range.
    pub fn at_vertex(surface: &Surface, v: u32) -> Option<SurfacePoint> {
        if v as usize >= surface.vertex_count() {
            return None;
        }
        let &face = surface.faces_of(v).first()?;
        Some(SurfacePoint {
            face,
            position: surface.position(v),
        })
    }
}

/// Ericson, Real-Time Collision Detection §5.1.5: the nearest point of a
/// triangle, by the Voronoi region of `p` among its corners and edges.
fn closest_on_triangle(p: DVec3, [a, b, c]: &[DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (*b - *a, *c - *a, p - *a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - *b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return *a + ab * (d1 / (d1 - d3));
    }
    let cp = p - *c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return *a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return *b + (*c - *b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom == 0.0 {
        return *a; // a degenerate face: any corner is as near as it gets
    }
    *a + ab * (vb / denom) + ac * (vc / denom)
}
