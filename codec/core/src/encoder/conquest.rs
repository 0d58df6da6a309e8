//! The encoder's conquests (AD01 §3): decimating and cleaning passes over
//! the mesh, removing vertices patch by patch and emitting one code per gate.

use std::collections::VecDeque;

use super::coding::{CoarseMesh, PassRecord};
use super::{CandidatePatch, PatchGuard};
pub(crate) use crate::gates::PassKind;
use crate::halfedge::{face, next, prev, Connectivity, NONE};
use crate::patch::{pattern, Pattern, Tag, MAX_VALENCE, NO_TWIN};

const FREE: u8 = 0;
const CONQUERED: u8 = 1;
const REMOVED: u8 = 2;

/// The geometric guard's floor: a patch whose doubled area, squared and
/// per triangle squared (grid units), is at most this is not guarded.
const NOISE_TRIANGLE: f64 = 16.0;

/// The mesh being simplified, with input-vertex ids throughout.
pub(crate) struct Simplifier<'g> {
    pub conn: Connectivity,
    /// Input-vertex id of each current vertex (the mesh is compacted per layer).
    pub ids: Vec<u32>,
    pub positions: Vec<[i32; 3]>,
    pub colours: Option<Vec<[u8; 3]>>,
    pub geometric_guard: bool,
    /// A caller's veto on decimations (the cell complex, a colour metric).
    pub patch_guard: Option<&'g dyn PatchGuard>,
    /// By input-vertex id, the vertices a chart shares with another (empty
    /// outside charts): no retriangulation may join two of them, or two
    /// charts could each make the same edge.
    pub cut: Vec<bool>,
    /// Mean face area of the mesh at the start of the pass, for guards.
    mean_face_area: f64,
    pub live_vertices: usize,
    state: Vec<u8>,
    tag: Vec<Tag>,
    face_done: Vec<bool>,
}

/// A removable vertex and the patch around it.
struct Patch {
    valence: usize,
    centre: u32,
    /// Outgoing half-edges of the centre, the first towards the gate's origin.
    ring: [u32; MAX_VALENCE],
    polygon: [u32; MAX_VALENCE],
    pattern: &'static Pattern,
}

impl<'g> Simplifier<'g> {
    /// `ids` gives each vertex's input-vertex id.
    pub(crate) fn new(
        conn: Connectivity,
        ids: Vec<u32>,
        positions: Vec<[i32; 3]>,
        colours: Option<Vec<[u8; 3]>>,
        geometric_guard: bool,
        patch_guard: Option<&'g dyn PatchGuard>,
    ) -> Self {
        let n = positions.len();
        Simplifier {
            conn,
            ids,
            positions,
            colours,
            geometric_guard,
            patch_guard,
            cut: Vec::new(),
            mean_face_area: 0.0,
            live_vertices: n,
            state: vec![FREE; n],
            tag: vec![Tag::None; n],
            face_done: Vec::new(),
        }
    }

    /// Runs one conquest over the mesh, removing what it can; the record
    /// is coded later against [`Simplifier::coarse_mesh`] taken right after.
    pub(crate) fn run_pass(&mut self, kind: PassKind) -> PassRecord {
        for (v, s) in self.state.iter_mut().enumerate() {
            *s = if self.conn.out[v] == NONE {
                REMOVED
            } else {
                FREE
            };
        }
        self.tag.fill(Tag::None);
        if self.patch_guard.is_some_and(|g| g.uses_mean_face_area()) {
            self.mean_face_area = self.mean_face_area();
        }
        self.face_done.clear();
        self.face_done.resize(self.conn.face_count_slots(), false);
        let mut record = PassRecord {
            kind,
            seeds: Vec::new(),
            decisions: Vec::new(),
            patches: Vec::new(),
            input_seeds: Vec::new(),
            input_removed: Vec::new(),
        };
        let mut gates = VecDeque::with_capacity(self.conn.face_count_slots());
        for f in 0..self.conn.face_count_slots() as u32 {
            if !self.conn.face_alive(f) || self.face_done[f as usize] {
                continue;
            }
            // A new connected component: its seed gate is the face's first edge.
            let h = 3 * f;
            let (a, b) = (self.conn.origin[h as usize], self.conn.target(h));
            self.conquer(a, Tag::Plus);
            self.conquer(b, Tag::Minus);
            record.seeds.push([a, b]);
            gates.push_back(h);
            while let Some(g) = gates.pop_front() {
                self.process_gate(g, kind, &mut gates, &mut record);
            }
        }
        let id = |v: u32| self.ids[v as usize];
        record.input_seeds = record.seeds.iter().map(|s| s.map(id)).collect();
        record.input_removed = record.patches.iter().map(|p| id(p.0)).collect();
        record
    }

