//! Patch retriangulation shared by encoder and decoder (AD01 §3.3).
//!
//! When the encoder removes a vertex of valence `d`, the hole it leaves is a
//! polygon `p0 … p(d-1)`, counter-clockwise, starting at the gate `p0 → p1`.
//! The polygon is retriangulated by a rule both sides can replay from the
//! retriangulation tags of the two gate vertices alone: the remaining
//! vertices are tagged by alternation from the gate, then ears are clipped at
//! `−` vertices (they lose valence) so that `+` vertices gain the new edges.
//! On a regular (valence-6) region this is the inverse of √3 subdivision
//! once the cleaning conquest has run, which keeps the coarser mesh regular
//! and the valence codes cheap.

use std::sync::OnceLock;

/// Retriangulation tag of a conquered vertex (AD01 "+"/"−" flags).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub(crate) enum Tag {
    None = 0,
    Plus = 1,
    Minus = 2,
}

impl Tag {
    pub(crate) fn opposite(self) -> Tag {
        match self {
            Tag::Plus => Tag::Minus,
            Tag::Minus => Tag::Plus,
            Tag::None => Tag::None,
        }
    }
}

pub(crate) const MIN_VALENCE: usize = 3;
pub(crate) const MAX_VALENCE: usize = 6;

/// The triangulation of one patch polygon, in polygon-local vertex indices.
#[derive(Clone, Debug)]
pub(crate) struct Pattern {
    pub valence: usize,
    /// `valence − 2` counter-clockwise triangles.
    pub triangles: [[u8; 3]; MAX_VALENCE - 2],
    /// For corner `3 t + k` (the directed edge `triangles[t][k] → triangles[t][k+1]`):
    /// the corner of the same edge in the neighbouring triangle when the edge
    /// is a diagonal, or `NO_TWIN + i` when it is polygon edge `i → i+1`.
    pub twin: [u8; 3 * (MAX_VALENCE - 2)],
    /// Tags the polygon vertices receive (index 0 and 1 are the gate's).
    pub tags: [Tag; MAX_VALENCE],
    /// Triangle holding the gate edge `0 → 1`, and the corner of that edge in it.
    pub gate_triangle: u8,
    pub gate_corner: u8,
    /// Corner holding polygon edge `i → i+1`.
    pub polygon_corner: [u8; MAX_VALENCE],
    /// How to reach every triangle from the gate triangle across diagonals,
    /// `valence − 3` steps `[from, k, to, r]`: the half-edge at corner `k`
    /// of triangle `from` is the twin of the one at corner `r` of `to`.
    pub walk: [[u8; 4]; MAX_VALENCE - 3],
}

pub(crate) const NO_TWIN: u8 = 100;

impl Pattern {
    pub(crate) fn triangle_count(&self) -> usize {
        self.valence - 2
    }

    /// Polygon-local index of the vertex at corner `c`.
    pub(crate) fn corner_vertex(&self, c: usize) -> usize {
        self.triangles[c / 3][c % 3] as usize
    }

    fn build(valence: usize, t0: Tag, t1: Tag) -> Pattern {
        let mut tags = [Tag::None; MAX_VALENCE];
        tags[0] = t0;
        tags[1] = t1;
        for i in 2..valence {
            tags[i] = tags[i - 1].opposite();
        }
        // Ear clipping: first `−` vertex (in polygon order) while any remain,
        // then a fan from the first remaining vertex.
        let mut ring: Vec<u8> = (0..valence as u8).collect();
        let mut triangles = [[0u8; 3]; MAX_VALENCE - 2];
        let mut n = 0;
        while ring.len() > 3 {
            let pos = ring
                .iter()
                .position(|&v| tags[v as usize] == Tag::Minus)
                .unwrap_or(1);
            let len = ring.len();
            let prev = ring[(pos + len - 1) % len];
            let next = ring[(pos + 1) % len];
            triangles[n] = [prev, ring[pos], next];
            n += 1;
            ring.remove(pos);
        }
        triangles[n] = [ring[0], ring[1], ring[2]];
        let count = valence - 2;
        let mut twin = [0u8; 3 * (MAX_VALENCE - 2)];
        let mut gate = (0, 0);
        let mut polygon_corner = [0u8; MAX_VALENCE];
        for c in 0..3 * count {
            let (a, b) = (triangles[c / 3][c % 3], triangles[c / 3][(c + 1) % 3]);
            if (a as usize + 1) % valence == b as usize {
                twin[c] = NO_TWIN + a;
                polygon_corner[a as usize] = c as u8;
                if a == 0 {
                    gate = (c / 3, c % 3);
                }
            } else {
                let other = (0..3 * count)
                    .find(|&o| triangles[o / 3][o % 3] == b && triangles[o / 3][(o + 1) % 3] == a)
                    .expect("a diagonal is shared by two triangles");
                twin[c] = other as u8;
            }
        }
        let mut walk = [[0u8; 4]; MAX_VALENCE - 3];
        let mut reached = vec![gate.0];
        let mut at = 0;
        while at < reached.len() {
            let t = reached[at];
            at += 1;
            for k in 0..3 {
                let other = twin[3 * t + k];
                if other < NO_TWIN && !reached.contains(&(other as usize / 3)) {
                    let to = other as usize / 3;
                    walk[reached.len() - 1] = [t as u8, k as u8, to as u8, other % 3];
                    reached.push(to);
                }
            }
        }
        Pattern {
            valence,
            triangles,
            twin,
            tags,
            gate_triangle: gate.0 as u8,
            gate_corner: gate.1 as u8,
            polygon_corner,
            walk,
        }
    }
}

