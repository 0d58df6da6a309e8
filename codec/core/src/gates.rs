//! The gate traversal of one conquest as the decoder sees it (AD01 §3):
//! the coarse mesh, a FIFO of gates, one code per gate.
//!
//! The decoder runs it with codes read from the stream. The encoder decides
//! what to remove on the fine mesh, then replays its decisions through this
//! same traversal on the coarse mesh it produced, coding each one there. So
//! every code can be modelled on what the decoder knows at that gate, and
//! both sides share one implementation of it:
//! - the tags of the gate's vertices and of its front vertex (as AD01);
//! - which patch valences still fit around the gate (a patch needs its
//!   `valence − 2` faces unconquered and inside the mesh): those that do not
//!   are excluded from the code, and how many fit is a context;
//! - the coarse valence of the front vertex, and the coarse valence classes
//!   of the gate's vertices.
//!
//! Every pass's models start from priors trained on a scan
//! ([`crate::priors`]), which is what makes this many contexts pay. On the
//! shared scans this takes connectivity from 4.5 (AD01's tags alone) to
//! 3.7 bits/vertex at no cost in geometry (docs/bench-log/).

use std::collections::VecDeque;

use crate::contexts::{
    CLEANING_CONTEXTS, DECIMATION_CONTEXTS, DECIMATION_SYMBOLS, FIT_CLASSES, FRONT_VALENCES,
    VALENCE_CLASSES,
};
use crate::entropy::{BitModel, FrequencyModel};
use crate::halfedge::{face, next, prev, Connectivity, NONE};
use crate::patch::{growth, pattern, Pattern, Tag, MAX_VALENCE, MIN_VALENCE};
use crate::predict::gate_context;
use crate::priors;
use crate::{Error, Result};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PassKind {
    /// Removes free vertices of valence 3–6.
    Decimating,
    /// Removes the valence-3 vertices decimation leaves behind.
    Cleaning,
}

/// Where a gate's code comes from: the stream (decoder) or the encoder's
/// recorded decisions, coded as they are replayed.
pub(crate) trait GateCodes {
    /// A decimating gate: 0 for a null patch or `valence − 2`, a symbol
    /// below `limit` (≥ 2: null patch or valence 3 are always possible).
    fn decimation(
        &mut self,
        model: &mut FrequencyModel<DECIMATION_SYMBOLS>,
        limit: usize,
    ) -> Result<usize>;
    /// A cleaning gate: whether a valence-3 vertex was removed there.
    fn cleaning(&mut self, model: &mut BitModel) -> Result<bool>;
}

/// The mesh a traversal walks, and what becomes of each patch it finds.
pub(crate) trait PatchSink {
    fn conn(&self) -> &Connectivity;
    /// Called once the patch is claimed. The decoder re-inserts the
    /// removed vertex's fan right there, while the patch's half-edges are
    /// still in cache; the traversal sees the same mesh either way (see
    /// [`Traversal::run`]).
    fn found(&mut self, region: &Region);
}

/// A mesh that is only walked (the encoder's replay).
pub(crate) struct Walked<'a>(pub &'a Connectivity);

impl PatchSink for Walked<'_> {
    fn conn(&self) -> &Connectivity {
        self.0
    }

    fn found(&mut self, _: &Region) {}
}

/// A patch found by the traversal: the removed vertex's border polygon and
/// the coarse half-edges it will be re-inserted into.
#[derive(Clone, Copy)]
pub(crate) struct Region {
    pub valence: usize,
    pub polygon: [u32; MAX_VALENCE],
    pub outer: [u32; MAX_VALENCE],
    /// The region's own half-edge on each border edge `p_i → p_i+1`.
    pub boundary: [u32; MAX_VALENCE],
    /// Half-edge at corner 0 of each pattern triangle.
    pub corner0: [u32; MAX_VALENCE - 2],
}

