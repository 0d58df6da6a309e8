//! The standalone multiresolution on generated meshes: every pass leaves
//! an oriented 2-manifold of the same topology, borders and features stay
//! where they were, and each collapse variant stops exactly at its target.

#[path = "simplifier/surface.rs"]
mod surface;

use std::collections::HashSet;

use surface::{corners, Surface};
use vitrine_codec::{Error, IndexedMesh};
use vitrine_mesh::repair::check_manifold;
use vitrine_samples::{
    add_noise, grid, icosphere, merge, paint, plate_with_tunnels, punch_holes, torus,
};
use vitrine_simplify::{
    border_vertices, simplify, simplify_with, Cleanup, Collapse, FeatureThreshold, Features,
    Placement, SimplifyOptions, StopReason, Target,
};

const VARIANTS: [Collapse; 3] = [Collapse::Edge, Collapse::HalfEdge, Collapse::Triangle];

/// Every collapse variant with each placement.
fn settings() -> impl Iterator<Item = (Collapse, Placement)> {
    VARIANTS
        .into_iter()
        .flat_map(|c| [Placement::Seed, Placement::Quadric].map(|p| (c, p)))
}

fn holed_grid() -> IndexedMesh {
    punch_holes(&grid(40), &[[10.0, 12.0, 0.0], [28.0, 26.0, 0.0]], 4.5)
}

fn noisy_torus() -> IndexedMesh {
    let mut mesh = torus(64, 32, 1.0, 0.35);
    add_noise(&mut mesh, 0.002, 11);
    mesh
}

/// The shapes the issue names, each with a name for failure messages.
fn corpus() -> Vec<(&'static str, IndexedMesh)> {
    vec![
        ("torus", torus(64, 32, 1.0, 0.35)),
        ("icosphere", icosphere(4)),
        ("plate genus 3", plate_with_tunnels(3, 6)),
        ("holed grid", holed_grid()),
        (
            "torus + sphere",
            merge(&[torus(48, 24, 1.0, 0.3), icosphere(3)], 3.0),
        ),
        ("noisy torus", noisy_torus()),
    ]
}

fn options(collapse: Collapse, target: Target) -> SimplifyOptions {
    SimplifyOptions {
        collapse,
        target,
        ..SimplifyOptions::default()
    }
}

fn options_at(collapse: Collapse, placement: Placement, target: Target) -> SimplifyOptions {
    SimplifyOptions {
        placement,
        ..options(collapse, target)
    }
}

/// Manifold, no duplicate or degenerate face (`check_manifold`), and no
/// face turned more than 90° from the input around its centroid: the input
/// faces within half its longest edge beyond the nearest one (the patch
/// it stands for; the nearest face alone is arbitrary beside a crease).
/// Faces in `checked` (by their corners' bits) passed in an earlier pass.
fn assert_sound(name: &str, input: &Surface, mesh: &IndexedMesh, checked: &mut HashSet<[u32; 9]>) {
    if let Err(e) = check_manifold(mesh) {
        panic!("{name}: {e}");
    }
    for (f, t) in mesh.triangles.iter().enumerate() {
        let bits: Vec<u32> = t
            .iter()
            .flat_map(|&v| mesh.positions[v as usize].map(f32::to_bits))
            .collect();
        if !checked.insert(bits.try_into().unwrap()) {
            continue;
        }
        let p = corners(mesh, t);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]);
        let longest = (0..3)
            .map(|k| p[k].distance(p[(k + 1) % 3]))
            .fold(0.0, f64::max);
        let input = input.normal_near((p[0] + p[1] + p[2]) / 3.0, longest / 2.0);
        let d = normal.normalize().dot(input.normalize());
        assert!(d > 0.0, "{name}: face {f} {t:?} is flipped ({d})");
    }
}