/// The pattern for a patch of `valence` whose gate vertices carry `t0`, `t1`.
pub(crate) fn pattern(valence: usize, t0: Tag, t1: Tag) -> &'static Pattern {
    static TABLE: OnceLock<Vec<Pattern>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let mut table = Vec::new();
        for valence in MIN_VALENCE..=MAX_VALENCE {
            for t0 in [Tag::Plus, Tag::Minus] {
                for t1 in [Tag::Plus, Tag::Minus] {
                    table.push(Pattern::build(valence, t0, t1));
                }
            }
        }
        table
    });
    let tag_index = |t: Tag| usize::from(t == Tag::Minus);
    &table[(valence - MIN_VALENCE) * 4 + tag_index(t0) * 2 + tag_index(t1)]
}

impl Pattern {
    /// The faces this pattern covers, as walks from the gate triangle: at
    /// each triangle, which edge after the one it was entered by leads on
    /// (1 = next, 2 = previous). The gate triangle is the empty walk.
    pub(crate) fn walks(&self) -> Vec<Vec<u8>> {
        let mut path: Vec<Vec<u8>> = vec![Vec::new(); self.triangle_count()];
        let mut entry = [0u8; MAX_VALENCE - 2];
        entry[self.gate_triangle as usize] = self.gate_corner;
        let mut out = vec![Vec::new()];
        for &[from, k, to, r] in &self.walk[..self.valence - 3] {
            let mut w = path[from as usize].clone();
            w.push((k + 3 - entry[from as usize]) % 3);
            entry[to as usize] = r;
            path[to as usize] = w.clone();
            out.push(w);
        }
        out
    }
}

/// The face a valence-(d+1) patch adds to the valence-d one with the same
/// gate tags, for d = 3, 4, 5: a walk of `len` steps from the gate (see
/// [`Pattern::walks`]). Patches grow by one face as their valence grows
/// (tested below), so walking these in turn tells how wide a patch fits.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Growth {
    pub len: u8,
    pub steps: [u8; MAX_VALENCE - 3],
    /// The face this walk passes last before its own: 0 for the gate's,
    /// `n + 1` for the face grown at step `n` (always an earlier one: every
    /// walk's prefix is a face of the smaller patch). Walking on from there
    /// takes one step, the last of `steps`.
    pub parent: u8,
}