/// What the traversal keeps of each patch once its sink has it: the removed
/// vertex's border polygon, which predicts its position. A third of a
/// [`Region`]'s size, so the pass's list streams through the cache faster.
#[derive(Clone, Copy)]
pub(crate) struct Border {
    pub valence: usize,
    pub polygon: [u32; MAX_VALENCE],
}

/// Adaptive models of the connectivity codes of one pass, each starting
/// from its trained prior ([`crate::priors`]).
///
/// A context is copied from its prior when the pass first uses it, not all
/// of them when the pass starts: there are 7,776 decimating contexts
/// (250 KB), and a pass over a small mesh touches few of them, so copying
/// them all cost more than decoding such a pass. Each context remembers the
/// pass that last set it up.
#[derive(Default)]
struct ConnModels {
    valence: Vec<FrequencyModel<DECIMATION_SYMBOLS>>,
    valence_pass: Vec<u32>,
    cleaning: Vec<BitModel>,
    cleaning_pass: Vec<u32>,
    /// The current pass, from 1 (0 marks a context no pass has used).
    pass: u32,
}

impl ConnModels {
    fn start_pass(&mut self) {
        if self.valence.is_empty() {
            self.valence = priors::decimation_models().to_vec();
            self.valence_pass = vec![0; DECIMATION_CONTEXTS];
            self.cleaning = priors::cleaning_models().to_vec();
            self.cleaning_pass = vec![0; CLEANING_CONTEXTS];
        }
        self.pass = self.pass.wrapping_add(1);
        if self.pass == 0 {
            self.valence_pass.fill(0);
            self.cleaning_pass.fill(0);
            self.pass = 1;
        }
    }

    #[inline]
    fn valence(&mut self, m: usize) -> &mut FrequencyModel<DECIMATION_SYMBOLS> {
        if self.valence_pass[m] != self.pass {
            self.valence_pass[m] = self.pass;
            self.valence[m] = priors::decimation_models()[m].clone();
        }
        &mut self.valence[m]
    }

    #[inline]
    fn cleaning(&mut self, m: usize) -> &mut BitModel {
        if self.cleaning_pass[m] != self.pass {
            self.cleaning_pass[m] = self.pass;
            self.cleaning[m] = priors::cleaning_models()[m];
        }
        &mut self.cleaning[m]
    }
}

/// How often each code was seen in each context, for training priors.
#[derive(Clone, Debug)]
pub struct GateStatistics {
    /// Per decimating context: how many gates took each symbol.
    pub decimation: Vec<[u64; DECIMATION_SYMBOLS]>,
    /// Per cleaning context: how many gates coded 0 and 1.
    pub cleaning: Vec<[u64; 2]>,
}

impl Default for GateStatistics {
    fn default() -> Self {
        GateStatistics {
            decimation: vec![[0; DECIMATION_SYMBOLS]; DECIMATION_CONTEXTS],
            cleaning: vec![[0; 2]; CLEANING_CONTEXTS],
        }
    }
}

/// Traversal state, reused across passes so a pass allocates nothing per vertex.
#[derive(Default)]
pub(crate) struct Traversal {
    tag: Vec<Tag>,
    face_done: Vec<bool>,
    gates: VecDeque<u32>,
    models: ConnModels,
    /// Borders of the patches in the order the traversal found them (the
    /// insertion order).
    pub borders: Vec<Border>,
    /// Counts every code by context when set (training, not decoding).
    pub statistics: Option<Box<GateStatistics>>,
}

impl Traversal {
    /// Room for a mesh of `needed` vertices and its faces, two a vertex
    /// (`target` vertices' worth if the arrays move; see [`crate::room`]).
    pub(crate) fn make_room(&mut self, needed: usize, target: usize) {
        use crate::room::reserve;
        reserve(&mut self.tag, needed, target);
        reserve(&mut self.face_done, 2 * needed, 2 * target);
    }

