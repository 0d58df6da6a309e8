//! How far apart the sites are. The seed covers the surface with discs of
//! one radius r, so a flat region gets as many sites as a fold of the same
//! area, and the Hausdorff distance, which the worst-served region sets,
//! comes from the folds (lucy, nefertiti-100k: 2–4× quadric's at 10 %,
//! session 33). [`VoronoiSpacing::Adaptive`] scales each vertex's cover
//! radius by a density read from the surface, as curvature-adapted
//! centroidal Voronoi remeshing does (Valette & Chassery's ACVD weighs
//! the area by curvature): a chord across a cell of radius ρ on a surface
//! of curvature κ misses it by about κρ²/2, so equal error wants ρ ∝
//! 1/√κ. The density is measured at the scale of the cells: each vertex's
//! height h, the farthest any vertex within geodesic distance s lies from
//! its tangent plane (≈ κs²/2 on a smooth patch; a thin fold or a rim
//! within s counts in full). The radius factor is (h / median h)^-½,
//! capped to [1/CAP, CAP], then limited to grow by at most GRADE × the
//! distance (in units of s) from any vertex, so that neighbouring cells
//! differ gradually, and last scaled so that the mean density (factor⁻²
//! over the area) is 1: a radius gives about as many sites either way,
//! and a plane's spacing is the seed's.
//!
//! The height is a proxy, and lucy's worst error at 10 % stayed where it
//! did not see it (2.40× quadric's). So up to ERROR_PASSES more passes
//! read the error itself: each input vertex's distance to the last
//! output, where it exceeds the 90th percentile, shrinks the factor there
//! (`refined_factors`), the radius is searched again from the last one,
//! and a pass is kept only if its worst vertex lies closer (lucy 10 %,
//! Dijkstra, quadric placement: 2.40× quadric's Hausdorff after the
//! height alone, 1.98× after the passes; session 34's log).

use std::str::FromStr;

use glam::DVec3;
use vitrine_codec::{Error, Result};
use vitrine_geodesic::{Method, Propagation, Surface};

/// How the cover radius varies over the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum VoronoiSpacing {
    /// One radius everywhere (the seed).
    Uniform,
    /// Smaller where the surface bends within a cell's reach, larger where
    /// it is flat, then denser where the error stayed largest (the default
    /// since session 34: better on the whole table).
    #[default]
    Adaptive,
}

impl FromStr for VoronoiSpacing {
    type Err = Error;

    /// `uniform` or `adaptive`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "uniform" => Ok(VoronoiSpacing::Uniform),
            "adaptive" => Ok(VoronoiSpacing::Adaptive),
            _ => Err(Error::Parameter(format!(
                "spacing must be uniform or adaptive, got {s:?}"
            ))),
        }
    }
}

/// The radius factor stays within [1/CAP, CAP] of the median vertex's.
const CAP: f64 = 3.0;

/// Radius factor ∝ (h / median h)^-POWER (½: equal chord error).
const POWER: f64 = 0.5;

/// The factor grows by at most this much per s of geodesic distance.
const GRADE: f64 = 1.0;

/// Passes that move sites to where the last one left its error.
pub(super) const ERROR_PASSES: usize = 3;

/// Vertices whose error exceeds this quantile's get denser sites.
const ERROR_QUANTILE: f64 = 0.9;

/// A pass shrinks a factor to this share of itself at most.
const ERROR_SHRINK: f64 = 0.5;

/// Each vertex's radius factor (1 for cones and unused vertices, which
/// never become sites). `s` is the scale the height is measured at: the
/// cover radius, or its estimate for a vertex count.
pub(super) fn radius_factors(surface: &Surface, first_cone: u32, s: f64) -> Vec<f64> {
    let used = used_vertices(surface, first_cone);
    let height = disc_max(surface, &used, s, |v| {
        let (normal, p) = (vertex_normal(surface, v), surface.position(v));
        move |w| normal.dot(surface.position(w) - p).abs()
    });
    let factor = relative_factors(&used, &height, CAP);
    finish(surface, &used, factor, s)
}

