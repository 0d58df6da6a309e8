//! Garland–Heckbert error quadrics for the simplifier's placement and
//! ordering (what SEEDS.md 004 says the seed lacks: its midpoints and
//! centroids drift the surface pass after pass). Each input vertex starts
//! with the sum of its faces' planes, weighted by area; a merge adds the
//! two quadrics, and the merged vertex goes where their sum is least.
//!
//! Written here rather than taken from a crate: meshoptimizer and
//! fast-simplification are whole simplifiers in C++, and only the 4×4
//! algebra is needed, a few dozen lines over glam.

use glam::{DMat3, DVec3};

/// `vᵀ A v + 2 bᵀ v + c`, the summed squared distances to a set of planes
/// (A symmetric, stored whole for clarity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Quadric {
    a: DMat3,
    b: DVec3,
    c: f64,
}

/// Zero error everywhere (not derived: glam's `DMat3::default()` is the
/// identity).
impl Default for Quadric {
    fn default() -> Self {
        Quadric {
            a: DMat3::ZERO,
            b: DVec3::ZERO,
            c: 0.0,
        }
    }
}

/// Below this |det A| relative to the trace cubed, A counts as singular
/// (a flat or cylindrical patch: a line or plane of minima), and the
/// optimum is looked for along the edge instead.
const SINGULAR: f64 = 1e-9;

impl Quadric {
    /// The plane through `p` with unit normal `n`, weighted by `weight`.
    pub fn plane(n: DVec3, p: DVec3, weight: f64) -> Self {
        let d = -n.dot(p);
        let a = DMat3::from_cols(n * n.x, n * n.y, n * n.z) * weight;
        Quadric {
            a,
            b: n * (d * weight),
            c: d * d * weight,
        }
    }

    /// The error at `v`: the weighted sum of squared distances.
    pub fn error(&self, v: DVec3) -> f64 {
        (v.dot(self.a * v) + 2.0 * self.b.dot(v) + self.c).max(0.0)
    }

    /// The point of least error, when A is invertible (three planes or
    /// more that meet in one point).
    pub fn minimum(&self) -> Option<DVec3> {
        let scale = self.a.x_axis.x + self.a.y_axis.y + self.a.z_axis.z;
        let det = self.a.determinant();
        if scale > 0.0 && det.abs() > SINGULAR * scale.powi(3) {
            Some(-(self.a.inverse() * self.b)).filter(|v| v.is_finite())
        } else {
            None
        }
    }

    /// The least of the error plus `weight` times the trace of A times the
    /// squared distance to `anchor`: the minimum where the planes pin a
    /// point down, and towards `anchor` along the directions they leave
    /// free (a flat patch's tangent plane, a crease's line), so a
    /// near-singular A cannot throw the point far off.
    pub fn minimum_near(&self, anchor: DVec3, weight: f64) -> Option<DVec3> {
        let trace = self.a.x_axis.x + self.a.y_axis.y + self.a.z_axis.z;
        if trace.is_nan() || trace <= 0.0 {
            return Some(anchor);
        }
        let lambda = weight * trace;
        let a = self.a + DMat3::from_diagonal(DVec3::splat(lambda));
        if a.determinant().abs() <= f64::MIN_POSITIVE {
            return None;
        }
        Some(a.inverse() * (anchor * lambda - self.b)).filter(|v| v.is_finite())
    }

    /// Where a merge of `p` and `q` goes: the minimum, unless it is far
    /// from the edge (a near-singular A would stretch the surface); then
    /// the best of the ends, the midpoint and the quarter points.
    pub fn best_on(&self, p: DVec3, q: DVec3) -> DVec3 {
        let reach = p.distance(q).max(f64::MIN_POSITIVE);
        if let Some(v) = self
            .minimum()
            .filter(|v| v.distance((p + q) * 0.5) <= 2.0 * reach)
        {
            return v;
        }
        [0.0, 0.25, 0.5, 0.75, 1.0]
            .map(|t| p.lerp(q, t))
            .into_iter()
            .min_by(|x, y| self.error(*x).total_cmp(&self.error(*y)))
            .unwrap_or(p)
    }
}

impl std::ops::Add for Quadric {
    type Output = Quadric;

    fn add(self, o: Quadric) -> Quadric {
        Quadric {
            a: self.a + o.a,
            b: self.b + o.b,
            c: self.c + o.c,
        }
    }
}

impl std::ops::AddAssign for Quadric {
    fn add_assign(&mut self, o: Quadric) {
        *self = *self + o;
    }
}

/// Each vertex's quadric: the planes of its faces, weighted by area.
pub(crate) fn vertex_quadrics(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<Quadric> {
    let mut out = vec![Quadric::default(); positions.len()];
    let p = |v: u32| DVec3::from(positions[v as usize].map(f64::from));
    for &[a, b, c] in triangles {
        let cross = (p(b) - p(a)).cross(p(c) - p(a));
        let area = cross.length() * 0.5;
        if area <= 0.0 {
            continue;
        }
        let q = Quadric::plane(cross / (2.0 * area), p(a), area);
        for v in [a, b, c] {
            out[v as usize] += q;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_default_costs_nothing() {
        let q = Quadric::default();
        assert_eq!(q.error(DVec3::new(3.0, -2.0, 7.0)), 0.0);
        assert_eq!(q + q, q);
    }

    #[test]
    fn a_plane_costs_the_squared_distance() {
        let q = Quadric::plane(DVec3::Z, DVec3::new(3.0, -1.0, 2.0), 1.0);
        assert!((q.error(DVec3::new(7.0, 5.0, 5.0)) - 9.0).abs() < 1e-12);
        assert!(q.error(DVec3::new(-4.0, 0.5, 2.0)) < 1e-12);
    }

    #[test]
    fn three_planes_meet_at_their_corner() {
        let corner = DVec3::new(1.0, 2.0, 3.0);
        let q = Quadric::plane(DVec3::X, corner, 1.0)
            + Quadric::plane(DVec3::Y, corner, 1.0)
            + Quadric::plane(DVec3::Z, corner, 1.0);
        let v = q.best_on(DVec3::new(0.5, 2.0, 3.0), DVec3::new(1.5, 2.5, 3.0));
        assert!(v.distance(corner) < 1e-9, "{v}");
    }

    #[test]
    fn near_an_anchor_a_plane_pins_only_its_normal() {
        // z = 1 leaves x and y free: they stay at the anchor's, z goes to
        // the plane (but for the small pull of the anchor).
        let q = Quadric::plane(DVec3::Z, DVec3::new(0.0, 0.0, 1.0), 3.0);
        let v = q.minimum_near(DVec3::new(2.0, -1.0, 0.0), 1e-4).unwrap();
        assert!((v.x - 2.0).abs() < 1e-9 && (v.y + 1.0).abs() < 1e-9, "{v}");
        assert!((v.z - 1.0).abs() < 1e-3, "{v}");
        assert_eq!(
            Quadric::default().minimum_near(DVec3::ONE, 1e-4),
            Some(DVec3::ONE)
        );
    }

    #[test]
    fn a_flat_patch_keeps_the_vertex_on_its_edge() {
        // One plane: A is singular, any point on z = 0 is optimal; the
        // choice stays on the segment.
        let q = Quadric::plane(DVec3::Z, DVec3::ZERO, 2.0);
        let (p, r) = (DVec3::new(0.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0));
        let v = q.best_on(p, r);
        assert!(v.z.abs() < 1e-12 && (0.0..=1.0).contains(&v.x), "{v}");
    }
}
