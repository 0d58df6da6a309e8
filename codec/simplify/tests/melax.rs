//! Melax LOD chains (seed 003) on generated meshes: exact level sizes
//! ⌊n·p/100⌋, manifold levels of the input's topology, no flipped face in
//! any level or frame, borders kept, UV seams thinned only along themselves.

use std::collections::HashSet;

use glam::DVec3;
use vitrine_codec::IndexedMesh;
use vitrine_mesh::export::sample_md2;
use vitrine_mesh::repair::check_manifold;
use vitrine_samples::{grid, icosphere, punch_holes, torus};
use vitrine_simplify::melax::{
    compact, melax_chain, melax_simplify, MelaxChain, MelaxCost, MelaxModel,
};
use vitrine_simplify::{border_vertices, Target};

const LEVELS: [u32; 5] = [100, 80, 60, 40, 20];

fn chain_of(mesh: &IndexedMesh) -> MelaxChain {
    let frames = [mesh.positions.clone()];
    melax_chain(&MelaxModel {
        triangles: &mesh.triangles,
        frames: &frames,
        corner_uvs: None,
        cost: MelaxCost::Sine,
    })
    .unwrap()
}

fn euler(mesh: &IndexedMesh) -> i64 {
    let mut edges = HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    mesh.positions.len() as i64 - edges.len() as i64 + mesh.triangles.len() as i64
}

/// Area-weighted vertex normals of `triangles` over `positions`.
fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<DVec3> {
    let p = |v: u32| DVec3::from(positions[v as usize].map(f64::from));
    let mut n = vec![DVec3::ZERO; positions.len()];
    for &[a, b, c] in triangles {
        let f = (p(b) - p(a)).cross(p(c) - p(a));
        for v in [a, b, c] {
            n[v as usize] += f;
        }
    }
    n
}

/// Faces of a level (input indices) facing away from the input around
/// their corners.
fn flipped(positions: &[[f32; 3]], input: &[[u32; 3]], level: &[[u32; 3]]) -> usize {
    let reference = vertex_normals(positions, input);
    let p = |v: u32| DVec3::from(positions[v as usize].map(f64::from));
    level
        .iter()
        .filter(|&&[a, b, c]| {
            let n = (p(b) - p(a)).cross(p(c) - p(a));
            let r: DVec3 = [a, b, c]
                .iter()
                .map(|&v| reference[v as usize].normalize_or_zero())
                .sum();
            n.dot(r) <= 0.0
        })
        .count()
}

#[test]
fn levels_have_exactly_n_p_over_100_vertices_and_stay_manifold() {
    for (name, mesh) in [
        ("torus", torus(40, 20, 1.0, 0.35)),
        ("icosphere", icosphere(3)),
    ] {
        let chain = chain_of(&mesh);
        let n = mesh.positions.len();
        for p in LEVELS {
            let level = chain.level(chain.percent(p)).unwrap();
            let (out, origin) = compact(&mesh, &level.triangles);
            assert_eq!(out.positions.len(), n * p as usize / 100, "{name} {p} %");
            assert_eq!(level.vertices, out.positions.len());
            check_manifold(&out).unwrap_or_else(|e| panic!("{name} {p} %: {e}"));
            assert_eq!(euler(&out), euler(&mesh), "{name} {p} %: topology");
            assert_eq!(
                flipped(&mesh.positions, &mesh.triangles, &level.triangles),
                0,
                "{name} {p} %"
            );
            // Positions never move.
            for (o, &v) in out.positions.iter().zip(&origin) {
                assert_eq!(*o, mesh.positions[v as usize]);
            }
        }
        // One vertex per collapse, and the chain is deterministic.
        assert_eq!(chain.collapses, chain_of(&mesh).collapses);
        assert!(
            chain.min_vertices() <= n / 10,
            "{name}: stops at {}",
            chain.min_vertices()
        );
    }
}

#[test]
fn borders_are_locked() {
    let mesh = punch_holes(&grid(24), &[[12.0, 12.0, 0.0]], 4.0);
    let mesh = vitrine_samples::compact(mesh);
    let border = border_vertices(&mesh);
    let out = melax_simplify(&mesh, Target::Fraction(0.2), MelaxCost::Sine).unwrap();
    let kept: HashSet<u32> = out.origin.iter().copied().collect();
    for (v, &b) in border.iter().enumerate() {
        if b {
            assert!(kept.contains(&(v as u32)), "border vertex {v} collapsed");
        }
    }
    check_manifold(&out.mesh).unwrap();
}