/// V − E + F, connected components, and border loops.
fn topology(mesh: &IndexedMesh) -> (i64, usize, usize) {
    let mut edges = HashSet::new();
    let mut border = HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.insert((a.min(b), a.max(b)));
            if !border.remove(&(b, a)) {
                border.insert((a, b));
            }
        }
    }
    let chi = mesh.positions.len() as i64 - edges.len() as i64 + mesh.triangles.len() as i64;
    let mut parent: Vec<usize> = (0..mesh.positions.len()).collect();
    fn find(p: &mut [usize], mut x: usize) -> usize {
        while p[x] != x {
            p[x] = p[p[x]];
            x = p[x];
        }
        x
    }
    let union = |p: &mut Vec<usize>, a: u32, b: u32| {
        let (ra, rb) = (find(p, a as usize), find(p, b as usize));
        p[ra] = rb;
    };
    for t in &mesh.triangles {
        union(&mut parent, t[0], t[1]);
        union(&mut parent, t[1], t[2]);
    }
    let components = (0..parent.len())
        .filter(|&v| find(&mut parent, v) == v)
        .count();
    let mut loops: Vec<usize> = (0..mesh.positions.len()).collect();
    for &(a, b) in &border {
        union(&mut loops, a, b);
    }
    let on_border: HashSet<u32> = border.iter().flat_map(|&(a, b)| [a, b]).collect();
    let loops = on_border
        .iter()
        .filter(|&&v| find(&mut loops, v as usize) == v as usize)
        .count();
    (chi, components, loops)
}

#[test]
fn every_pass_leaves_a_sound_manifold_and_the_clean_up_finds_nothing() {
    for (name, mesh) in corpus() {
        let surface = Surface::new(&mesh);
        for (collapse, placement) in settings() {
            let name = format!("{name}, {collapse:?}, {placement:?}");
            let (mut passes, mut checked) = (0, HashSet::new());
            let out = simplify_with(
                &mesh,
                &options_at(collapse, placement, Target::Fraction(0.1)),
                |r, m, _| {
                    passes += 1;
                    let pass = format!("{name}, pass {passes}");
                    assert_sound(&pass, &surface, m, &mut checked);
                    assert_eq!(r.cleanup, Cleanup::default(), "{name}, pass {passes}");
                    assert_eq!(
                        (r.vertices, r.faces),
                        (m.vertex_count(), m.face_count()),
                        "{name}, pass {passes}"
                    );
                },
            )
            .unwrap();
            assert_eq!(out.passes.len(), passes, "{name}");
            assert!(passes >= 2, "{name}: {passes} passes");
        }
    }
}

#[test]
fn each_variant_stops_exactly_at_its_target() {
    let mesh = torus(64, 32, 1.0, 0.35);
    for (collapse, placement) in settings() {
        for n in [1500, 777, 301] {
            let out =
                simplify(&mesh, &options_at(collapse, placement, Target::Vertices(n))).unwrap();
            assert_eq!(
                out.stopped,
                StopReason::Target,
                "{collapse:?} {placement:?} {n}"
            );
            assert_eq!(out.mesh.vertex_count(), n, "{collapse:?} {placement:?}");
            assert_eq!(out.origin.len(), n);
            assert_eq!(
                out.mesh.face_count(),
                2 * n,
                "{collapse:?} {placement:?}: a torus has F = 2V"
            );
        }
        let out = simplify(
            &icosphere(4),
            &options_at(collapse, placement, Target::Fraction(0.25)),
        )
        .unwrap();
        assert_eq!(out.mesh.vertex_count(), (2562.0f64 * 0.25).round() as usize);
    }
}

#[test]
fn genus_components_and_border_loops_survive() {
    for (name, mesh) in corpus() {
        let before = topology(&mesh);
        for (collapse, placement) in settings() {
            let out = simplify(
                &mesh,
                &options_at(collapse, placement, Target::Fraction(0.15)),
            )
            .unwrap();
            assert_eq!(topology(&out.mesh), before, "{name}, {collapse:?}");
        }
    }
    assert_eq!(topology(&plate_with_tunnels(3, 6)).0, 2 - 2 * 3);
    assert_eq!(topology(&holed_grid()), (1 - 2, 1, 3));
}

