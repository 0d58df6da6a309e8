//! The fast-marching update of one corner from the other two.
//!
//! Kimmel & Sethian's update (seed 001 §3.1.2) assumes a plane wave
//! reaching A at T(A) and B at T(B). Here the front is taken as a circle
//! instead: the source is placed in the triangle's plane at T(A) from A
//! and T(B) from B, on the far side of AB, and C gets its straight
//! distance when that line crosses AB (Novotni & Klein 2002). The local
//! problem is the same, but the circle is exact for a point source on a
//! plane, where the plane wave errs by a few percent near the source.
//!
//! When the line misses AB and C is obtuse, the faces beyond AB are
//! unfolded into the plane until a vertex W lands inside the angle at C;
//! C is then updated from (A, W) and (W, B) as if those were triangles
//! (Kimmel & Sethian 1998 §4, which the seed leaves out). Otherwise the
//! edge updates T(A) + |AC|, T(B) + |BC| stand, made by the caller.

use glam::{DVec2, DVec3};

use crate::surface::{Surface, NONE};

/// Faces unfolded at most looking for a vertex inside an obtuse angle.
const MAX_UNFOLD: usize = 8;

/// C's distance through face `f` from its corners `a` and `b`, whose
/// distances `known` gives (as for any other settled vertex of the same
/// front); `None` when the front does not cross AB towards C.
pub(crate) fn update(
    surface: &Surface,
    f: u32,
    a: u32,
    b: u32,
    c: u32,
    known: &dyn Fn(u32) -> Option<f64>,
) -> Option<f64> {
    let (da, db) = (known(a)?, known(b)?);
    let (pa, pb, pc) = (
        surface.position(a),
        surface.position(b),
        surface.position(c),
    );
    // The face in its own plane: A at the origin, B on +x, C above.
    let ab = pb - pa;
    let l = ab.length();
    if l == 0.0 {
        return None;
    }
    let x = ab / l;
    let cx = (pc - pa).dot(x);
    let cy = ((pc - pa) - cx * x).length();
    if cy == 0.0 {
        return None;
    }
    let (a2, b2, c2) = (DVec2::ZERO, DVec2::new(l, 0.0), DVec2::new(cx, cy));
    if let Some(d) = through(a2, da, b2, db, c2) {
        return Some(d);
    }
    if (a2 - c2).dot(b2 - c2) >= 0.0 {
        return None; // not obtuse at C: the edge updates are right
    }
    let (w, w2) = unfold_into_angle(surface, f, [a, b], [a2, b2], c2, [pa, pb])?;
    let dw = known(w)?;
    [through(a2, da, w2, dw, c2), through(w2, dw, b2, db, c2)]
        .into_iter()
        .flatten()
        .reduce(f64::min)
}

/// The distance from the point source at `da` from `a` and `db` from `b`
/// (on the side of line ab away from `c`) to `c`, when the straight line
/// from the source to `c` crosses segment ab.
pub(crate) fn through(a: DVec2, da: f64, b: DVec2, db: f64, c: DVec2) -> Option<f64> {
    let e = b - a;
    let l = e.length();
    if l == 0.0 {
        return None;
    }
    let x = e / l;
    // C's height over line ab; the source goes on the other side.
    let cy = (c - a).dot(x.perp()).abs();
    if cy == 0.0 {
        return None;
    }
    let cx = (c - a).dot(x);
    let sx = (da * da - db * db + l * l) / (2.0 * l);
    let h2 = da * da - sx * sx;
    if h2 < 0.0 {
        return None; // |da − db| > |ab|: no source fits
    }
    let sy = -h2.sqrt();
    let t = -sy / (cy - sy);
    let crossing = sx + t * (cx - sx);
    if !(0.0..=l).contains(&crossing) {
        return None;
    }
    Some(DVec2::new(cx - sx, cy - sy).length())
}

/// Walks the faces beyond edge ab of face `f` (in the plane, a and b at
/// `flat`), unfolding each, until a vertex lies strictly inside the angle
/// acb; returns it and its unfolded position.
fn unfold_into_angle(
    surface: &Surface,
    f: u32,
    [a, b]: [u32; 2],
    [a2, b2]: [DVec2; 2],
    c2: DVec2,
    [pa, pb]: [DVec3; 2],
) -> Option<(u32, DVec2)> {
    let side = |p: DVec2, q: DVec2| (p - c2).perp_dot(q - c2);
    let turn = side(a2, b2);
    let (mut p, mut q) = ((a, a2, pa), (b, b2, pb));
    let (mut face, mut away) = (f, c2);
    for _ in 0..MAX_UNFOLD {
        let g = across_edge(surface, face, p.0, q.0)?;
        let t = surface.triangles()[g as usize];
        let w = t.iter().copied().find(|&v| v != p.0 && v != q.0)?;
        let pw = surface.position(w);
        let w2 = unfold(p.1, q.1, away, p.2.distance(pw), q.2.distance(pw))?;
        let beyond_a = side(a2, w2) * turn <= 0.0;
        let beyond_b = side(w2, b2) * turn <= 0.0;
        match (beyond_a, beyond_b) {
            (false, false) => return Some((w, w2)),
            // Beyond ray ca: the angle leaves this face through (w, q).
            (true, false) => {
                away = p.1;
                p = (w, w2, pw);
            }
            (false, true) => {
                away = q.1;
                q = (w, w2, pw);
            }
            (true, true) => return None,
        }
        face = g;
    }
    None
}

/// The face across edge (p, q) of `face`.
fn across_edge(surface: &Surface, face: u32, p: u32, q: u32) -> Option<u32> {
    let t = surface.triangles()[face as usize];
    let k = (0..3).find(|&k| {
        let (u, v) = (t[k], t[(k + 1) % 3]);
        (u == p && v == q) || (u == q && v == p)
    })?;
    let g = surface.across(face, k);
    (g != NONE).then_some(g)
}

/// The point `dp` from `p` and `dq` from `q` on the side of line pq away
/// from `away`.
fn unfold(p: DVec2, q: DVec2, away: DVec2, dp: f64, dq: f64) -> Option<DVec2> {
    let e = q - p;
    let l = e.length();
    if l == 0.0 {
        return None;
    }
    let x = e / l;
    let mut y = x.perp();
    if (away - p).dot(y) > 0.0 {
        y = -y;
    }
    let s = (dp * dp - dq * dq + l * l) / (2.0 * l);
    let h = (dp * dp - s * s).max(0.0).sqrt();
    Some(p + s * x + h * y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_point_source_on_the_plane_is_exact() {
        let source = DVec2::new(0.3, -2.0);
        let (a, b, c) = (DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(0.4, 0.8));
        let d = through(a, a.distance(source), b, b.distance(source), c).unwrap();
        assert!((d - c.distance(source)).abs() < 1e-12, "{d}");
    }

    #[test]
    fn a_line_that_misses_the_edge_gives_nothing() {
        let source = DVec2::new(-3.0, -0.5);
        let (a, b, c) = (DVec2::ZERO, DVec2::new(1.0, 0.0), DVec2::new(4.0, 0.2));
        assert!(through(a, a.distance(source), b, b.distance(source), c).is_none());
    }
}