    /// Walks one pass over `mesh` from `seeds` (one gate `a → b` per
    /// connected component), asking `codes` for each gate's code and
    /// collecting at most `max_patches` patches in [`Traversal::borders`].
    /// `valences` are the coarse mesh's ([`crate::predict::umbrellas`]).
    ///
    /// `mesh` may change each patch it is told of into anything whose
    /// faces are new (appended) or the patch's own slots: those count as
    /// conquered, and the traversal never looks inside conquered faces (a
    /// fit test stops at them, gates in them are skipped), nor at a vertex
    /// the pass inserts. So it finds the same patches and codes whether or
    /// not the sink re-inserts vertices as it goes.
    pub(crate) fn run(
        &mut self,
        mesh: &mut impl PatchSink,
        valences: &[u8],
        kind: PassKind,
        seeds: &[[u32; 2]],
        max_patches: usize,
        codes: &mut impl GateCodes,
    ) -> Result<()> {
        let n = mesh.conn().out.len();
        self.tag.clear();
        self.tag.resize(n, Tag::None);
        self.face_done.clear();
        self.face_done.resize(mesh.conn().face_count_slots(), false);
        self.borders.clear();
        self.gates.clear();
        self.models.start_pass();
        for &[a, b] in seeds {
            let conn = mesh.conn();
            if a as usize >= n || b as usize >= n || conn.out[a as usize] == NONE {
                return Err(Error::stream(
                    "seed gate names a vertex that does not exist yet",
                ));
            }
            let h = conn
                .find_half_edge(a, b)
                .ok_or_else(|| Error::stream("seed gate is not an edge of the mesh"))?;
            if self.face_done[face(h) as usize] {
                return Err(Error::stream("seed gate lies in an already conquered face"));
            }
            self.conquer(a, Tag::Plus);
            self.conquer(b, Tag::Minus);
            self.gates.push_back(h);
            while let Some(g) = self.gates.pop_front() {
                let found = self.gate(mesh.conn(), valences, g, kind, max_patches, codes)?;
                if let Some(region) = found {
                    mesh.found(&region);
                    // Faces the sink appended are conquered (a fan is never walked).
                    self.face_done.resize(mesh.conn().face_count_slots(), true);
                }
            }
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn gate(
        &mut self,
        conn: &Connectivity,
        valences: &[u8],
        g: u32,
        kind: PassKind,
        max_patches: usize,
        codes: &mut impl GateCodes,
    ) -> Result<Option<Region>> {
        let f = face(g);
        if self.face_done[f as usize] {
            return Ok(None);
        }
        let (origin, target) = (conn.origin[g as usize], conn.target(g));
        let front = conn.origin[prev(g) as usize];
        let t0 = self.tag[origin as usize];
        let t1 = self.tag[target as usize];
        let ctx = gate_context(t0, t1, self.tag[front as usize]);
        let class = |v: u32| match valences[v as usize] {
            ..=4 => 0,
            5 | 6 => 1,
            _ => 2,
        };
        let (g0, g1) = (as_gate_tag(t0), as_gate_tag(t1));
        let region = match kind {
            PassKind::Decimating => {
                // Patches of every valence up to the widest that fits are possible.
                let (widest, entries) = self.widest_fit(conn, g, g0, g1);
                let front_valence = (valences[front as usize] as usize).clamp(2, 9) - 2;
                let m = (((ctx * FRONT_VALENCES + front_valence) * VALENCE_CLASSES
                    + class(origin))
                    * VALENCE_CLASSES
                    + class(target))
                    * FIT_CLASSES
                    + widest
                    - MIN_VALENCE;
                let sym = codes.decimation(self.models.valence(m), widest - 1)?;
                if let Some(s) = &mut self.statistics {
                    s.decimation[m][sym.min(DECIMATION_SYMBOLS - 1)] += 1;
                }
                match sym {
                    0 => None,
                    sym => {
                        let pat = pattern(MIN_VALENCE - 1 + sym, g0, g1);
                        Some(self.find_patch(conn, g, pat, &entries).ok_or_else(|| {
                            Error::stream("patch faces do not match their pattern")
                        })?)
                    }
                }
            }
            PassKind::Cleaning => {
                let m = ((ctx * VALENCE_CLASSES + class(front)) * VALENCE_CLASSES + class(origin))
                    * VALENCE_CLASSES
                    + class(target);
                let removed = codes.cleaning(self.models.cleaning(m))?;
                if let Some(s) = &mut self.statistics {
                    s.cleaning[m][usize::from(removed)] += 1;
                }
                if removed {
                    // A triangle: the gate's face alone, no face to walk to.
                    let region = self.find_patch(conn, g, pattern(MIN_VALENCE, g0, g1), &[g; 4]);
                    Some(region.ok_or_else(|| Error::stream("cleaning patch does not fit"))?)
                } else {
                    None
                }
            }
        };
        let Some(region) = region else {
            // Null patch: conquer the front face and go on through its other two edges.
            self.face_done[f as usize] = true;
            self.conquer(front, Tag::Plus);
            for h in [next(g), prev(g)] {
                self.push_gate(conn.twin[h as usize]);
            }
            return Ok(None);
        };
        if self.borders.len() >= max_patches {
            return Err(Error::stream(
                "pass inserts more vertices than its header says",
            ));
        }
        self.claim_patch(&region, pattern(region.valence, g0, g1));
        self.borders.push(Border {
            valence: region.valence,
            polygon: region.polygon,
        });
        Ok(Some(region))
    }

    /// The largest valence whose patch faces exist around the gate and are
    /// unconquered (3 at least: the gate's own face is free), and the
    /// half-edge each of those faces is entered by (the gate first, then
    /// the faces in [`growth`] order). A superset of what
    /// [`Traversal::find_patch`] accepts, which also checks the polygon.
    #[inline]
    fn widest_fit(&self, c: &Connectivity, g: u32, g0: Tag, g1: Tag) -> (usize, Entries) {
        let mut faces = [face(g); MAX_VALENCE - 2];
        // The half-edge each face was entered by: every grown face is one
        // step on from an earlier one (its parent), so one twin load each.
        let mut entries = [g; MAX_VALENCE - 2];
        for (n, added) in growth(g0, g1).iter().enumerate() {
            let from = entries[added.parent as usize];
            let out = match added.steps[added.len as usize - 1] {
                1 => next(from),
                _ => prev(from),
            };
            let h = c.twin[out as usize];
            if h == NONE {
                return (MIN_VALENCE + n, entries);
            }
            let f = face(h);
            if self.face_done[f as usize] || faces[..=n].contains(&f) {
                return (MIN_VALENCE + n, entries);
            }
            faces[n + 1] = f;
            entries[n + 1] = h;
        }
        (MAX_VALENCE, entries)
    }

    /// The `valence − 2` faces of the retriangulated patch at the gate, from
    /// the half-edges [`Traversal::widest_fit`] entered them by (it found
    /// them on the mesh, unconquered and distinct, for every valence up to
    /// the widest, and a code never names a wider one); `None` when their
    /// corners do not make the pattern's polygon (a repeated vertex).
    fn find_patch(
        &self,
        c: &Connectivity,
        g: u32,
        pat: &Pattern,
        entries: &Entries,
    ) -> Option<Region> {
        let d = pat.valence;
        let count = d - 2;
        let advance = |mut h: u32, steps: u8| {
            for _ in 0..steps {
                h = next(h);
            }
            h
        };
        let mut corner0 = [NONE; MAX_VALENCE - 2];
        // Corner 0 of the gate triangle is `gate_corner` steps before the gate.
        corner0[pat.gate_triangle as usize] = advance(g, 3 - pat.gate_corner);
        // The pattern's walk reaches its faces in growth order (tested in
        // `patch`): walk step `i` enters by `entries[i + 1]`.
        for (&[_, _, to, r], &h) in pat.walk[..d - 3].iter().zip(&entries[1..]) {
            corner0[to as usize] = advance(h, 3 - r);
        }
        let mut polygon = [NONE; MAX_VALENCE];
        for (t, &h0) in corner0[..count].iter().enumerate() {
            let mut h = h0;
            for &local in &pat.triangles[t] {
                let v = c.origin[h as usize];
                let p = &mut polygon[local as usize];
                if *p == NONE {
                    *p = v;
                } else if *p != v {
                    return None;
                }
                h = next(h);
            }
        }
        if (1..d).any(|i| polygon[..i].contains(&polygon[i])) {
            return None;
        }
        let mut outer = [NONE; MAX_VALENCE];
        let mut boundary = [NONE; MAX_VALENCE];
        for i in 0..d {
            let corner = pat.polygon_corner[i];
            let h = advance(corner0[corner as usize / 3], corner % 3);
            boundary[i] = h;
            outer[i] = c.twin[h as usize];
        }
        Some(Region {
            valence: d,
            polygon,
            outer,
            boundary,
            corner0,
        })
    }

    /// Conquers the patch's faces and border as the encoder did.
    fn claim_patch(&mut self, r: &Region, pat: &Pattern) {
        let d = r.valence;
        for &h in &r.corner0[..d - 2] {
            self.face_done[face(h) as usize] = true;
        }
        for i in 0..d {
            self.conquer(r.polygon[i], pat.tags[i]);
        }
        for &o in &r.outer[1..d] {
            self.push_gate(o);
        }
    }

    /// Queues gate `h` unless it is a border (`NONE`) or its face is already
    /// conquered. Faces are never un-conquered within a pass, so such a gate
    /// would be skipped when popped anyway: dropping it here gives the same
    /// codes and keeps about 60 % of gates out of the FIFO.
    #[inline]
    fn push_gate(&mut self, h: u32) {
        if h != NONE && !self.face_done[face(h) as usize] {
            self.gates.push_back(h);
        }
    }

    /// Tags `v` unless it already has a tag (a conquered vertex keeps its first).
    fn conquer(&mut self, v: u32, tag: Tag) {
        let t = &mut self.tag[v as usize];
        if *t == Tag::None {
            *t = tag;
        }
    }
}

/// The half-edges a patch's faces are entered by: the gate, then one per
/// face grown around it ([`Traversal::widest_fit`]).
type Entries = [u32; MAX_VALENCE - 2];

/// Gate vertices are always tagged in a well-formed pass; a hostile one
/// must still not panic, so an untagged vertex reads as `+`.
fn as_gate_tag(t: Tag) -> Tag {
    if t == Tag::None {
        Tag::Plus
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::entropy::RangeEncoder;

    /// Adapts context `m` of both kinds as coding would.
    fn adapt(models: &mut ConnModels, m: usize) {
        let mut enc = RangeEncoder::new();
        enc.encode_symbol_below(models.valence(m), 2, DECIMATION_SYMBOLS);
        enc.encode_bit(models.cleaning(m), true);
    }

    #[test]
    fn each_pass_starts_every_context_from_its_prior() {
        let mut models = ConnModels::default();
        models.start_pass();
        adapt(&mut models, 7);
        assert_ne!(models.valence(7), &priors::decimation_models()[7]);
        assert_ne!(models.cleaning(7), &priors::cleaning_models()[7]);
        models.start_pass();
        assert_eq!(models.valence(7), &priors::decimation_models()[7]);
        assert_eq!(models.cleaning(7), &priors::cleaning_models()[7]);
        // When the pass counter wraps around to a number a context was
        // last set up in, that context still starts afresh.
        let mut models = ConnModels::default();
        models.start_pass();
        assert_eq!(models.pass, 1);
        adapt(&mut models, 7);
        models.pass = u32::MAX;
        models.start_pass();
        assert_eq!(models.pass, 1);
        assert_eq!(models.cleaning(7), &priors::cleaning_models()[7]);
        assert_eq!(models.valence(7), &priors::decimation_models()[7]);
    }
}
