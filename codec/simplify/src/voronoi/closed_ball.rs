//! The closed-ball property (seed 001, Prop. 3.1, with the repairs of
//! SEEDS.md 001) of the diagram that labels every vertex with its nearest
//! site.
//!
//! A cell's region is the union of its vertices' barycentric dual cells:
//! always a surface with border (its corners are edge midpoints and face
//! centres, where the pieces meet in fans), and it retracts onto the
//! subcomplex the cell's vertices span. So it is a disc exactly when that
//! subcomplex is connected with χ = V − E + F = 1 (a whole closed
//! component has χ = 2, an annulus 0). Two cells meet along the Voronoi
//! edge pieces inside the faces that hold both labels; they form one curve
//! when those crossing edges are linked through such faces into one chain,
//! and (the surface is closed: holes are coned) it is an arc exactly when
//! it ends in two Voronoi vertices, the faces with three labels. Three
//! cells must meet in one point: one face for each triple of labels, which
//! also keeps duplicate faces out of the dual.

use std::collections::HashMap;

use vitrine_geodesic::{Surface, UNREACHED};

/// Which part of the diagram fails, by site labels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Violation {
    /// The cell is not a disc.
    Cell(u32),
    /// The two cells meet in more than one curve, or in a closed one.
    Pair(u32, u32),
    /// The three cells meet in more than one point.
    Triple([u32; 3]),
}

/// Every violation of `labels` (one per vertex) over `surface`.
pub(super) fn violations(surface: &Surface, labels: &[u32], sites: usize) -> Vec<Violation> {
    let mut cells = CellCounts::new(surface.vertex_count(), sites);
    let mut chains = Forest::new(surface.edge_ids());
    let mut pairs: HashMap<(u32, u32), Curve> = HashMap::new();
    let mut triples: HashMap<[u32; 3], u32> = HashMap::new();
    for v in 0..surface.vertex_count() as u32 {
        let lv = labels[v as usize];
        if lv == UNREACHED {
            continue;
        }
        cells.vertices[lv as usize] += 1;
        for &w in surface.neighbours(v).0 {
            if w > v && labels[w as usize] == lv {
                cells.edges[lv as usize] += 1;
                cells.spans.join(v, w);
            }
        }
    }
    for t in surface.triangles() {
        let l = t.map(|v| labels[v as usize]);
        if l.contains(&UNREACHED) {
            continue; // a caller's bug, not the input's: every face is labelled
        }
        let crossing: Vec<usize> = (0..3).filter(|&k| l[k] != l[(k + 1) % 3]).collect();
        match crossing.len() {
            0 => cells.faces[l[0] as usize] += 1,
            2 => {
                let edge = |k: usize| surface.edge_id(t[k], t[(k + 1) % 3]).unwrap_or(0);
                chains.join(edge(crossing[0]), edge(crossing[1]));
            }
            _ => {
                let mut key = l;
                key.sort_unstable();
                *triples.entry(key).or_default() += 1;
                for (a, b) in [(key[0], key[1]), (key[1], key[2]), (key[0], key[2])] {
                    pairs.entry((a, b)).or_default().ends += 1;
                }
            }
        }
    }
    for v in 0..surface.vertex_count() as u32 {
        for &w in surface.neighbours(v).0 {
            let (lv, lw) = (labels[v as usize], labels[w as usize]);
            if w > v && lv != lw {
                let chain = chains.find(surface.edge_id(v, w).unwrap_or(0));
                let curve = pairs.entry((lv.min(lw), lv.max(lw))).or_default();
                match curve.chain {
                    None => curve.chain = Some(chain),
                    Some(c) if c != chain => curve.split = true,
                    Some(_) => {}
                }
            }
        }
    }
    let mut out = cells.violations(labels);
    let mut bad_pairs: Vec<_> = pairs
        .into_iter()
        .filter(|(_, c)| c.split || c.ends != 2)
        .map(|(p, _)| p)
        .collect();
    bad_pairs.sort_unstable();
    out.extend(bad_pairs.into_iter().map(|(a, b)| Violation::Pair(a, b)));
    let mut bad_triples: Vec<_> = triples
        .into_iter()
        .filter(|&(_, n)| n != 1)
        .map(|(t, _)| t)
        .collect();
    bad_triples.sort_unstable();
    out.extend(bad_triples.into_iter().map(Violation::Triple));
    out
}

/// Where two cells meet: the chain of crossing edges, whether there is
/// more than one, and how many Voronoi vertices end it.
#[derive(Default)]
struct Curve {
    chain: Option<u32>,
    split: bool,
    ends: u32,
}

