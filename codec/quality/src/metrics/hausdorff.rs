//! Metro-style Hausdorff distance between two triangle surfaces.

use super::bvh::TriangleBvh;
use super::parallel_map;
use super::sampling::{sample_surface, triangle_corners, used_vertices};
use glam::DVec3;
use vitrine_codec::IndexedMesh;

/// Seeds of the two sampling passes: fixed, so every run gives the same numbers.
const SEED_A: u64 = 0x5eed_f00a;
const SEED_B: u64 = 0x5eed_f00b;
/// Query points per parallel work item; fixed so sums do not depend on the thread count.
const CHUNK: usize = 4096;

/// Distances between two surfaces, in the meshes' units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hausdorff {
    /// One-sided Hausdorff distance: the largest distance from a point of `a` to the surface of `b`.
    pub a_to_b: f64,
    /// The largest distance from a point of `b` to the surface of `a`.
    pub b_to_a: f64,
    /// `max(a_to_b, b_to_a)`: the symmetric Hausdorff distance.
    pub symmetric: f64,
    /// Mean distance from `a` to `b` over the area-uniform samples (an area-weighted mean).
    pub mean_a_to_b: f64,
    /// Mean distance from `b` to `a` over the area-uniform samples.
    pub mean_b_to_a: f64,
    /// Bounding-box diagonal of `a`, the usual normaliser (Metro reports `symmetric / diagonal`).
    pub diagonal: f64,
}

impl Hausdorff {
    /// The symmetric distance as a fraction of `a`'s bounding-box diagonal.
    pub fn relative(&self) -> f64 {
        if self.diagonal > 0.0 {
            self.symmetric / self.diagonal
        } else {
            self.symmetric
        }
    }
}

/// The symmetric Hausdorff distance between the surfaces of `a` and `b`, as in
/// Metro (Cignoni, Rocchini, Scopigno 1998).
///
/// Each direction measures, from a set of points on one surface, the distance to
/// the nearest point of any triangle of the other (exact point–triangle
/// distances, found through a bounding volume hierarchy). The points are
/// `samples_per_mesh` samples drawn uniformly by area with a fixed seed, plus
/// every vertex a triangle uses. Maxima are taken over all of them; the means
/// over the area samples only (over the vertices when `samples_per_mesh` is 0).
///
/// A mesh without triangles has no surface to measure to: the distance towards
/// it is infinite, unless the other mesh has no points either (then 0).
/// Triangles with an out-of-range index are ignored. Runs on every core.
pub fn hausdorff(a: &IndexedMesh, b: &IndexedMesh, samples_per_mesh: usize) -> Hausdorff {
    HausdorffReference::new(a, samples_per_mesh).distance_to(b)
}

/// The `a` side of [`hausdorff`] prepared once (its samples, its triangle
/// hierarchy, its diagonal), to measure many meshes — every level of a
/// stream — against the same original.
pub struct HausdorffReference {
    points: (Vec<DVec3>, Vec<DVec3>),
    bvh: TriangleBvh,
    samples_per_mesh: usize,
    diagonal: f64,
}

impl HausdorffReference {
    pub fn new(a: &IndexedMesh, samples_per_mesh: usize) -> Self {
        let ta = triangle_corners(a);
        let points = (
            sample_surface(&ta, samples_per_mesh, SEED_A),
            used_vertices(a),
        );
        let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for p in &a.positions {
            let p = DVec3::from(p.map(f64::from));
            min = min.min(p);
            max = max.max(p);
        }
        HausdorffReference {
            points,
            bvh: TriangleBvh::new(ta),
            samples_per_mesh,
            diagonal: if a.positions.is_empty() {
                0.0
            } else {
                (max - min).length()
            },
        }
    }

    /// [`hausdorff`]`(a, b, samples_per_mesh)` for the `a` this was made from.
    pub fn distance_to(&self, b: &IndexedMesh) -> Hausdorff {
        let tb = triangle_corners(b);
        let points_b = (
            sample_surface(&tb, self.samples_per_mesh, SEED_B),
            used_vertices(b),
        );
        let bvh_b = TriangleBvh::new(tb);
        let (a_to_b, mean_a_to_b) = one_sided(&self.points, &bvh_b);
        let (b_to_a, mean_b_to_a) = one_sided(&points_b, &self.bvh);
        Hausdorff {
            a_to_b,
            b_to_a,
            symmetric: a_to_b.max(b_to_a),
            mean_a_to_b,
            mean_b_to_a,
            diagonal: self.diagonal,
        }
    }
}

/// The distance from each point to the surface of `mesh` (its triangles):
/// how far a level strayed from chosen points of the original, such as its
/// feature vertices.
pub fn distances_to_surface(points: &[DVec3], mesh: &IndexedMesh) -> Vec<f64> {
    let surface = TriangleBvh::new(triangle_corners(mesh));
    let chunks = parallel_map(points.len().div_ceil(CHUNK), |chunk| {
        let end = ((chunk + 1) * CHUNK).min(points.len());
        points[chunk * CHUNK..end]
            .iter()
            .map(|&p| surface.distance_squared(p).sqrt())
            .collect::<Vec<f64>>()
    });
    chunks.concat()
}

/// (max, mean) distance from the points to the surface in `to`.
fn one_sided((samples, vertices): &(Vec<DVec3>, Vec<DVec3>), to: &TriangleBvh) -> (f64, f64) {
    let points: Vec<DVec3> = samples.iter().chain(vertices).copied().collect();
    if points.is_empty() {
        return (0.0, 0.0);
    }
    let averaged = if samples.is_empty() {
        points.len()
    } else {
        samples.len()
    };
    let chunks = parallel_map(points.len().div_ceil(CHUNK), |chunk| {
        let start = chunk * CHUNK;
        let end = (start + CHUNK).min(points.len());
        let (mut max, mut sum) = (0.0f64, 0.0f64);
        for (i, p) in points[start..end].iter().enumerate() {
            let d = to.distance_squared(*p).sqrt();
            max = max.max(d);
            if start + i < averaged {
                sum += d;
            }
        }
        (max, sum)
    });
    let max = chunks.iter().fold(0.0f64, |m, c| m.max(c.0));
    let sum: f64 = chunks.iter().map(|c| c.1).sum();
    (max, sum / averaged as f64)
}
