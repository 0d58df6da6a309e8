//! One decimation pass (seed 004, Alg. 4): removable vertices in ascending
//! θ, ties by index (or, with quadric placement, cheapest merge first);
//! each merge freezes its survivor and the survivor's neighbours for the
//! rest of the pass, so a pass touches the surface evenly, like an
//! independent set, instead of eating one region.

use glam::DVec3;

use super::topology::{allows, Scratch};
use super::working::{Merge, WorkingMesh};
use super::{Collapse, Placement, SimplifyOptions};

/// With quadric placement, the share of a pass's candidates (the cheapest)
/// it may merge; the rest wait for the next pass.
const PASS_QUANTILE: f64 = 0.5;

pub(super) struct Pass<'a> {
    mesh: &'a mut WorkingMesh,
    collapse: Collapse,
    placement: Placement,
    threshold: f64,
    target: usize,
    frozen: Vec<bool>,
    scratch: Scratch,
    ring: Vec<u32>,
    /// The candidates' cheapest merges, when [`Pass::features_cheaper`]
    /// has priced them already (the pass then does not price them again).
    costs: Option<Vec<f64>>,
    /// With quadric placement, the dearest merge this round may make.
    cap: f64,
    /// Whether a pass whose cheaper half merged nothing may make dear
    /// merges (else it ends, and features are freed first).
    dear: bool,
}

impl<'a> Pass<'a> {
    pub fn new(
        mesh: &'a mut WorkingMesh,
        options: &SimplifyOptions,
        threshold: f64,
        target: usize,
        dear: bool,
    ) -> Self {
        let frozen = vec![false; mesh.positions.len()];
        Pass {
            mesh,
            collapse: options.collapse,
            placement: options.placement,
            threshold,
            target,
            frozen,
            scratch: Scratch::default(),
            ring: Vec::new(),
            costs: None,
            cap: f64::INFINITY,
            dear,
        }
    }

    /// Runs the pass; returns how many merges it made.
    pub fn run(mut self) -> usize {
        let mut candidates: Vec<u32> = (0..self.mesh.positions.len() as u32)
            .filter(|&v| self.mesh.removable(v, self.threshold))
            .collect();
        let order: Vec<f64> = match self.placement {
            Placement::Seed => self.mesh.theta.clone(),
            Placement::Quadric => match self.costs.take() {
                Some(cost) => cost,
                None => {
                    let mut cost = vec![f64::INFINITY; self.mesh.positions.len()];
                    for &v in &candidates {
                        cost[v as usize] = self.cheapest(v);
                    }
                    cost
                }
            },
        };
        candidates.sort_by(|&a, &b| {
            order[a as usize]
                .total_cmp(&order[b as usize])
                .then(a.cmp(&b))
        });
        // With quadric placement a pass takes only its cheaper merges: the
        // dearer ones wait for a pass where they may have become cheap or
        // where nothing cheaper is left. Without the cap a pass merges every
        // candidate the independent set allows, however dear (bunny at 10 %:
        // the ears cut through, 4.2× quadric's Hausdorff distance).
        let cap = match self.placement {
            Placement::Seed => f64::INFINITY,
            Placement::Quadric => {
                let finite = candidates
                    .iter()
                    .filter(|&&v| order[v as usize].is_finite())
                    .count();
                let at = ((finite as f64 * PASS_QUANTILE) as usize).min(finite.saturating_sub(1));
                candidates
                    .get(at)
                    .map_or(f64::INFINITY, |&v| order[v as usize])
            }
        };
        let merges = self.merge(&candidates, &order, cap);
        if merges == 0 && cap.is_finite() && self.dear {
            // Every cheap candidate was frozen or refused: the dear ones
            // may go, rather than features being freed for want of merges.
            return self.merge(&candidates, &order, f64::INFINITY);
        }
        merges
    }

    /// Merges the candidates in order, those costing at most `cap`.
    fn merge(&mut self, candidates: &[u32], order: &[f64], cap: f64) -> usize {
        self.cap = cap;
        let mut merges = 0;
        for &v in candidates {
            if order[v as usize] > cap {
                break;
            }
            let left = self.mesh.live_vertices.saturating_sub(self.target);
            if left == 0 {
                break;
            }
            if !self.usable(v) {
                continue;
            }
            let done = match self.collapse {
                Collapse::Edge => self.edge(v),
                Collapse::HalfEdge => self.half_edge(v),
                // One vertex short of the target: an edge collapse ends it exactly.
                Collapse::Triangle if left == 1 => self.edge(v),
                Collapse::Triangle => self.triangle(v),
            };
            if let Some((survivor, count)) = done {
                merges += count;
                self.freeze_around(survivor);
            }
        }
        merges
    }