pub(crate) fn growth(t0: Tag, t1: Tag) -> &'static [Growth; MAX_VALENCE - MIN_VALENCE] {
    static TABLE: OnceLock<Vec<[Growth; MAX_VALENCE - MIN_VALENCE]>> = OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let mut table = Vec::new();
        for t0 in [Tag::Plus, Tag::Minus] {
            for t1 in [Tag::Plus, Tag::Minus] {
                let mut row = [Growth::default(); MAX_VALENCE - MIN_VALENCE];
                for (i, g) in row.iter_mut().enumerate() {
                    let small = pattern(MIN_VALENCE + i, t0, t1).walks();
                    let big = pattern(MIN_VALENCE + i + 1, t0, t1).walks();
                    let added = big
                        .iter()
                        .find(|w| !small.contains(w))
                        .expect("a larger patch adds a face");
                    g.len = added.len() as u8;
                    g.steps[..added.len()].copy_from_slice(added);
                }
                for n in 0..row.len() {
                    let prefix = &row[n].steps[..row[n].len as usize - 1];
                    row[n].parent = if prefix.is_empty() {
                        0
                    } else {
                        let earlier = row[..n]
                            .iter()
                            .position(|e| &e.steps[..e.len as usize] == prefix)
                            .expect("a walk's prefix is an earlier face");
                        earlier as u8 + 1
                    };
                }
                table.push(row);
            }
        }
        table
    });
    let tag_index = |t: Tag| usize::from(t == Tag::Minus);
    &table[tag_index(t0) * 2 + tag_index(t1)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_hexagon_is_inverse_sqrt3() {
        let p = pattern(6, Tag::Plus, Tag::Minus);
        assert_eq!(
            &p.triangles[..4],
            &[[0, 1, 2], [2, 3, 4], [4, 5, 0], [0, 2, 4]]
        );
    }

    #[test]
    fn walks_reach_every_triangle_once() {
        for valence in MIN_VALENCE..=MAX_VALENCE {
            for t0 in [Tag::Plus, Tag::Minus] {
                for t1 in [Tag::Plus, Tag::Minus] {
                    let p = pattern(valence, t0, t1);
                    let mut seen = vec![p.gate_triangle];
                    for &[from, k, to, r] in &p.walk[..valence - 3] {
                        assert!(seen.contains(&from) && !seen.contains(&to));
                        assert_eq!(p.twin[3 * from as usize + k as usize], 3 * to + r);
                        seen.push(to);
                    }
                    assert_eq!(seen.len(), valence - 2);
                }
            }
        }
    }

    /// The faces of a valence-d patch are among those of the valence-(d+1)
    /// patch with the same gate tags (AD01's ear clipping grows the same
    /// way), so if d + 1 fits around a gate, d does too.
    #[test]
    fn patterns_grow_by_one_face() {
        for t0 in [Tag::Plus, Tag::Minus] {
            for t1 in [Tag::Plus, Tag::Minus] {
                for valence in MIN_VALENCE..MAX_VALENCE {
                    let small = pattern(valence, t0, t1).walks();
                    let big = pattern(valence + 1, t0, t1).walks();
                    for w in &small {
                        assert!(
                            big.contains(w),
                            "{valence} {t0:?} {t1:?}: {w:?} not in {big:?}"
                        );
                    }
                    let added = growth(t0, t1)[valence - MIN_VALENCE];
                    let added = &added.steps[..added.len as usize];
                    assert!(big.iter().any(|w| w == added) && !small.iter().any(|w| w == added));
                }
            }
        }
    }

    #[test]
    fn pattern_walks_reach_their_faces_in_growth_order() {
        // The gate traversal enters a patch's faces by the half-edges its
        // fit test found in growth order, so walk step i must be growth i,
        // each one step on from its parent.
        for t0 in [Tag::Plus, Tag::Minus] {
            for t1 in [Tag::Plus, Tag::Minus] {
                let grown = growth(t0, t1);
                for valence in MIN_VALENCE..=MAX_VALENCE {
                    let walks = pattern(valence, t0, t1).walks();
                    for (i, w) in walks[1..].iter().enumerate() {
                        let g = grown[i];
                        assert_eq!(w[..], g.steps[..g.len as usize], "{valence} {t0:?} {t1:?}");
                        let parent = match g.parent {
                            0 => &[][..],
                            p => &walks[p as usize][..],
                        };
                        assert_eq!(parent, &w[..w.len() - 1]);
                    }
                }
            }
        }
    }

    #[test]
    fn every_pattern_is_a_triangulation() {
        for valence in MIN_VALENCE..=MAX_VALENCE {
            for t0 in [Tag::Plus, Tag::Minus] {
                for t1 in [Tag::Plus, Tag::Minus] {
                    let p = pattern(valence, t0, t1);
                    let mut polygon_edges = vec![0; valence];
                    for c in 0..3 * p.triangle_count() {
                        let t = p.twin[c];
                        if t >= NO_TWIN {
                            polygon_edges[(t - NO_TWIN) as usize] += 1;
                        } else {
                            assert_eq!(p.twin[t as usize] as usize, c);
                        }
                    }
                    assert!(polygon_edges.iter().all(|&n| n == 1));
                    let g = 3 * p.gate_triangle as usize + p.gate_corner as usize;
                    assert_eq!(p.corner_vertex(g), 0);
                    assert_eq!(p.twin[g], NO_TWIN);
                }
            }
        }
    }
}