/// V, E and F of the subcomplex each cell spans, and its connectivity.
struct CellCounts {
    vertices: Vec<i64>,
    edges: Vec<i64>,
    faces: Vec<i64>,
    spans: Forest,
}

impl CellCounts {
    fn new(vertices: usize, sites: usize) -> Self {
        CellCounts {
            vertices: vec![0; sites],
            edges: vec![0; sites],
            faces: vec![0; sites],
            spans: Forest::new(vertices),
        }
    }

    fn violations(&mut self, labels: &[u32]) -> Vec<Violation> {
        let sites = self.vertices.len();
        let mut root = vec![UNREACHED; sites];
        let mut split = vec![false; sites];
        for (v, &l) in labels.iter().enumerate() {
            if l == UNREACHED {
                continue;
            }
            let r = self.spans.find(v as u32);
            match root[l as usize] {
                UNREACHED => root[l as usize] = r,
                s if s != r => split[l as usize] = true,
                _ => {}
            }
        }
        (0..sites)
            .filter(|&s| {
                let chi = self.vertices[s] - self.edges[s] + self.faces[s];
                self.vertices[s] > 0 && (split[s] || chi != 1)
            })
            .map(|s| Violation::Cell(s as u32))
            .collect()
    }
}

/// Union–find with path halving.
struct Forest {
    parent: Vec<u32>,
}

impl Forest {
    fn new(n: usize) -> Self {
        Forest {
            parent: (0..n as u32).collect(),
        }
    }

    fn find(&mut self, mut x: u32) -> u32 {
        while self.parent[x as usize] != x {
            let p = self.parent[self.parent[x as usize] as usize];
            self.parent[x as usize] = p;
            x = p;
        }
        x
    }

    fn join(&mut self, a: u32, b: u32) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.parent[a.max(b) as usize] = a.min(b);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Labels of the sphere's vertices by the nearest of `directions`.
    fn nearest_of(surface: &Surface, directions: &[[f64; 3]]) -> Vec<u32> {
        (0..surface.vertex_count() as u32)
            .map(|v| {
                let p = surface.position(v);
                let score = |d: &[f64; 3]| p.dot(glam::DVec3::from(*d));
                (0..directions.len())
                    .max_by(|&a, &b| score(&directions[a]).total_cmp(&score(&directions[b])))
                    .unwrap() as u32
            })
            .collect()
    }

    fn sphere() -> Surface {
        Surface::new(&vitrine_samples::icosphere(3)).unwrap()
    }

    #[test]
    fn four_cells_like_a_tetrahedron_have_the_property() {
        let s = sphere();
        let tetra = [
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ];
        assert_eq!(violations(&s, &nearest_of(&s, &tetra), 4), vec![]);
    }

    #[test]
    fn one_cell_is_a_sphere_two_meet_in_a_loop_three_in_two_points() {
        let s = sphere();
        let one = vec![0; s.vertex_count()];
        assert_eq!(violations(&s, &one, 1), vec![Violation::Cell(0)]);
        let two = nearest_of(&s, &[[0.3, 0.1, 1.0], [-0.3, -0.1, -1.0]]);
        assert_eq!(violations(&s, &two, 2), vec![Violation::Pair(0, 1)]);
        // Three wedges around an axis: each pair meets in an arc from pole
        // to pole, and all three at both poles.
        let wedges = nearest_of(
            &s,
            &[[1.0, 0.05, 0.1], [-0.5, 0.87, 0.1], [-0.5, -0.87, 0.1]],
        );
        let found = violations(&s, &wedges, 3);
        assert!(found.contains(&Violation::Triple([0, 1, 2])), "{found:?}");
        assert!(
            !found.iter().any(|v| matches!(v, Violation::Cell(_))),
            "{found:?}"
        );
    }

    #[test]
    fn a_cell_in_two_pieces_or_an_annulus_is_not_a_disc() {
        let s = sphere();
        // Cell 0 at both poles, cell 1 the band between: 0 is in two
        // pieces, 1 is an annulus (χ = 0).
        let labels: Vec<u32> = (0..s.vertex_count() as u32)
            .map(|v| u32::from(s.position(v).z.abs() < 0.5))
            .collect();
        let found = violations(&s, &labels, 2);
        assert!(found.contains(&Violation::Cell(0)), "{found:?}");
        assert!(found.contains(&Violation::Cell(1)), "{found:?}");
    }
}