/// The factors once more, from the error the last pass left: each vertex's
/// `error` (its distance to that pass's output), as its largest within s,
/// shrinks its factor by (e / e₉₀)^-½ where it exceeds the 90th
/// percentile e₉₀ (by half at most), so that sites move to where the
/// error was (the normalisation takes them from everywhere else). The
/// range may widen to CAP² either way of the median.
pub(super) fn refined_factors(
    surface: &Surface,
    first_cone: u32,
    s: f64,
    factors: &[f64],
    error: &[f64],
) -> Vec<f64> {
    let used = used_vertices(surface, first_cone);
    let worst = disc_max(surface, &used, s, |_| |w: u32| error[w as usize]);
    let mut sorted: Vec<f64> = (0..worst.len())
        .filter(|&v| used[v])
        .map(|v| worst[v])
        .collect();
    if sorted.is_empty() {
        return factors.to_vec();
    }
    sorted.sort_by(f64::total_cmp);
    let bar = sorted[((sorted.len() - 1) as f64 * ERROR_QUANTILE) as usize].max(f64::MIN_POSITIVE);
    let change: Vec<f64> = worst
        .iter()
        .map(|&e| (e / bar).powf(-POWER).clamp(ERROR_SHRINK, 1.0))
        .collect();
    let factor: Vec<f64> = (0..factors.len())
        .map(|v| if used[v] { factors[v] * change[v] } else { 1.0 })
        .collect();
    let middle = median(&used, &factor);
    let factor = factor
        .iter()
        .map(|&f| (f / middle).clamp(1.0 / (CAP * CAP), CAP * CAP))
        .collect();
    finish(surface, &used, factor, s)
}

fn used_vertices(surface: &Surface, first_cone: u32) -> Vec<bool> {
    (0..surface.vertex_count() as u32)
        .map(|v| v < first_cone && !surface.faces_of(v).is_empty())
        .collect()
}

/// For each used vertex v, the largest `value(v)(w)` over the vertices w
/// within geodesic distance s of it (Dijkstra); 0 elsewhere.
fn disc_max<F: Fn(u32) -> f64>(
    surface: &Surface,
    used: &[bool],
    s: f64,
    value: impl Fn(u32) -> F,
) -> Vec<f64> {
    let mut front = Propagation::new(surface, Method::Dijkstra);
    let mut out = vec![0.0; used.len()];
    for v in 0..used.len() as u32 {
        if !used[v as usize] {
            continue;
        }
        let at = value(v);
        front.seed(v, 0, 0.0);
        front.run(s);
        out[v as usize] = front
            .touched()
            .iter()
            .filter(|&&w| front.distance(w) <= s && used[w as usize])
            .map(|&w| at(w))
            .fold(0.0, f64::max);
        front.clear();
    }
    out
}

fn median(used: &[bool], values: &[f64]) -> f64 {
    let mut sorted: Vec<f64> = (0..values.len())
        .filter(|&v| used[v])
        .map(|v| values[v])
        .collect();
    if sorted.is_empty() {
        return 1.0;
    }
    let middle = sorted.len() / 2;
    *sorted.select_nth_unstable_by(middle, f64::total_cmp).1
}

/// (x / median x)^-POWER within [1/cap, cap]; 1 for unused vertices.
fn relative_factors(used: &[bool], height: &[f64], cap: f64) -> Vec<f64> {
    let n = used.len();
    let middle = median(used, height);
    // A surface flat in more than half its vertices: the median plane
    // height is 0, and the flat half gets the cap.
    let reference = if middle > 0.0 {
        middle
    } else {
        (0..n)
            .filter(|&v| used[v])
            .map(|v| height[v])
            .fold(0.0, f64::max)
            .max(f64::MIN_POSITIVE)
    };
    (0..n)
        .map(|v| {
            if !used[v] {
                return 1.0;
            }
            let h = height[v].max(reference / cap.powf(1.0 / POWER));
            (h / reference).powf(-POWER).clamp(1.0 / cap, cap)
        })
        .collect()
}

