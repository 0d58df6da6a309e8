//! The umbrella vectors of a level's vertices, kept up to date as passes
//! re-insert vertices instead of swept again over every face before each
//! pass.
//!
//! A pass predicts every vertex it re-inserts from the umbrellas of the
//! mesh it starts on ([`crate::predict::umbrellas`]). Re-inserting a vertex
//! `v` into a patch of `d` border vertices replaces the patch's `d − 2`
//! faces by `v`'s fan: every border vertex loses its half-edges along the
//! patch's diagonals and gains one to `v`, and `v` has `d`. So the next
//! pass's umbrellas are this pass's plus what each fan changed, which the
//! decoder adds as it decodes the vertex (the border's positions are then
//! in cache: the predictor just read them). Those gains wait beside the
//! umbrellas they change (the same 32 bytes, so the same cache line) until
//! the pass ends, because the pass's later predictions still read the mesh
//! it started on. A sweep is bound by random accesses to every vertex; the
//! pass's end is one sequential one.
//!
//! The sums wrap, as the sweep's do: the same values modulo 2³².

use crate::gates::Border;
use crate::halfedge::Connectivity;
use crate::predict::umbrellas;

/// One vertex's umbrella on the mesh the pass started on, and what the
/// fans re-inserted so far changed of it.
#[derive(Clone, Copy, Default)]
#[repr(C, align(32))]
struct Umbrella {
    /// The sum of `neighbour − vertex` over the outgoing half-edges, and their count.
    start: [i32; 4],
    gained: [i32; 4],
}

#[derive(Default)]
pub(super) struct Umbrellas {
    records: Vec<Umbrella>,
    /// The counts again, saturated to a byte, for the gate traversal's contexts.
    pub valences: Vec<u8>,
    /// Umbrellas of the re-inserted vertices, in insertion order.
    inserted: Vec<[i32; 4]>,
    /// Whether `records` are the level's (set by the first sweep, cleared
    /// when a pass fails part-way).
    current: bool,
    sweep: Vec<[i32; 4]>,
}

impl Umbrellas {
    /// Sweeps the level's faces unless the umbrellas are already its own.
    pub(super) fn ensure(&mut self, conn: &Connectivity, positions: &[[i32; 3]]) {
        if self.current && self.records.len() == positions.len() {
            return;
        }
        umbrellas(conn, positions, &mut self.sweep, &mut self.valences);
        self.records.clear();
        self.records
            .extend(self.sweep.iter().map(|&start| Umbrella {
                start,
                gained: [0; 4],
            }));
        self.inserted.clear();
        self.current = true;
    }

    /// A pass failed part-way: the next one sweeps again.
    pub(super) fn invalidate(&mut self) {
        self.current = false;
    }

    /// Vertex `v`'s umbrella on the mesh the pass started on.
    #[inline]
    pub(super) fn at_start(&self, v: u32) -> [i32; 4] {
        self.records[v as usize].start
    }

    /// Records the fan of a vertex re-inserted at `position` into `border`
    /// (vertices of `positions`, all there before the pass).
    pub(super) fn add_fan(&mut self, border: &Border, positions: &[[i32; 3]], position: [i32; 3]) {
        let d = border.valence;
        let corners: [[i32; 3]; crate::patch::MAX_VALENCE] =
            std::array::from_fn(|i| positions[border.polygon[i.min(d - 1)] as usize]);
        let mut own = [0i32, 0, 0, d as i32];
        for (&v, corner) in border.polygon[..d].iter().zip(&corners) {
            let g = &mut self.records[v as usize].gained;
            for c in 0..3 {
                g[c] = g[c].wrapping_add(position[c].wrapping_sub(corner[c]));
                own[c] = own[c].wrapping_add(corner[c].wrapping_sub(position[c]));
            }
            g[3] = g[3].wrapping_add(1);
        }
        for &[i, j] in &border.diagonals[..d - 3] {
            let (i, j) = (i as usize, j as usize);
            for (a, b) in [(i, j), (j, i)] {
                let g = &mut self.records[border.polygon[a] as usize].gained;
                for c in 0..3 {
                    g[c] = g[c].wrapping_sub(corners[b][c].wrapping_sub(corners[a][c]));
                }
                g[3] = g[3].wrapping_sub(1);
            }
        }
        self.inserted.push(own);
    }

    /// The pass is over: its gains join the umbrellas, and its vertices'
    /// umbrellas follow in insertion order.
    pub(super) fn end_pass(&mut self) {
        for (u, valence) in self.records.iter_mut().zip(&mut self.valences) {
            for c in 0..4 {
                u.start[c] = u.start[c].wrapping_add(u.gained[c]);
            }
            u.gained = [0; 4];
            *valence = u.start[3].clamp(0, 255) as u8;
        }
        for &start in &self.inserted {
            self.records.push(Umbrella {
                start,
                gained: [0; 4],
            });
            self.valences.push(start[3].clamp(0, 255) as u8);
        }
        self.inserted.clear();
    }

    /// The sweep's umbrellas of the same mesh (debug builds check the upkeep against it).
    #[cfg(debug_assertions)]
    pub(super) fn agrees_with_sweep(&self, conn: &Connectivity, positions: &[[i32; 3]]) -> bool {
        let (mut swept, mut valences) = (Vec::new(), Vec::new());
        umbrellas(conn, positions, &mut swept, &mut valences);
        self.records.len() == swept.len()
            && self.records.iter().zip(&swept).all(|(u, s)| u.start == *s)
            && self.valences == valences
    }
}
