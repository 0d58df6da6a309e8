//! One front, many sources: each vertex holds its distance to the nearest
//! source and that source's label. Sources can be added after a run; the
//! next run then re-opens only the vertices the new sources bring closer
//! (the simplifier inserts sites this way, SEEDS.md 001 "slow refinement").

use std::cmp::Reverse;
use std::collections::BinaryHeap;
use std::str::FromStr;

use vitrine_codec::{Error, Result};

use crate::march;
use crate::surface::{Surface, NONE};

/// How distance crosses the surface.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Method {
    /// Shortest paths along edges: exact on the edge graph, longer than the
    /// surface geodesic by up to ~8 % on a regular grid.
    Dijkstra,
    /// Fast marching across faces, with obtuse corners unfolded: never
    /// longer than Dijkstra, exact on a plane.
    #[default]
    FastMarching,
}

impl FromStr for Method {
    type Err = Error;

    /// `dijkstra` or `fmm`.
    fn from_str(s: &str) -> Result<Self> {
        match s.trim() {
            "dijkstra" => Ok(Method::Dijkstra),
            "fmm" | "fast-marching" => Ok(Method::FastMarching),
            _ => Err(Error::Parameter(format!(
                "distance must be dijkstra or fmm, got {s:?}"
            ))),
        }
    }
}

/// A label meaning "no source reached here".
pub const UNREACHED: u32 = NONE;

/// A distance in the heap: f64 ordered by `total_cmp` (never NaN here).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key(f64);

impl Eq for Key {}

impl PartialOrd for Key {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Key {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0)
    }
}

/// Distances and labels from any number of sources, over one surface.
pub struct Propagation<'s> {
    surface: &'s Surface,
    method: Method,
    distance: Vec<f64>,
    label: Vec<u32>,
    /// Whether the vertex was taken from the heap at its current distance:
    /// only such vertices feed the fast-marching update.
    settled: Vec<bool>,
    heap: BinaryHeap<Reverse<(Key, u32)>>,
    /// Vertices given a distance since the last [`Propagation::clear`].
    touched: Vec<u32>,
    /// Vertices brought closer, when asked for ([`Propagation::track_changes`]).
    changed: Option<Vec<u32>>,
}

impl<'s> Propagation<'s> {
    pub fn new(surface: &'s Surface, method: Method) -> Self {
        let n = surface.vertex_count();
        Propagation {
            surface,
            method,
            distance: vec![f64::INFINITY; n],
            label: vec![UNREACHED; n],
            settled: vec![false; n],
            heap: BinaryHeap::new(),
            touched: Vec::new(),
            changed: None,
        }
    }

    /// Whether to log every vertex brought closer from now on, for
    /// [`Propagation::take_changed`] (the farthest-point cover reads it).
    pub fn track_changes(&mut self, on: bool) {
        self.changed = on.then(Vec::new);
    }

    /// The vertices brought closer since the last call (with repeats).
    pub fn take_changed(&mut self) -> Vec<u32> {
        self.changed
            .as_mut()
            .map(std::mem::take)
            .unwrap_or_default()
    }

    pub fn surface(&self) -> &'s Surface {
        self.surface
    }

    pub fn distances(&self) -> &[f64] {
        &self.distance
    }

    pub fn labels(&self) -> &[u32] {
        &self.label
    }

    pub fn distance(&self, vertex: u32) -> f64 {
        self.distance[vertex as usize]
    }

    pub fn label(&self, vertex: u32) -> u32 {
        self.label[vertex as usize]
    }

    /// The vertices given a distance since the last clear (with repeats).
    pub fn touched(&self) -> &[u32] {
        &self.touched
    }

    /// Starts a source at `vertex`, `distance` away from it, unless the
    /// vertex is already as close to another source or blocked.
    pub fn seed(&mut self, vertex: u32, label: u32, distance: f64) {
        if !self.surface.is_blocked(vertex) {
            self.offer(vertex, label, distance);
        }
    }

    /// Runs the front until every vertex within `limit` is final (use
    /// `f64::INFINITY` for all). Vertices beyond keep tentative distances.
    pub fn run(&mut self, limit: f64) {
        while let Some(&Reverse((Key(d), v))) = self.heap.peek() {
            if d > limit {
                break;
            }
            self.heap.pop();
            if d > self.distance[v as usize] || self.settled[v as usize] {
                continue; // stale: the vertex came closer since
            }
            self.settled[v as usize] = true;
            self.relax_edges(v);
            if self.method == Method::FastMarching {
                self.relax_faces(v);
            }
        }
    }

    /// Forgets every distance (cost proportional to what was touched).
    pub fn clear(&mut self) {
        for &v in &self.touched {
            self.distance[v as usize] = f64::INFINITY;
            self.label[v as usize] = UNREACHED;
            self.settled[v as usize] = false;
        }
        self.touched.clear();
        self.heap.clear();
    }

    fn offer(&mut self, v: u32, label: u32, d: f64) {
        let i = v as usize;
        if d < self.distance[i] {
            if self.distance[i] == f64::INFINITY {
                self.touched.push(v);
            }
            self.distance[i] = d;
            self.label[i] = label;
            self.settled[i] = false;
            self.heap.push(Reverse((Key(d), v)));
            if let Some(changed) = &mut self.changed {
                changed.push(v);
            }
        }
    }

    fn relax_edges(&mut self, v: u32) {
        let surface = self.surface;
        let (d, label) = (self.distance[v as usize], self.label[v as usize]);
        let (ring, lengths) = surface.neighbours(v);
        for (&w, &l) in ring.iter().zip(lengths) {
            if !surface.is_blocked(w) {
                self.offer(w, label, d + l);
            }
        }
    }

    /// For every face around the newly settled `v`, updates each other
    /// corner from v and the third corner when that one is settled too
    /// and reached from the same source (distances from two sources form
    /// no single front; across a cell border the edge update stands).
    fn relax_faces(&mut self, v: u32) {
        let surface = self.surface;
        let label = self.label[v as usize];
        for &f in surface.faces_of(v) {
            let t = surface.triangles()[f as usize];
            let k = t.iter().position(|&w| w == v).unwrap_or(0);
            for (b, c) in [
                (t[(k + 1) % 3], t[(k + 2) % 3]),
                (t[(k + 2) % 3], t[(k + 1) % 3]),
            ] {
                let (bi, ci) = (b as usize, c as usize);
                if !self.settled[bi] || self.label[bi] != label {
                    continue;
                }
                if surface.is_blocked(c) {
                    continue;
                }
                let known = |w: u32| {
                    let i = w as usize;
                    (self.settled[i] && self.label[i] == label).then_some(self.distance[i])
                };
                // A settled C is re-opened too: on a curved front the
                // faces C's shortest path crosses can settle after C did
                // (its edge update arrives first). Only real gains count.
                if let Some(d) = march::update(surface, f, v, b, c, &known) {
                    if d < self.distance[ci] * (1.0 - 1e-12) {
                        self.offer(c, label, d);
                    }
                }
            }
        }
    }
}
