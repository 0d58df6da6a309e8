//! Clip partners (seed 002, §4): which splats on a crease cut each other,
//! how (union or intersection of half-spaces), and the planes packed for
//! the GPU.
//!
//! # GPU layout
//!
//! [`Clipping::planes`] is a flat `f32` array of planes, [`PLANE_FLOATS`]
//! (4) floats each: `(a, b, c, d)`; a fragment at P is clipped by the plane
//! when `a·P.x + b·P.y + c·P.z + d > 0`. The sign is folded in: convex
//! partners store (n_j, −n_j·C_j), concave ones its negation. One RGBA32F
//! texel per plane. [`Clipping::clip`] has one `u32` per splat:
//!
//! | bits | meaning |
//! |---|---|
//! | 0–3 | number of planes (0–8; 0 = never clipped) |
//! | 4–5 | [`ClipMode`]: 1 union (clipped if any plane clips), 2 intersection (clipped if all do) |
//! | 6–31 | index of the splat's first plane in `planes` (in planes, not floats) |
//!
//! # Corners
//!
//! Near a corner a splat's partners can lie on several surfaces, some
//! meeting it at a convex edge and some at a concave one (the inner corner
//! of an L-shaped block). One classification of the whole set is then
//! wrong for part of it: concave partners taken as convex cut away the
//! splat's visible half. The seed leaves this open (§7.2) and proposes
//! the split done here: the partners are grouped by surface id, each group
//! is classified (eq. 4.13–4.14), and where the groups disagree (one
//! concave, another convex) the splat is dropped from clipping. It keeps
//! its partners but gets no planes: it may overshoot by up to its radius,
//! which a hole would not forgive. Where the groups agree, the whole set is
//! classified as before (a reflex corner of one face, where two convex
//! groups meet, needs the intersection that only the joint set gives).

use super::{cross, dot, sub, Graph, SplatOptions};

/// What clipping needs to know about the cloud besides the graph.
#[derive(Clone, Copy, Debug)]
pub struct ClipInput<'a> {
    pub positions: &'a [[f32; 3]],
    pub normals: &'a [[f32; 3]],
    pub radii: &'a [f32],
    /// From [`super::surface_ids`]: partners are grouped by them.
    pub surface_ids: &'a [u32],
}

/// Floats per packed plane.
pub const PLANE_FLOATS: usize = 4;

/// How a splat combines its partners' half-spaces (eq. 4.15).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
pub enum ClipMode {
    None = 0,
    /// Clipped where any partner plane clips.
    Union = 1,
    /// Clipped only where every partner plane clips.
    Intersection = 2,
}

/// The clip partners of every splat and their packed planes.
#[derive(Clone, Debug, Default)]
pub struct Clipping {
    /// Splats on a crease (an angular gap in their continuous neighbours)
    /// with at least one sharp edge.
    pub candidates: usize,
    /// Splats with partners whose surface-id groups disagree (see the
    /// module comment): partners kept, no planes.
    pub mixed_corners: usize,
    /// Partners per splat as rows: `partners[offsets[i]..offsets[i + 1]]`.
    pub offsets: Vec<u32>,
    pub partners: Vec<u32>,
    /// One per splat, see the module comment.
    pub clip: Vec<u32>,
    /// Packed planes, see the module comment.
    pub planes: Vec<f32>,
}

impl Clipping {
    pub fn partners_of(&self, i: usize) -> &[u32] {
        &self.partners[self.offsets[i] as usize..self.offsets[i + 1] as usize]
    }

    pub fn mode(&self, i: usize) -> ClipMode {
        match (self.clip[i] >> 4) & 3 {
            1 => ClipMode::Union,
            2 => ClipMode::Intersection,
            _ => ClipMode::None,
        }
    }
}

/// A unit vector orthogonal to `n`, and `n × it`.
fn tangent_basis(n: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let a = if n[0].abs() < 0.9 {
        [1.0, 0.0, 0.0]
    } else {
        [0.0, 1.0, 0.0]
    };
    let t = cross(n, a);
    let l = dot(t, t).sqrt();
    let t = t.map(|v| v / l);
    (t, cross(n, t))
}