#[test]
fn a_flat_region_goes_before_a_crease() {
    // A cube-ish sphere has no flat region; a grid folded along a ridge does.
    let mut mesh = grid(16);
    for p in &mut mesh.positions {
        p[2] = -(p[0] - 8.0).abs();
    }
    let frames = [mesh.positions.clone()];
    let chain = melax_chain(&MelaxModel {
        triangles: &mesh.triangles,
        frames: &frames,
        corner_uvs: None,
        cost: MelaxCost::Sine,
    })
    .unwrap();
    // Sliding along the ridge (x = 8) or within a flank is free; leaving
    // the ridge is not, and comes after every free collapse.
    let ridge = |v: u32| mesh.positions[v as usize][0] == 8.0;
    let first_off = chain
        .collapses
        .iter()
        .position(|c| ridge(c.gone) && !ridge(c.keep))
        .unwrap_or(chain.collapses.len());
    assert!(
        first_off > 200,
        "a ridge vertex left the ridge at collapse {first_off}"
    );
}

/// Triangles (counter-clockwise), corner texture ids, frames.
type Textured = (Vec<[u32; 3]>, Vec<[u32; 3]>, Vec<Vec<[f32; 3]>>);

/// The MD2 sample's triangles (counter-clockwise), corner texture ids and frames.
fn md2_model(rings: u32, sides: u32, frames: usize) -> Textured {
    let model = sample_md2(rings, sides, frames);
    let triangles = model.mesh_triangles();
    let corner_uvs: Vec<[u32; 3]> = model
        .triangles
        .iter()
        .map(|t| [t.st[0], t.st[2], t.st[1]].map(u32::from))
        .collect();
    let frames = model.frames.iter().map(|f| f.positions()).collect();
    (triangles, corner_uvs, frames)
}

/// Checks every level of `chain` against its textured input: exact sizes,
/// no flip in any frame, manifold; every corner keeps a texture coordinate
/// its vertex had; seams neither grow nor are crossed (an edge whose faces
/// disagree on its ends' coordinates lies along an input seam), and the
/// seam junctions stay. Returns the seam vertices gone at each level.
fn assert_textured_levels(
    chain: &MelaxChain,
    triangles: &[[u32; 3]],
    corner_uvs: &[[u32; 3]],
    frames: &[Vec<[f32; 3]>],
    levels: &[u32],
) -> Vec<usize> {
    let pairs: HashSet<(u32, u32)> = triangles
        .iter()
        .zip(corner_uvs)
        .flat_map(|(t, s)| (0..3).map(move |k| (t[k], s[k])))
        .collect();
    let ids = |v: u32| pairs.iter().filter(|p| p.0 == v).count();
    let seam: HashSet<u32> = (0..frames[0].len() as u32)
        .filter(|&v| ids(v) > 1)
        .collect();
    let junctions: HashSet<u32> = seam.iter().copied().filter(|&v| ids(v) > 2).collect();
    let mut seam_gone = Vec::new();
    for &p in levels {
        let level = chain.level(chain.percent(p)).unwrap();
        let uvs = level.corner_uvs.as_ref().unwrap();
        let used: HashSet<u32> = level.triangles.iter().flatten().copied().collect();
        assert_eq!(used.len(), chain.percent(p), "{p} %");
        assert!(
            junctions.iter().all(|v| used.contains(v)),
            "{p} %: a seam junction went"
        );
        seam_gone.push(seam.iter().filter(|v| !used.contains(v)).count());
        for (t, s) in level.triangles.iter().zip(uvs) {
            for k in 0..3 {
                assert!(
                    pairs.contains(&(t[k], s[k])),
                    "{p} %: corner {:?}",
                    (t[k], s[k])
                );
            }
        }
        // Each edge's coordinates at its two ends, per face.
        let mut sides: std::collections::HashMap<(u32, u32), Vec<(u32, u32)>> = Default::default();
        for (t, s) in level.triangles.iter().zip(uvs) {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (ua, ub) = (s[k], s[(k + 1) % 3]);
                let key = if a < b {
                    ((a, b), (ua, ub))
                } else {
                    ((b, a), (ub, ua))
                };
                sides.entry(key.0).or_default().push(key.1);
            }
        }
        for ((a, b), ends) in &sides {
            if ends.len() == 2 && ends[0] != ends[1] {
                assert!(
                    seam.contains(a) && seam.contains(b),
                    "{p} %: texture crosses edge {a}–{b} off the input's seams"
                );
            }
        }
        for (k, f) in frames.iter().enumerate() {
            assert_eq!(
                flipped(f, triangles, &level.triangles),
                0,
                "{p} % frame {k}"
            );
        }
        let mesh = IndexedMesh {
            positions: frames[0].clone(),
            colors: None,
            triangles: level.triangles.clone(),
        };
        check_manifold(&compact(&mesh, &level.triangles).0).unwrap();
    }
    seam_gone
}