    /// Whether the protected vertices (θ above τ, off the borders) would now
    /// merge more cheaply than the candidates: the median of their cheapest
    /// merges under the candidates'. Then going on without them costs the
    /// surface more than freeing some (bunny's ears were cut through while
    /// a scan's noise, all above τ, stood untouched).
    pub fn features_cheaper(&mut self) -> bool {
        let mut costs = vec![f64::INFINITY; self.mesh.positions.len()];
        let mut candidates = Vec::new();
        let mut protected = Vec::new();
        for v in 0..self.mesh.positions.len() as u32 {
            if !self.mesh.removable(v, f64::INFINITY) {
                continue;
            }
            // A protected vertex has no face whose corners may all move:
            // triangle collapses are weighed as edge merges here.
            let cost = match self.collapse {
                Collapse::Triangle => self.cheapest_edge(v),
                _ => self.cheapest(v),
            };
            let candidate = self.mesh.removable(v, self.threshold);
            if candidate {
                costs[v as usize] = cost;
            }
            if !cost.is_finite() {
                continue;
            }
            if candidate {
                candidates.push(cost);
            } else {
                protected.push(cost);
            }
        }
        if self.collapse != Collapse::Triangle {
            self.costs = Some(costs);
        }
        match (median(&mut protected), median(&mut candidates)) {
            (Some(p), Some(c)) => p < c,
            _ => false,
        }
    }

    /// The mesh the pass works on.
    pub fn mesh(&self) -> &WorkingMesh {
        self.mesh
    }

    /// Live, unfrozen and removable (a merge may have raised its θ).
    fn usable(&self, v: u32) -> bool {
        !self.frozen[v as usize] && self.mesh.removable(v, self.threshold)
    }

    /// Neighbours of `v` passing `keep`, shortest edge first (ties by index).
    fn partners(&mut self, v: u32, keep: impl Fn(&Self, u32) -> bool) -> Vec<u32> {
        self.mesh.neighbours(v, &mut self.ring);
        let mut out: Vec<u32> = self
            .ring
            .iter()
            .copied()
            .filter(|&w| keep(self, w))
            .collect();
        let p = self.mesh.point(v);
        let length = |w: u32| p.distance_squared(self.mesh.point(w));
        out.sort_by(|&a, &b| length(a).total_cmp(&length(b)).then(a.cmp(&b)));
        out
    }

    /// With quadric placement, the cost of `v`'s cheapest merge this pass
    /// could make (the order of the candidates).
    fn cheapest(&mut self, v: u32) -> f64 {
        match self.collapse {
            Collapse::Edge => self.cheapest_edge(v),
            Collapse::HalfEdge => {
                let merges = self.merges_into_neighbours(v);
                merges.first().map_or(f64::INFINITY, |m| self.cost(m))
            }
            Collapse::Triangle => self
                .collapsible_faces(v)
                .first()
                .map_or(f64::INFINITY, |c| c.0),
        }
    }

    /// The cost of `v`'s cheapest quadric edge merge.
    fn cheapest_edge(&mut self, v: u32) -> f64 {
        let merges = self.quadric_edges(v);
        merges.first().map_or(f64::INFINITY, |m| self.cost(m))
    }

    /// The error of a merge's placement under the two quadrics it sums.
    fn cost(&self, m: &Merge) -> f64 {
        let q = self.mesh.quadric(m.keep) + self.mesh.quadric(m.gone);
        q.error(DVec3::from(m.to.map(f64::from)))
    }