/// The vertices on an edge with one face, counted independently of the crate.
fn open_edge_vertices(mesh: &IndexedMesh) -> HashSet<u32> {
    let mut open = HashSet::new();
    for t in &mesh.triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            if !open.remove(&(b, a)) {
                open.insert((a, b));
            }
        }
    }
    open.into_iter().flat_map(|(a, b)| [a, b]).collect()
}

#[test]
fn borders_of_a_holed_grid_are_found_exactly_and_left_bit_for_bit() {
    let mesh = holed_grid();
    let expected = open_edge_vertices(&mesh);
    let found: HashSet<u32> = border_vertices(&mesh)
        .iter()
        .enumerate()
        .filter(|(_, &b)| b)
        .map(|(v, _)| v as u32)
        .collect();
    assert_eq!(found, expected);
    assert!(expected.len() > 4 * 40, "outline and two holes");
    for (collapse, placement) in settings() {
        let out = simplify(
            &mesh,
            &options_at(collapse, placement, Target::Fraction(0.3)),
        )
        .unwrap();
        assert_eq!(
            out.stopped,
            StopReason::Target,
            "{collapse:?} {placement:?}"
        );
        let target = (0.3 * mesh.vertex_count() as f64).round() as usize;
        assert_eq!(
            out.mesh.vertex_count(),
            target,
            "{collapse:?} {placement:?}"
        );
        let kept: HashSet<u32> = out.origin.iter().copied().collect();
        for (o, &v) in out.origin.iter().enumerate() {
            if expected.contains(&v) {
                let (a, b) = (out.mesh.positions[o], mesh.positions[v as usize]);
                assert_eq!(
                    a.map(f32::to_bits),
                    b.map(f32::to_bits),
                    "{collapse:?} {placement:?}"
                );
            }
        }
        assert!(
            expected.is_subset(&kept),
            "{collapse:?} {placement:?}: a border vertex went"
        );
        let output_border: HashSet<u32> = open_edge_vertices(&out.mesh)
            .into_iter()
            .map(|o| out.origin[o as usize])
            .collect();
        assert_eq!(output_border, expected, "{collapse:?} {placement:?}");
    }
}

/// A 40 × 40 grid folded into a 90° ridge along x = 20.
fn ridge() -> IndexedMesh {
    let mut mesh = grid(40);
    for p in &mut mesh.positions {
        p[2] = -(p[0] - 20.0).abs();
    }
    mesh
}

#[test]
fn a_flat_region_simplifies_far_more_than_a_ridge() {
    let mesh = ridge();
    let interior = |p: &[f32; 3]| p[1] > 0.0 && p[1] < 40.0;
    let count = |m: &IndexedMesh, band: &dyn Fn(f32) -> bool| {
        m.positions
            .iter()
            .filter(|p| interior(p) && band((p[0] - 20.0).abs()))
            .count() as f64
    };
    let near: &dyn Fn(f32) -> bool = &|d| d <= 1.0;
    let flat: &dyn Fn(f32) -> bool = &|d| (6.0..19.0).contains(&d);
    for collapse in VARIANTS {
        let o = SimplifyOptions {
            features: Features::Keep,
            ..options(collapse, Target::Fraction(0.2))
        };
        let out = simplify(&mesh, &o).unwrap();
        let kept_near = count(&out.mesh, near) / count(&mesh, near);
        let kept_flat = count(&out.mesh, flat) / count(&mesh, flat);
        assert!(kept_near >= 0.95, "{collapse:?}: ridge kept {kept_near}");
        assert!(kept_flat <= 0.15, "{collapse:?}: flat kept {kept_flat}");
        // The crest itself is untouched, bit for bit.
        let output: HashSet<[u32; 3]> = out
            .mesh
            .positions
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect();
        for p in mesh.positions.iter().filter(|p| p[0] == 20.0) {
            assert!(
                output.contains(&p.map(f32::to_bits)),
                "{collapse:?}: crest {p:?}"
            );
        }
    }
}

