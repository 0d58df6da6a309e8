//! The disc cover (seed 001 §3.1, Alg. 2): a candidate not yet inside a
//! disc becomes a centre, and its disc (vertices nearer than r) grows by
//! its own bounded propagation. The centres form an r-net. Candidates come
//! in one of the seed's three orders (§3.1.1).

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::str::FromStr;

use vitrine_codec::{Error, Result};
use vitrine_geodesic::Propagation;

/// In which order candidates become centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Order {
    /// Vertex order (Peixoto 2002).
    Incremental,
    /// The vertex farthest from every centre so far, next: the fewest
    /// sites for a radius (seed §5).
    #[default]
    Farthest,
    /// Largest |K| first (Gaussian curvature by mixed area): centres on
    /// the tips and saddles.
    Curvature,
}

impl FromStr for Order {
    type Err = Error;

    /// `incremental`, `farthest` or `curvature`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "incremental" => Ok(Order::Incremental),
            "farthest" => Ok(Order::Farthest),
            "curvature" => Ok(Order::Curvature),
            _ => Err(Error::Parameter(format!(
                "order must be incremental, farthest or curvature, got {s:?}"
            ))),
        }
    }
}

/// Centres of discs of `radius` (times the centre's factor, if given) over
/// `candidates`, taken in their order; `covered` marks the vertices
/// already inside a disc and is updated. `scratch` is an empty
/// propagation, left empty.
pub(super) fn greedy_discs(
    scratch: &mut Propagation<'_>,
    candidates: &[u32],
    radius: f64,
    factors: Option<&[f64]>,
    covered: &mut [bool],
) -> Vec<u32> {
    let mut centres = Vec::new();
    for &c in candidates {
        if covered[c as usize] {
            continue;
        }
        centres.push(c);
        covered[c as usize] = true;
        let radius = radius * factors.map_or(1.0, |f| f[c as usize]);
        scratch.seed(c, 0, 0.0);
        scratch.run(radius);
        for &v in scratch.touched() {
            if scratch.distance(v) < radius {
                covered[v as usize] = true;
            }
        }
        scratch.clear();
    }
    centres
}

/// Marks the vertices within `radius` (times each centre's factor, if
/// given) of `centres` as `covered`. `scratch` is an empty propagation,
/// left empty.
pub(super) fn mark_discs(
    scratch: &mut Propagation<'_>,
    centres: &[u32],
    radius: f64,
    factors: Option<&[f64]>,
    covered: &mut [bool],
) {
    if let Some(f) = factors {
        for &c in centres {
            mark_discs(scratch, &[c], radius * f[c as usize], None, covered);
        }
        return;
    }
    for &c in centres {
        scratch.seed(c, 0, 0.0);
    }
    scratch.run(radius);
    for &v in scratch.touched() {
        if scratch.distance(v) < radius {
            covered[v as usize] = true;
        }
    }
    scratch.clear();
}

/// Farthest-point sampling on the diagram's own front: the vertex farthest
/// from all sites becomes the next one (a vertex no site reaches, in a
/// component of its own, first), until every vertex is within `radius`.
/// With `factors`, distances are over each vertex's own factor: the vertex
/// farthest for its radius comes next, until every vertex is within
/// `radius` × its factor. Sites get labels from `first_label` on; the
/// front ends up final.
pub(super) fn farthest_points(
    front: &mut Propagation<'_>,
    candidates: &[u32],
    radius: f64,
    factors: Option<&[f64]>,
    first_label: u32,
) -> Vec<u32> {
    front.track_changes(true);
    front.run(f64::INFINITY);
    let scaled = |front: &Propagation<'_>, v: u32| {
        front.distance(v) / factors.map_or(1.0, |f| f[v as usize])
    };
    // Largest distance first, then lowest vertex.
    let mut heap: BinaryHeap<(u64, Reverse<u32>)> = candidates
        .iter()
        .map(|&v| (ordered(scaled(front, v)), Reverse(v)))
        .collect();
    front.take_changed();
    let mut candidate = vec![false; front.surface().vertex_count()];
    for &v in candidates {
        candidate[v as usize] = true;
    }
    let mut centres = Vec::new();
    while let Some((k, Reverse(v))) = heap.pop() {
        let d = scaled(front, v);
        if k != ordered(d) {
            continue; // stale: v came closer to a newer site
        }
        if d < radius {
            break;
        }
        front.seed(v, first_label + centres.len() as u32, 0.0);
        centres.push(v);
        front.run(f64::INFINITY);
        for w in front.take_changed() {
            if candidate[w as usize] {
                heap.push((ordered(scaled(front, w)), Reverse(w)));
            }
        }
    }
    front.track_changes(false);
    centres
}

/// A non-negative f64 (or +∞) as an integer of the same order.
fn ordered(d: f64) -> u64 {
    d.to_bits()
}