#[test]
fn animated_models_share_one_collapse_map_and_keep_their_seams() {
    let (triangles, corner_uvs, frames) = md2_model(24, 16, 6);
    let chain = melax_chain(&MelaxModel {
        triangles: &triangles,
        frames: &frames,
        corner_uvs: Some(&corner_uvs),
        cost: MelaxCost::Sine,
    })
    .unwrap();
    let seam_gone = assert_textured_levels(&chain, &triangles, &corner_uvs, &frames, &LEVELS);
    // The two seam loops (24 + 16 − 1 vertices) thin out along themselves.
    assert!(seam_gone[LEVELS.len() - 1] > 0, "{seam_gone:?}");
}

#[test]
fn a_model_of_many_uv_islands_reaches_20_percent() {
    // The sample's skin cut into 4 × 4-quad islands: 168 of its 384
    // vertices lie on seams, so locking them stopped Melax at 44 %.
    let (rings, sides) = (24u32, 16u32);
    let (triangles, corner_uvs, frames) = md2_model(rings, sides, 2);
    let grid_of = |id: u32| (id / (sides + 1), id % (sides + 1));
    let mut ids: std::collections::HashMap<(u32, u32, u32), u32> = Default::default();
    let islands: Vec<[u32; 3]> = corner_uvs
        .iter()
        .map(|s| {
            let corners = s.map(grid_of);
            let i0 = corners.iter().map(|c| c.0).min().unwrap();
            let j0 = corners.iter().map(|c| c.1).min().unwrap();
            let island = (i0 / 4) * 100 + j0 / 4;
            corners.map(|(i, j)| {
                let next = ids.len() as u32;
                *ids.entry((island, i, j)).or_insert(next)
            })
        })
        .collect();
    let chain = melax_chain(&MelaxModel {
        triangles: &triangles,
        frames: &frames,
        corner_uvs: Some(&islands),
        cost: MelaxCost::Sine,
    })
    .unwrap();
    assert!(
        chain.min_vertices() <= chain.percent(20),
        "stops at {}",
        chain.min_vertices()
    );
    let seam_gone = assert_textured_levels(&chain, &triangles, &islands, &frames, &LEVELS);
    assert!(seam_gone[LEVELS.len() - 1] > 80, "{seam_gone:?}");
}

#[test]
fn the_target_is_reached_exactly_or_the_stop_is_said() {
    let mesh = torus(24, 12, 1.0, 0.3);
    let out = melax_simplify(&mesh, Target::Vertices(50), MelaxCost::Sine).unwrap();
    assert!(out.reached);
    assert_eq!(out.mesh.positions.len(), 50);
    let chain = chain_of(&mesh);
    let e = chain
        .level(chain.min_vertices().saturating_sub(1))
        .unwrap_err();
    assert!(e.to_string().contains("Melax stops at"), "{e}");
}

/// A smooth, closed surface with no crease, flat in some places and curved
/// in others, as a scan of a face or a vase is: an icosphere with low bumps,
/// stretched to an ellipsoid of axes 3 : 1 : ⅓.
fn smooth_blob() -> IndexedMesh {
    let mut mesh = icosphere(5);
    for p in &mut mesh.positions {
        let [x, y, z] = p.map(f64::from);
        let r = 1.0 + 0.12 * (2.0 * x).sin() * (3.0 * y).cos() + 0.08 * (2.5 * z).sin();
        *p = [3.0 * x * r, y * r, z * r / 3.0].map(|c| c as f32);
    }
    mesh
}

#[test]
fn the_sine_crease_term_keeps_a_smooth_surface_closer_than_the_seeds() {
    // The seed's (1 − f·n)/2 is second order in the crease angle: on a
    // smooth surface its collapses look nearly free and pile up in one
    // patch. sin(θ/2) is first order, and spreads them.
    let mesh = smooth_blob();
    let n = mesh.positions.len();
    let frames = [mesh.positions.clone()];
    let chain = |cost| {
        melax_chain(&MelaxModel {
            triangles: &mesh.triangles,
            frames: &frames,
            corner_uvs: None,
            cost,
        })
        .unwrap()
    };
    let (sine, seed) = (chain(MelaxCost::Sine), chain(MelaxCost::Seed));
    assert_ne!(sine.collapses, seed.collapses);
    // Measured: sin(θ/2) comes to 0.67, 0.53 and 0.44 of the seed's distance.
    for p in [40, 20, 5] {
        let distance = |chain: &MelaxChain| {
            let level = chain.level(chain.percent(p)).unwrap();
            let (out, _) = compact(&mesh, &level.triangles);
            assert_eq!(out.positions.len(), n * p as usize / 100);
            check_manifold(&out).unwrap();
            vitrine_quality::metrics::hausdorff(&mesh, &out, 50_000).relative()
        };
        let (h_sine, h_seed) = (distance(&sine), distance(&seed));
        eprintln!("{p} %: sine {h_sine:.5}, seed {h_seed:.5}");
        assert!(
            h_sine < 0.75 * h_seed,
            "{p} %: sin(θ/2) {h_sine:.5} against the seed's {h_seed:.5}"
        );
    }
}