#[test]
fn the_same_input_gives_the_same_output() {
    let mesh = noisy_torus();
    for collapse in VARIANTS {
        let o = options(collapse, Target::Fraction(0.2));
        let (a, b) = (simplify(&mesh, &o).unwrap(), simplify(&mesh, &o).unwrap());
        assert_eq!(a.mesh, b.mesh);
        assert_eq!(a.origin, b.origin);
        assert_eq!(a.passes, b.passes);
    }
}

#[test]
fn colours_travel_with_their_vertices() {
    let mut mesh = holed_grid();
    mesh.colors = Some(vec![[200, 40, 90]; mesh.positions.len()]);
    for collapse in VARIANTS {
        let out = simplify(&mesh, &options(collapse, Target::Fraction(0.3))).unwrap();
        let colours = out.mesh.colors.as_ref().unwrap();
        assert_eq!(colours.len(), out.mesh.vertex_count());
        assert!(
            colours.iter().all(|&c| c == [200, 40, 90]),
            "an average of equals"
        );
    }
    let mut mesh = icosphere(4);
    paint(&mut mesh);
    let input = mesh.colors.clone().unwrap();
    let out = simplify(&mesh, &options(Collapse::HalfEdge, Target::Fraction(0.3))).unwrap();
    for (o, &v) in out.origin.iter().enumerate() {
        assert_eq!(
            out.mesh.colors.as_ref().unwrap()[o],
            input[v as usize],
            "kept as is"
        );
    }
}

#[test]
fn features_or_topology_can_stop_it_short_and_it_says_so() {
    // A 90° threshold frees everything but borders; a 40 × 40 grid whose
    // borders are all its outline cannot go below them.
    let mut o = options(Collapse::Edge, Target::Vertices(10));
    o.threshold = FeatureThreshold::Degrees(90.0);
    let out = simplify(&grid(40), &o).unwrap();
    assert_eq!(out.stopped, StopReason::NoCandidate);
    assert!(out.mesh.vertex_count() >= 160);
    o.max_passes = 1;
    let out = simplify(&grid(40), &o).unwrap();
    assert_eq!((out.stopped, out.passes.len()), (StopReason::MaxPasses, 1));
    let out = simplify(
        &icosphere(2),
        &options(Collapse::Edge, Target::Vertices(1000)),
    )
    .unwrap();
    assert_eq!((out.stopped, out.passes.len()), (StopReason::Target, 0));
}

#[test]
fn bad_parameters_and_non_manifold_input_are_refused() {
    let o = options(Collapse::Edge, Target::Fraction(1.5));
    assert!(matches!(
        simplify(&icosphere(1), &o),
        Err(Error::Parameter(_))
    ));
    let mut fin = grid(2);
    let t = fin.triangles[0];
    fin.positions.push([0.5, 0.5, 1.0]);
    fin.triangles.push([t[0], t[2], 9]); // a third face on the diagonal (0, 4)
    let o = SimplifyOptions::default();
    assert!(matches!(simplify(&fin, &o), Err(Error::Unsupported(_))));
    assert_eq!("half-edge".parse::<Collapse>().unwrap(), Collapse::HalfEdge);
    assert_eq!("25%".parse::<Target>().unwrap(), Target::Fraction(0.25));
    assert_eq!("5000".parse::<Target>().unwrap(), Target::Vertices(5000));
    for bad in ["", "-3", "120%", "half"] {
        assert!(bad.parse::<Target>().is_err(), "{bad}");
    }
    assert!("vertex".parse::<Collapse>().is_err());
}

