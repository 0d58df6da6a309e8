//! A static kd-tree over points for nearest-vertex queries.

use glam::DVec3;

/// Points stored as an implicit balanced tree: the median of every range is its root.
pub(crate) struct KdTree {
    points: Vec<(DVec3, u32)>,
    /// Split axis of the node stored at the same position in `points`.
    axes: Vec<u8>,
}

impl KdTree {
    pub(crate) fn new(points: impl IntoIterator<Item = DVec3>) -> Self {
        let mut points: Vec<(DVec3, u32)> = points
            .into_iter()
            .enumerate()
            .map(|(i, p)| (p, i as u32))
            .collect();
        let mut axes = vec![0u8; points.len()];
        build(&mut points, &mut axes);
        Self { points, axes }
    }

    /// The index of the point nearest to `q`, or `None` when there are none.
    /// Among equally near points, the one with the smallest `tie(index)` wins,
    /// then the smallest index: the answer never depends on the tree's layout.
    pub(crate) fn nearest(&self, q: DVec3, tie: impl Fn(u32) -> u64) -> Option<u32> {
        let mut best: Option<(f64, u64, u32)> = None;
        search(&self.points, &self.axes, q, &tie, &mut best);
        best.map(|(_, _, i)| i)
    }
}

fn build(points: &mut [(DVec3, u32)], axes: &mut [u8]) {
    if points.len() <= 1 {
        return;
    }
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for (p, _) in points.iter() {
        min = min.min(*p);
        max = max.max(*p);
    }
    let e = max - min;
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    let mid = points.len() / 2;
    points.select_nth_unstable_by(mid, |a, b| a.0[axis].total_cmp(&b.0[axis]));
    axes[mid] = axis as u8;
    let (lo, rest) = points.split_at_mut(mid);
    let (alo, arest) = axes.split_at_mut(mid);
    build(lo, alo);
    build(&mut rest[1..], &mut arest[1..]);
}

fn search(
    points: &[(DVec3, u32)],
    axes: &[u8],
    q: DVec3,
    tie: &impl Fn(u32) -> u64,
    best: &mut Option<(f64, u64, u32)>,
) {
    if points.is_empty() {
        return;
    }
    let mid = points.len() / 2;
    let (p, index) = points[mid];
    let d2 = (p - q).length_squared();
    let within = |best: &Option<(f64, u64, u32)>, d2: f64| best.is_none_or(|b| d2 <= b.0);
    if within(best, d2) {
        let candidate = (d2, tie(index), index);
        if best.is_none_or(|b| {
            candidate.0 < b.0 || (candidate.0 == b.0 && (candidate.1, candidate.2) < (b.1, b.2))
        }) {
            *best = Some(candidate);
        }
    }
    let axis = axes[mid] as usize;
    let diff = q[axis] - p[axis];
    let lower = (&points[..mid], &axes[..mid]);
    let upper = (&points[mid + 1..], &axes[mid + 1..]);
    let (near, far) = if diff < 0.0 {
        (lower, upper)
    } else {
        (upper, lower)
    };
    search(near.0, near.1, q, tie, best);
    if within(best, diff * diff) {
        search(far.0, far.1, q, tie, best);
    }
}
