//! A deterministic random number generator and area-uniform surface sampling.

use glam::DVec3;
use vitrine_codec::IndexedMesh;

/// SplitMix64 (Steele, Lea, Flood 2014): tiny, fast and good enough for sampling.
pub(crate) struct SplitMix64(u64);

impl SplitMix64 {
    pub(crate) fn new(seed: u64) -> Self {
        Self(seed)
    }

    pub(crate) fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub(crate) fn next_f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// The corners of every triangle whose indices are in range, in f64.
pub(crate) fn triangle_corners(mesh: &IndexedMesh) -> Vec<[DVec3; 3]> {
    let n = mesh.positions.len();
    mesh.triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < n))
        .map(|t| t.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from))))
        .collect()
}

/// Every vertex some in-range triangle uses, in index order.
pub(crate) fn used_vertices(mesh: &IndexedMesh) -> Vec<DVec3> {
    let n = mesh.positions.len();
    let mut used = vec![false; n];
    for t in &mesh.triangles {
        if t.iter().all(|&v| (v as usize) < n) {
            for &v in t {
                used[v as usize] = true;
            }
        }
    }
    mesh.positions
        .iter()
        .zip(used)
        .filter(|(_, u)| *u)
        .map(|(p, _)| DVec3::from(p.map(f64::from)))
        .collect()
}

/// `count` points distributed uniformly by area over the triangles (none if the
/// surface has no area). The same `seed` gives the same points.
pub(crate) fn sample_surface(triangles: &[[DVec3; 3]], count: usize, seed: u64) -> Vec<DVec3> {
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0;
    for [a, b, c] in triangles {
        total += (*b - *a).cross(*c - *a).length() * 0.5;
        cumulative.push(total);
    }
    if total <= 0.0 || !total.is_finite() {
        return Vec::new();
    }
    let mut rng = SplitMix64::new(seed);
    (0..count)
        .map(|_| {
            let target = rng.next_f64() * total;
            let t = cumulative
                .partition_point(|&c| c <= target)
                .min(triangles.len() - 1);
            let [a, b, c] = triangles[t];
            // Uniform on the triangle: the square-root warp of the unit square.
            let r1 = rng.next_f64().sqrt();
            let r2 = rng.next_f64();
            a * (1.0 - r1) + b * (r1 * (1.0 - r2)) + c * (r1 * r2)
        })
        .collect()
}