#[test]
fn features_go_last_when_the_target_needs_them() {
    // The ridge at 12 % (the 160 border vertices are 9.5 %, the border
    // and the ridge band 16 %): keeping every feature vertex stops short;
    // letting them go last reaches the target exactly, the flat sides gone
    // first.
    let mesh = ridge();
    let target = (0.12 * mesh.vertex_count() as f64).round() as usize;
    for collapse in VARIANTS {
        let keep = SimplifyOptions {
            features: Features::Keep,
            ..options(collapse, Target::Fraction(0.12))
        };
        let kept = simplify(&mesh, &keep).unwrap();
        assert_eq!(kept.stopped, StopReason::NoCandidate, "{collapse:?}");
        assert!(kept.mesh.vertex_count() > target, "{collapse:?}");
        assert_eq!(kept.final_threshold_radians, kept.threshold_radians);
        let last = simplify(&mesh, &options(collapse, Target::Fraction(0.12))).unwrap();
        assert_eq!(last.stopped, StopReason::Target, "{collapse:?}");
        assert_eq!(last.mesh.vertex_count(), target, "{collapse:?}");
        assert!(last.final_threshold_radians > last.threshold_radians);
        let border = border_vertices(&mesh);
        let interior = last
            .origin
            .iter()
            .filter(|&&v| !border[v as usize])
            .map(|&v| (mesh.positions[v as usize][0] - 20.0).abs());
        let (near, far) = interior.fold(
            (0, 0),
            |(n, f), d| {
                if d <= 1.0 {
                    (n + 1, f)
                } else {
                    (n, f + 1)
                }
            },
        );
        // Shares of the interior's 3 ridge columns and 36 others (39 rows).
        let (near, far) = (f64::from(near) / 117.0, f64::from(far) / 1404.0);
        assert!(
            near > 4.0 * far,
            "{collapse:?}: {near} of the ridge, {far} of the rest"
        );
    }
}

#[test]
fn quadric_placement_stays_closer_to_a_smooth_surface() {
    // A sphere at 5 %: the seed's midpoints cut inside the surface, the
    // quadric optimum hugs it. Distance to the unit sphere, RMS over 15
    // points per output face (corners, edge thirds, centroid and more).
    let mesh = icosphere(5);
    let rms = |m: &IndexedMesh| {
        let (mut sum, mut n) = (0.0, 0.0);
        for t in &m.triangles {
            let p = corners(m, t);
            for i in 0..=4 {
                for j in 0..=4 - i {
                    let (a, b) = (f64::from(i) / 4.0, f64::from(j) / 4.0);
                    let x = p[0] + (p[1] - p[0]) * a + (p[2] - p[0]) * b;
                    sum += (x.length() - 1.0).powi(2);
                    n += 1.0;
                }
            }
        }
        (sum / n).sqrt()
    };
    for collapse in VARIANTS {
        let seed = simplify(&mesh, &options(collapse, Target::Fraction(0.05))).unwrap();
        let quadric = simplify(
            &mesh,
            &options_at(collapse, Placement::Quadric, Target::Fraction(0.05)),
        )
        .unwrap();
        assert_eq!(seed.mesh.vertex_count(), quadric.mesh.vertex_count());
        let (s, q) = (rms(&seed.mesh), rms(&quadric.mesh));
        // Half-edge collapses keep input positions (only their order
        // moves). Triangle collapses that chose among the face's centroid
        // and corners, unpriced, kept 0.64 of the seed's distance; at the
        // summed quadric's minimum and cheapest first, 0.22.
        let bound = if collapse == Collapse::HalfEdge {
            0.75
        } else {
            0.5
        };
        assert!(q < bound * s, "{collapse:?}: quadric {q}, seed {s}");
    }
}

#[test]
fn a_plate_keeps_its_sharp_edges_under_quadric_placement() {
    // Flat faces and 90° edges: quadric simplification loses nothing at 10
    // and 5 %. A vertex whose cheap merges were refused used to take its
    // dearest one across an edge of the plate (8 % of the diagonal).
    // Triangle collapses went to the centroid or a corner, unpriced and
    // uncapped, and cut its edges by 6–9 %.
    let plate = plate_with_tunnels(3, 6);
    for collapse in VARIANTS {
        for fraction in [0.10, 0.05] {
            let out = simplify(
                &plate,
                &options_at(collapse, Placement::Quadric, Target::Fraction(fraction)),
            )
            .unwrap();
            assert_eq!(out.stopped, StopReason::Target);
            let h = vitrine_quality::metrics::hausdorff(&plate, &out.mesh, 50_000).relative();
            assert!(
                h < 1e-4,
                "{collapse:?} at {fraction}: Hausdorff {h} over the diagonal"
            );
        }
    }
}