    /// The mesh as the last pass left it, for coding that pass.
    pub(crate) fn coarse_mesh(&self) -> CoarseMesh<'_> {
        CoarseMesh {
            conn: &self.conn,
            positions: &self.positions,
            colours: self.colours.as_deref(),
        }
    }

    /// Drops dead vertices and face slots so later passes walk dense,
    /// cache-friendly arrays; order is kept, so output does not change.
    pub(crate) fn compact(&mut self) {
        let mut vertex_map = vec![NONE; self.ids.len()];
        let mut kept = 0u32;
        for (v, m) in vertex_map.iter_mut().enumerate() {
            if self.conn.out[v] != NONE {
                *m = kept;
                self.ids[kept as usize] = self.ids[v];
                self.positions[kept as usize] = self.positions[v];
                if let Some(c) = &mut self.colours {
                    c[kept as usize] = c[v];
                }
                kept += 1;
            }
        }
        let n = kept as usize;
        self.ids.truncate(n);
        self.positions.truncate(n);
        if let Some(c) = &mut self.colours {
            c.truncate(n);
        }
        let slots = self.conn.face_count_slots();
        let mut face_map = vec![NONE; slots];
        let mut faces = 0u32;
        for (f, m) in face_map.iter_mut().enumerate() {
            if self.conn.face_alive(f as u32) {
                *m = faces;
                faces += 1;
            }
        }
        let remap_half_edge = |h: u32| {
            if h == NONE {
                NONE
            } else {
                3 * face_map[face(h) as usize] + h % 3
            }
        };
        // In place: a face or vertex only ever moves down (its new index is
        // at most its old one), and each slot is read before anything is
        // written over it. No new arrays, so no fresh pages to fault in on a
        // multi-million-vertex scan.
        let conn = &mut self.conn;
        for (f, &m) in face_map.iter().enumerate() {
            if m != NONE {
                for k in 0..3 {
                    let (from, to) = (3 * f + k, 3 * m as usize + k);
                    conn.origin[to] = vertex_map[conn.origin[from] as usize];
                    conn.twin[to] = remap_half_edge(conn.twin[from]);
                }
            }
        }
        conn.origin.truncate(3 * faces as usize);
        conn.twin.truncate(3 * faces as usize);
        for (v, &m) in vertex_map.iter().enumerate() {
            let h = conn.out[v];
            if h != NONE {
                conn.out[m as usize] = remap_half_edge(h);
            }
        }
        conn.out.truncate(n);
        self.state.truncate(n);
        self.tag.truncate(n);
    }

    /// Interior vertices of valence 3: what a cleaning pass could remove.
    pub(crate) fn valence_three_vertices(&self) -> usize {
        (0..self.conn.out.len() as u32)
            .filter(|&v| {
                let start = self.conn.out[v as usize];
                if start == NONE {
                    return false;
                }
                let mut h = start;
                for _ in 0..3 {
                    h = self.conn.rotate_ccw(h);
                    if h == NONE {
                        return false;
                    }
                }
                h == start
            })
            .count()
    }

    fn conquer(&mut self, v: u32, tag: Tag) {
        if self.state[v as usize] == FREE {
            self.state[v as usize] = CONQUERED;
        }
        if self.tag[v as usize] == Tag::None {
            self.tag[v as usize] = tag;
        }
    }

    fn process_gate(
        &mut self,
        g: u32,
        kind: PassKind,
        gates: &mut VecDeque<u32>,
        record: &mut PassRecord,
    ) {
        let f = face(g);
        if !self.conn.face_alive(f) || self.face_done[f as usize] {
            return;
        }
        let t0 = self.tag[self.conn.origin[g as usize] as usize];
        let t1 = self.tag[self.conn.target(g) as usize];
        if let Some(patch) = self.removable(g, kind, t0, t1) {
            record.decisions.push((patch.valence - 2) as u8);
            record
                .patches
                .push((patch.centre, patch.valence, patch.polygon));
            self.remove(&patch, gates);
        } else {
            let front = self.conn.origin[prev(g) as usize];
            record.decisions.push(0);
            // Null patch: conquer the front face and go on through its other two edges.
            self.face_done[f as usize] = true;
            self.conquer(front, Tag::Plus);
            for h in [next(g), prev(g)] {
                self.push_gate(self.conn.twin[h as usize], gates);
            }
        }
    }

    /// The patch around the gate's front vertex, if removing it keeps the
    /// mesh a manifold the decoder can rebuild exactly.
    fn removable(&self, g: u32, kind: PassKind, t0: Tag, t1: Tag) -> Option<Patch> {
        let c = &self.conn;
        let centre = c.origin[prev(g) as usize];
        if self.state[centre as usize] != FREE {
            return None;
        }
        let max_valence = if kind == PassKind::Cleaning {
            3
        } else {
            MAX_VALENCE
        };
        let mut ring = [NONE; MAX_VALENCE];
        let mut polygon = [NONE; MAX_VALENCE];
        let start = prev(g);
        let mut h = start;
        let mut valence = 0;
        loop {
            if valence == max_valence {
                return None;
            }
            ring[valence] = h;
            polygon[valence] = c.target(h);
            valence += 1;
            h = c.rotate_ccw(h);
            if h == NONE {
                return None; // border vertex: AD01 keeps borders intact
            }
            if h == start {
                break;
            }
        }
        if valence < 3 {
            return None;
        }
        let pattern = pattern(valence, t0, t1);
        if valence == 3 {
            // Removing a valence-3 vertex whose link is already a face would
            // leave two faces on the same three vertices (a tetrahedron's tip).
            let outer = c.twin[g as usize];
            if outer != NONE && c.origin[prev(outer) as usize] == polygon[2] {
                return None;
            }
        } else {
            for corner in 0..3 * pattern.triangle_count() {
                let t = pattern.twin[corner] as usize;
                if t < NO_TWIN as usize && corner < t {
                    let a = polygon[pattern.corner_vertex(corner)];
                    let b = polygon[pattern.corner_vertex(t)];
                    if c.has_edge(a, b) || self.on_cut(a) && self.on_cut(b) {
                        return None;
                    }
                }
            }
        }
        let patch = Patch {
            valence,
            centre,
            ring,
            polygon,
            pattern,
        };
        if self.geometric_guard && self.folds(&patch) {
            return None;
        }
        if let Some(guard) = self.patch_guard {
            if !guard.allows(&self.candidate(&patch)) {
                return None;
            }
        }
        Some(patch)
    }

    fn on_cut(&self, v: u32) -> bool {
        !self.cut.is_empty() && self.cut[self.ids[v as usize] as usize]
    }

    fn candidate<'p>(&self, p: &'p Patch) -> CandidatePatch<'p> {
        let mut polygon = [[0i32; 3]; MAX_VALENCE];
        let mut polygon_colours = [[0u8; 3]; MAX_VALENCE];
        for i in 0..p.valence {
            polygon[i] = self.positions[p.polygon[i] as usize];
            if let Some(c) = &self.colours {
                polygon_colours[i] = c[p.polygon[i] as usize];
            }
        }
        CandidatePatch {
            centre: self.positions[p.centre as usize],
            centre_colour: self.colours.as_ref().map(|c| c[p.centre as usize]),
            valence: p.valence,
            polygon,
            polygon_colours,
            triangles: &p.pattern.triangles[..p.pattern.triangle_count()],
            mean_face_area: self.mean_face_area,
        }
    }

    fn mean_face_area(&self) -> f64 {
        let (mut sum, mut n) = (0.0, 0usize);
        for t in self.conn.triangles() {
            let [a, b, c] = t.map(|v| glam::DVec3::from(self.positions[v as usize].map(f64::from)));
            sum += 0.5 * (b - a).cross(c - a).length();
            n += 1;
        }
        if n == 0 {
            0.0
        } else {
            sum / n as f64
        }
    }

    /// Whether a new triangle would face against the patch (a visible fold).
    fn folds(&self, p: &Patch) -> bool {
        let pos = |v: u32| self.positions[v as usize].map(|x| x as f64);
        let cross = |a: [f64; 3], b: [f64; 3], c: [f64; 3]| {
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let w = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            [
                u[1] * w[2] - u[2] * w[1],
                u[2] * w[0] - u[0] * w[2],
                u[0] * w[1] - u[1] * w[0],
            ]
        };
        let centre = pos(p.centre);
        let mut normal = [0.0; 3];
        for i in 0..p.valence {
            let n = cross(
                centre,
                pos(p.polygon[i]),
                pos(p.polygon[(i + 1) % p.valence]),
            );
            (0..3).for_each(|k| normal[k] += n[k]);
        }
        // A patch whose triangles are on average within two grid cells'
        // area (its doubled area at most 4 a triangle) has no orientation
        // the quantization can hold: what looks like a fold there is grid
        // noise. Guarding those stalled dense scans whose triangles are a
        // grid cell or smaller: a 20.5 M-vertex scan at 12 bits stopped at
        // a base of 346,498 vertices, 19.7 MB, against Draco's 12.1 MB
        // (format 4: 14.8 MB with only zero-area triangles let through,
        // 11.6 MB with this). Larger patches are guarded as before, a
        // zero-area sliver included.
        let doubled_area_squared =
            normal[0] * normal[0] + normal[1] * normal[1] + normal[2] * normal[2];
        let noise = NOISE_TRIANGLE * (p.valence * p.valence) as f64;
        if doubled_area_squared <= noise {
            return false;
        }
        p.pattern.triangles[..p.pattern.triangle_count()]
            .iter()
            .any(|t| {
                let n = cross(
                    pos(p.polygon[t[0] as usize]),
                    pos(p.polygon[t[1] as usize]),
                    pos(p.polygon[t[2] as usize]),
                );
                n[0] * normal[0] + n[1] * normal[1] + n[2] * normal[2] <= 0.0
            })
    }

    /// Removes the patch's centre and retriangulates its polygon by the pattern.
    fn remove(&mut self, p: &Patch, gates: &mut VecDeque<u32>) {
        let d = p.valence;
        let pat = p.pattern;
        let mut outer = [NONE; MAX_VALENCE];
        let mut old_faces = [NONE; MAX_VALENCE];
        for i in 0..d {
            outer[i] = self.conn.twin[next(p.ring[i]) as usize];
            old_faces[i] = face(p.ring[i]);
        }
        let kept = d - 2;
        for &f in &old_faces[kept..d] {
            for k in 0..3 {
                self.conn.origin[3 * f as usize + k] = NONE;
                self.conn.twin[3 * f as usize + k] = NONE;
            }
        }
        let half_edge = |corner: usize| 3 * old_faces[corner / 3] + (corner % 3) as u32;
        for corner in 0..3 * kept {
            let h = half_edge(corner);
            self.conn.origin[h as usize] = p.polygon[pat.corner_vertex(corner)];
            let t = pat.twin[corner];
            if t >= NO_TWIN {
                let o = outer[(t - NO_TWIN) as usize];
                self.conn.twin[h as usize] = o;
                if o != NONE {
                    self.conn.twin[o as usize] = h;
                }
            } else {
                self.conn.twin[h as usize] = half_edge(t as usize);
            }
        }
        for &f in &old_faces[..kept] {
            self.face_done[f as usize] = true;
        }
        for i in 0..d {
            let v = p.polygon[i];
            self.conn.out[v as usize] = half_edge(pat.polygon_corner[i] as usize);
            self.conquer(v, pat.tags[i]);
        }
        self.conn.out[p.centre as usize] = NONE;
        self.state[p.centre as usize] = REMOVED;
        self.live_vertices -= 1;
        for &o in &outer[1..d] {
            self.push_gate(o, gates);
        }
    }

    /// Queues gate `h` unless it is a border (`NONE`) or its face is dead or
    /// already conquered: faces are neither revived nor un-conquered within
    /// a pass, so such a gate would be skipped when popped anyway (as in
    /// [`crate::gates`], which keeps most gates out of the FIFO this way).
    #[inline]
    fn push_gate(&self, h: u32, gates: &mut VecDeque<u32>) {
        if h != NONE {
            let f = face(h);
            if self.conn.face_alive(f) && !self.face_done[f as usize] {
                gates.push_back(h);
            }
        }
    }
}
