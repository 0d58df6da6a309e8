//! A bounding volume hierarchy over triangles for point-to-surface distance queries.

use glam::DVec3;

const LEAF_SIZE: usize = 4;

struct Node {
    min: DVec3,
    max: DVec3,
    /// Leaf: first triangle. Inner node: index of the left child (the right one follows it).
    first: u32,
    /// Triangles in a leaf; 0 for an inner node.
    count: u32,
}

/// Triangles in median-split order under a binary tree of axis-aligned boxes.
pub(crate) struct TriangleBvh {
    nodes: Vec<Node>,
    triangles: Vec<[DVec3; 3]>,
}

impl TriangleBvh {
    pub(crate) fn new(mut triangles: Vec<[DVec3; 3]>) -> Self {
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF_SIZE + 1);
        if !triangles.is_empty() {
            nodes.push(Node {
                min: DVec3::ZERO,
                max: DVec3::ZERO,
                first: 0,
                count: 0,
            });
            build(&mut nodes, 0, &mut triangles, 0);
        }
        Self { nodes, triangles }
    }

    /// Squared distance from `p` to the nearest point of any triangle
    /// (infinite when there are none).
    pub(crate) fn distance_squared(&self, p: DVec3) -> f64 {
        let mut best = f64::INFINITY;
        if self.nodes.is_empty() {
            return best;
        }
        let mut stack: Vec<(u32, f64)> = Vec::with_capacity(64);
        stack.push((0, 0.0));
        while let Some((index, box_distance)) = stack.pop() {
            if box_distance >= best {
                continue;
            }
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                let first = node.first as usize;
                for t in &self.triangles[first..first + node.count as usize] {
                    best = best.min(point_triangle_distance_squared(p, t));
                }
                continue;
            }
            let (l, r) = (node.first, node.first + 1);
            let dl = box_distance_squared(p, &self.nodes[l as usize]);
            let dr = box_distance_squared(p, &self.nodes[r as usize]);
            // Nearer child last, so it is popped first.
            if dl < dr {
                stack.push((r, dr));
                stack.push((l, dl));
            } else {
                stack.push((l, dl));
                stack.push((r, dr));
            }
        }
        best
    }
}

fn build(nodes: &mut Vec<Node>, index: usize, triangles: &mut [[DVec3; 3]], offset: usize) {
    let (mut min, mut max) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    let (mut cmin, mut cmax) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for t in triangles.iter() {
        for p in t {
            min = min.min(*p);
            max = max.max(*p);
        }
        let c = centroid(t);
        cmin = cmin.min(c);
        cmax = cmax.max(c);
    }
    nodes[index].min = min;
    nodes[index].max = max;
    if triangles.len() <= LEAF_SIZE {
        nodes[index].first = offset as u32;
        nodes[index].count = triangles.len() as u32;
        return;
    }
    let extent = cmax - cmin;
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = triangles.len() / 2;
    triangles.select_nth_unstable_by(mid, |a, b| centroid(a)[axis].total_cmp(&centroid(b)[axis]));
    let left = nodes.len();
    for _ in 0..2 {
        nodes.push(Node {
            min: DVec3::ZERO,
            max: DVec3::ZERO,
            first: 0,
            count: 0,
        });
    }
    nodes[index].first = left as u32;
    let (lo, hi) = triangles.split_at_mut(mid);
    build(nodes, left, lo, offset);
    build(nodes, left + 1, hi, offset + mid);
}

fn centroid(t: &[DVec3; 3]) -> DVec3 {
    (t[0] + t[1] + t[2]) / 3.0
}

fn box_distance_squared(p: DVec3, node: &Node) -> f64 {
    let d = (node.min - p).max(p - node.max).max(DVec3::ZERO);
    d.length_squared()
}

/// Squared distance from `p` to triangle `t` (Ericson, Real-Time Collision
/// Detection, §5.1.5), with degenerate triangles treated as their edges.
pub(crate) fn point_triangle_distance_squared(p: DVec3, t: &[DVec3; 3]) -> f64 {
    let [a, b, c] = *t;
    let ab = b - a;
    let ac = c - a;
    let normal = ab.cross(ac);
    if normal.length_squared() <= 1e-24 * ab.length_squared() * ac.length_squared()
        || normal.length_squared() == 0.0
    {
        return segment_distance_squared(p, a, b)
            .min(segment_distance_squared(p, b, c))
            .min(segment_distance_squared(p, c, a));
    }
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return ap.length_squared();
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return bp.length_squared();
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (p - (a + ab * v)).length_squared();
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return cp.length_squared();
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (p - (a + ac * w)).length_squared();
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (p - (b + (c - b) * w)).length_squared();
    }
    // Inside the face: the distance to the plane.
    let n = normal.dot(ap);
    n * n / normal.length_squared()
}

fn segment_distance_squared(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + ab * s)).length_squared()
}