    /// Quadric edge merges of `v`, cheapest first: with a removable
    /// neighbour both go to the best point of the edge; a neighbour that
    /// may not move (border, feature) takes `v` where it stands.
    fn quadric_edges(&mut self, v: u32) -> Vec<Merge> {
        let partners = self.partners(v, |s, w| !s.frozen[w as usize]);
        let mut merges: Vec<(f64, Merge)> = partners
            .iter()
            .map(|&w| {
                let m = if self.usable(w) {
                    self.quadric_point(w, v)
                } else {
                    self.stay(w, v)
                };
                (self.cost(&m), m)
            })
            .collect();
        merges.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.keep.cmp(&b.1.keep)));
        merges.into_iter().map(|(_, m)| m).collect()
    }

    /// `v` into each unfrozen neighbour, which stays where it is: nearest
    /// first, or cheapest first with quadric placement.
    fn merges_into_neighbours(&mut self, v: u32) -> Vec<Merge> {
        let partners = self.partners(v, |s, w| !s.frozen[w as usize]);
        let mut merges: Vec<Merge> = partners.iter().map(|&w| self.stay(w, v)).collect();
        if self.placement == Placement::Quadric {
            let mut costed: Vec<(f64, Merge)> =
                merges.into_iter().map(|m| (self.cost(&m), m)).collect();
            costed.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.keep.cmp(&b.1.keep)));
            merges = costed.into_iter().map(|(_, m)| m).collect();
        }
        merges
    }

    /// `gone` into `keep`, which does not move.
    fn stay(&self, keep: u32, gone: u32) -> Merge {
        Merge {
            keep,
            gone,
            to: self.mesh.positions[keep as usize],
            colour: self.mesh.colour(keep),
        }
    }

    /// Both to the least-error point of their edge; colour averaged.
    fn quadric_point(&self, keep: u32, gone: u32) -> Merge {
        let q = self.mesh.quadric(keep) + self.mesh.quadric(gone);
        let to = q.best_on(self.mesh.point(keep), self.mesh.point(gone));
        Merge {
            to: to.as_vec3().to_array(),
            ..self.midpoint(keep, gone)
        }
    }

    /// Tries each merge in turn; applies the first the checks allow and
    /// returns its survivor. With quadric placement, a merge dearer than
    /// the round's cap is not made: a vertex whose cheap merges are refused
    /// (they would fold a face) waits rather than taking a dear one (a
    /// plate's crease vertex went across the plate's edge, 8 % of its
    /// diagonal, where quadric simplification loses nothing).
    fn first_allowed(&mut self, merges: impl IntoIterator<Item = Merge>) -> Option<u32> {
        let capped = self.placement == Placement::Quadric && self.cap.is_finite();
        for m in merges {
            if capped && self.cost(&m) > self.cap {
                return None;
            }
            if allows(self.mesh, &m, &mut self.scratch) {
                self.mesh.apply(&m);
                return Some(m.keep);
            }
        }
        None
    }

    /// Both ends to the midpoint (−1 vertex, −2 faces); both must be
    /// removable. With quadric placement: see [`Self::quadric_edges`].
    fn edge(&mut self, v: u32) -> Option<(u32, usize)> {
        let merges = match self.placement {
            Placement::Seed => {
                let partners = self.partners(v, |s, w| s.usable(w));
                partners.iter().map(|&w| self.midpoint(v, w)).collect()
            }
            Placement::Quadric => self.quadric_edges(v),
        };
        Some((self.first_allowed(merges)?, 1))
    }

    /// `v` into a neighbour, which stays where it is (it may be a border
    /// or feature vertex: it does not move).
    fn half_edge(&mut self, v: u32) -> Option<(u32, usize)> {
        let merges = self.merges_into_neighbours(v);
        Some((self.first_allowed(merges)?, 1))
    }

    /// A face's three corners to one point (−2 vertices, −4 faces), as two
    /// checked merges: with the seed's placement the smallest face first,
    /// to its centroid; with quadric placement the cheapest face first, to
    /// the point its summed quadric prefers, and none dearer than the
    /// pass's cap (a collapse that crosses a crease costs what it cuts).
    /// When the second merge is refused the first stands on its own
    /// (−1 vertex).
    fn triangle(&mut self, v: u32) -> Option<(u32, usize)> {
        for (cost, f, to) in self.collapsible_faces(v) {
            if cost > self.cap {
                return None;
            }
            let t = self.mesh.triangles[f as usize];
            let others: Vec<u32> = t.iter().copied().filter(|&w| w != v).collect();
            let merge = |gone| Merge {
                keep: v,
                gone,
                to,
                colour: self.mean_colour(&t),
            };
            let (first, second) = (merge(others[0]), merge(others[1]));
            if !self.allowed(&first) {
                continue;
            }
            self.mesh.apply(&first);
            let second = self.allowed(&second) && {
                self.mesh.apply(&second);
                true
            };
            return Some((v, 1 + usize::from(second)));
        }
        None
    }

    /// The faces around `v` whose corners may all move, each with the cost
    /// of collapsing it (its area with the seed's placement, which takes the
    /// smallest first; the summed quadric's error at the chosen point with
    /// quadric placement), cheapest first, ties by face index.
    fn collapsible_faces(&self, v: u32) -> Vec<(f64, u32, [f32; 3])> {
        let mut faces: Vec<(f64, u32, [f32; 3])> = self.mesh.faces_of[v as usize]
            .iter()
            .filter(|&&f| {
                let t = self.mesh.triangles[f as usize];
                t.iter().all(|&w| self.usable(w))
            })
            .map(|&f| {
                let t = self.mesh.triangles[f as usize];
                let (to, cost) = self.triangle_point(&t);
                let order = match self.placement {
                    Placement::Seed => self.area(f),
                    Placement::Quadric => cost,
                };
                (order, f, to)
            })
            .collect();
        faces.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        faces
    }

    /// Whether the checks allow `m` (the link condition, no flips).
    fn allowed(&mut self, m: &Merge) -> bool {
        allows(self.mesh, m, &mut self.scratch)
    }

    fn mean_colour(&self, t: &[u32; 3]) -> Option<[f32; 3]> {
        self.mesh
            .colours
            .as_ref()
            .map(|c| [0, 1, 2].map(|k| t.iter().map(|&w| c[w as usize][k]).sum::<f32>() / 3.0))
    }

    fn midpoint(&self, a: u32, b: u32) -> Merge {
        let to = ((self.mesh.point(a) + self.mesh.point(b)) * 0.5)
            .as_vec3()
            .to_array();
        let colour = self
            .mesh
            .colour(a)
            .zip(self.mesh.colour(b))
            .map(|(p, q)| [0, 1, 2].map(|k| (p[k] + q[k]) / 2.0));
        Merge {
            keep: a,
            gone: b,
            to,
            colour,
        }
    }

    /// Where a triangle collapse goes, and the summed quadric's error there:
    /// the seed's centroid; or with quadric placement the quadric's minimum
    /// when it lies near the face, else the best of the centroid, the
    /// corners and the edges' midpoints (the free minimum of a near-flat or
    /// crease patch can lie far off and fold a face: tests/simplifier.rs,
    /// the genus-3 plate).
    fn triangle_point(&self, t: &[u32; 3]) -> ([f32; 3], f64) {
        let p = t.map(|w| self.mesh.point(w));
        let centroid = (p[0] + p[1] + p[2]) / 3.0;
        let q = t
            .iter()
            .map(|&w| self.mesh.quadric(w))
            .fold(super::quadric::Quadric::default(), |a, b| a + b);
        let best = match self.placement {
            Placement::Seed => centroid,
            Placement::Quadric => {
                let reach = (0..3)
                    .map(|k| p[k].distance(p[(k + 1) % 3]))
                    .fold(0.0, f64::max);
                q.minimum()
                    .filter(|x| x.distance(centroid) <= reach)
                    .unwrap_or_else(|| {
                        [centroid, p[0], p[1], p[2]]
                            .into_iter()
                            .chain((0..3).map(|k| (p[k] + p[(k + 1) % 3]) * 0.5))
                            .min_by(|a, b| q.error(*a).total_cmp(&q.error(*b)))
                            .unwrap_or(centroid)
                    })
            }
        };
        (best.as_vec3().to_array(), q.error(best))
    }

    fn area(&self, f: u32) -> f64 {
        let p = self.mesh.triangles[f as usize].map(|w| self.mesh.point(w));
        super::topology::normal(&p).length()
    }

    /// Freezes a merge's survivor and its ring for the rest of the pass.
    fn freeze_around(&mut self, survivor: u32) {
        self.frozen[survivor as usize] = true;
        self.mesh.neighbours(survivor, &mut self.ring);
        for &w in &self.ring {
            self.frozen[w as usize] = true;
        }
    }
}

/// The middle value (the upper one of an even count); `None` when empty.
fn median(values: &mut [f64]) -> Option<f64> {
    if values.is_empty() {
        return None;
    }
    let middle = values.len() / 2;
    let (_, m, _) = values.select_nth_unstable_by(middle, f64::total_cmp);
    Some(*m)
}