/// Whether splat i lies on a crease: its continuous neighbours, seen around
/// n_i (eq. 4.2), leave an angular gap wider than `gap`.
fn on_crease(
    i: usize,
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    graph: &Graph,
    opts: &SplatOptions,
    angles: &mut Vec<f32>,
) -> bool {
    let (t1, t2) = tangent_basis(normals[i]);
    angles.clear();
    for &j in graph.neighbours(i) {
        let j = j as usize;
        if dot(normals[i], normals[j]) >= opts.sharp_threshold {
            let d = sub(positions[j], positions[i]);
            angles.push(dot(d, t2).atan2(dot(d, t1)));
        }
    }
    if angles.is_empty() {
        return true;
    }
    angles.sort_unstable_by(f32::total_cmp);
    let wrap = angles[0] + std::f32::consts::TAU - angles[angles.len() - 1];
    let widest = angles.windows(2).map(|w| w[1] - w[0]).fold(wrap, f32::max);
    widest > opts.crease_gap
}

/// The parameter interval along the line `p + t·d` (|d| = 1) inside the
/// disc of radius `r` around the origin of its plane (the line lies in it).
fn disc_interval(p: [f32; 3], d: [f32; 3], r: f32) -> Option<(f32, f32)> {
    let b = dot(p, d);
    let c = dot(p, p) - r * r;
    let disc = b * b - c;
    (disc > 0.0).then(|| {
        let s = disc.sqrt();
        (-b - s, -b + s)
    })
}

/// Whether the intersection line of the planes of splats i and j crosses
/// both discs over a common stretch (eq. 4.4–4.12 for circular splats).
fn crosses_both(
    i: usize,
    j: usize,
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    radii: &[f32],
) -> bool {
    let (ni, nj) = (normals[i], normals[j]);
    let d = cross(ni, nj);
    let dl = dot(d, d).sqrt();
    if dl < 1e-6 {
        return false;
    }
    let d = d.map(|v| v / dl);
    // Work relative to C_i: plane i is n_i·x = 0, plane j is n_j·x = h.
    let cj = sub(positions[j], positions[i]);
    let h = dot(nj, cj);
    let c = dot(ni, nj);
    let det = 1.0 - c * c;
    // P_o = t_i n_i + t_j n_j on both planes (eq. 4.5, typo fixed).
    let (ti, tj) = (-c * h / det, h / det);
    let po = [0, 1, 2].map(|a| ti * ni[a] + tj * nj[a]);
    let Some((a0, a1)) = disc_interval(po, d, radii[i]) else {
        return false;
    };
    let Some((b0, b1)) = disc_interval(sub(po, cj), d, radii[j]) else {
        return false;
    };
    a0.max(b0) < a1.min(b1)
}

/// Finds the clip partners of every splat, classifies them and packs the
/// planes (see the module comment for the layout).
pub fn clip_partners(input: ClipInput, graph: &Graph, opts: &SplatOptions) -> Clipping {
    let ClipInput {
        positions,
        normals,
        radii,
        surface_ids,
    } = input;
    let n = positions.len();
    assert_eq!(surface_ids.len(), n, "one surface id per splat");
    let w = opts.sharp_threshold;
    let mut angles = Vec::new();
    let crease: Vec<bool> = (0..n)
        .map(|i| {
            let has_sharp = graph
                .neighbours(i)
                .iter()
                .any(|&j| dot(normals[i], normals[j as usize]) < w);
            has_sharp && on_crease(i, positions, normals, graph, opts, &mut angles)
        })
        .collect();
    let mut out = Clipping {
        candidates: crease.iter().filter(|&&c| c).count(),
        offsets: Vec::with_capacity(n + 1),
        clip: vec![0; n],
        ..Default::default()
    };
    out.offsets.push(0);
    let mut found: Vec<(f32, u32)> = Vec::new();
    for i in 0..n {
        found.clear();
        if crease[i] {
            for &j in graph.neighbours(i) {
                let ju = j as usize;
                if crease[ju]
                    && dot(normals[i], normals[ju]) < w
                    && crosses_both(i, ju, positions, normals, radii)
                {
                    found.push((crate::grid::dist2(positions[i], positions[ju]), j));
                }
            }
        }
        found.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        found.truncate(opts.max_partners.min(15));
        out.partners.extend(found.iter().map(|f| f.1));
        out.offsets.push(out.partners.len() as u32);
        let partners = &out.partners[out.partners.len() - found.len()..];
        if groups_disagree(i, partners, surface_ids, positions, normals) {
            out.mixed_corners += 1;
        } else if !found.is_empty() {
            let first = (out.planes.len() / PLANE_FLOATS) as u32;
            let (mode, concave) = classify(i, partners, positions, normals);
            for &(_, j) in &found {
                let (nj, cj) = (normals[j as usize], positions[j as usize]);
                let s = if concave { -1.0 } else { 1.0 };
                out.planes
                    .extend_from_slice(&[s * nj[0], s * nj[1], s * nj[2], -s * dot(nj, cj)]);
            }
            out.clip[i] = found.len() as u32 | (mode as u32) << 4 | first << 6;
        }
    }
    out
}