/// Graded (`grade`) and scaled to a mean density of 1.
fn finish(surface: &Surface, used: &[bool], mut factor: Vec<f64>, s: f64) -> Vec<f64> {
    let n = used.len();
    grade(surface, used, &mut factor, s);
    // Scaled so that the mean density (factor⁻², over the area) is 1: r
    // gives about as many sites as uniform spacing does.
    let (mut area, mut density) = (0.0, 0.0);
    for v in (0..n).filter(|&v| used[v]) {
        let a = vertex_area(surface, v as u32);
        area += a;
        density += a / (factor[v] * factor[v]);
    }
    let (lo, hi) = (0..n)
        .filter(|&v| used[v])
        .fold((f64::MAX, 0.0f64), |(l, h), v| {
            (l.min(factor[v]), h.max(factor[v]))
        });
    if hi <= lo * (1.0 + 1e-12) {
        // Evenly curved (or flat): the seed's spacing, exactly.
        return vec![1.0; n];
    }
    if area > 0.0 && density > 0.0 {
        let k = (density / area).sqrt();
        for v in (0..n).filter(|&v| used[v]) {
            factor[v] *= k;
        }
    }
    factor
}

/// A third of the area of the vertex's faces.
fn vertex_area(surface: &Surface, v: u32) -> f64 {
    surface
        .faces_of(v)
        .iter()
        .map(|&f| {
            let p = surface.triangles()[f as usize].map(|u| surface.position(u));
            (p[1] - p[0]).cross(p[2] - p[0]).length() / 6.0
        })
        .sum()
}

/// Limits the factor to grow by at most GRADE per s along the edges: one
/// Dijkstra-like sweep from the smallest factors (factor(w) ≤ factor(v) +
/// GRADE × |vw| / s).
fn grade(surface: &Surface, used: &[bool], factor: &mut [f64], s: f64) {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let key = |f: f64| f.to_bits();
    let mut heap: BinaryHeap<Reverse<(u64, u32)>> = (0..factor.len() as u32)
        .filter(|&v| used[v as usize])
        .map(|v| Reverse((key(factor[v as usize]), v)))
        .collect();
    while let Some(Reverse((k, v))) = heap.pop() {
        if k != key(factor[v as usize]) {
            continue;
        }
        let (next, lengths) = surface.neighbours(v);
        for (&w, &l) in next.iter().zip(lengths) {
            if !used[w as usize] {
                continue;
            }
            let bound = factor[v as usize] + GRADE * l / s;
            if bound < factor[w as usize] {
                factor[w as usize] = bound;
                heap.push(Reverse((key(bound), w)));
            }
        }
    }
}

/// The area-weighted normal of the vertex's faces (zero if they cancel).
fn vertex_normal(surface: &Surface, v: u32) -> DVec3 {
    surface
        .faces_of(v)
        .iter()
        .map(|&f| {
            let p = surface.triangles()[f as usize].map(|u| surface.position(u));
            (p[1] - p[0]).cross(p[2] - p[0])
        })
        .sum::<DVec3>()
        .normalize_or_zero()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_plane_is_uniform_and_a_bump_gets_smaller_radii() {
        let plane = Surface::new(&vitrine_samples::grid(16)).unwrap();
        let f = radius_factors(&plane, plane.vertex_count() as u32, 3.0);
        assert!(f.iter().all(|&x| (x - 1.0).abs() < 1e-12), "{f:?}");
        let mut bumped = vitrine_samples::grid(32);
        for p in &mut bumped.positions {
            let d2 = (p[0] - 8.0).powi(2) + (p[1] - 8.0).powi(2);
            p[2] = 3.0 * (-d2 / 8.0).exp();
        }
        let surface = Surface::new(&bumped).unwrap();
        let f = radius_factors(&surface, surface.vertex_count() as u32, 3.0);
        let at = |x: u32, y: u32| f[(y * 33 + x) as usize];
        assert!(at(8, 8) < 1.0, "on the bump: {}", at(8, 8));
        assert!(at(28, 28) > 1.0, "far from it: {}", at(28, 28));
        let (lo, hi) = f
            .iter()
            .fold((f64::MAX, 0.0f64), |(l, h), &x| (l.min(x), h.max(x)));
        assert!(hi / lo <= CAP * CAP * (1.0 + 1e-9), "{lo} – {hi}");
    }
}