/// Eq. 4.13–4.14: the partners' class about their mean centre and the
/// splat's about its own plane, each concave (`Some(true)`), convex
/// (`Some(false)`) or undecided.
fn classes(
    i: usize,
    partners: &[u32],
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
) -> (Option<bool>, Option<bool>) {
    let k = partners.len() as f32;
    let mut m = [0f32; 3];
    for &j in partners {
        for a in 0..3 {
            m[a] += positions[j as usize][a] / k;
        }
    }
    let partner_class = class_of(
        partners
            .iter()
            .map(|&j| dot(sub(m, positions[j as usize]), normals[j as usize])),
    );
    let own_class = class_of(
        partners
            .iter()
            .map(|&j| dot(sub(positions[j as usize], positions[i]), normals[i])),
    );
    (partner_class, own_class)
}

/// Concave (`Some(true)`) when every signed distance is positive, convex
/// when every one is negative, else undecided.
fn class_of(signs: impl Iterator<Item = f32>) -> Option<bool> {
    let (mut pos, mut neg) = (true, true);
    for s in signs {
        pos &= s > 0.0;
        neg &= s < 0.0;
    }
    match (pos, neg) {
        (true, _) => Some(true),
        (_, true) => Some(false),
        _ => None,
    }
}

/// Eq. 4.15: the same class (or an undecided one) gives the union of the
/// clip half-spaces, mixed classes the intersection. Returns the mode and
/// whether the partners' half-spaces are taken as concave (clip where
/// (P − C_j)·n_j < 0).
fn classify(
    i: usize,
    partners: &[u32],
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
) -> (ClipMode, bool) {
    let (partner_class, own_class) = classes(i, partners, positions, normals);
    let concave = own_class.or(partner_class).unwrap_or(false);
    let mode = match (partner_class, own_class) {
        (Some(a), Some(b)) if a != b => ClipMode::Intersection,
        _ => ClipMode::Union,
    };
    (mode, concave)
}

/// The corner split (module comment): whether the partners, grouped by
/// surface id and each group classified on its own, include a concave
/// group and a convex one.
fn groups_disagree(
    i: usize,
    partners: &[u32],
    surface_ids: &[u32],
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
) -> bool {
    let mut by_id: Vec<u32> = partners.to_vec();
    by_id.sort_unstable_by_key(|&j| (surface_ids[j as usize], j));
    let (mut concave, mut convex) = (false, false);
    for group in by_id.chunk_by(|&a, &b| surface_ids[a as usize] == surface_ids[b as usize]) {
        let (partner_class, own_class) = classes(i, group, positions, normals);
        // A group on one surface has no class of its own about its mean
        // centre (eq. 4.13 is 0); where the group straddles the splat's
        // plane (eq. 4.14 undecided, as the top face does around an inner
        // corner), the splat is seen from the group's planes instead.
        let seen_from_group = class_of(group.iter().map(|&j| {
            dot(
                sub(positions[i], positions[j as usize]),
                normals[j as usize],
            )
        }));
        match own_class.or(seen_from_group).or(partner_class) {
            Some(true) => concave = true,
            Some(false) => convex = true,
            None => {}
        }
    }
    concave && convex
}
