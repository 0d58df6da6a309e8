//! Melax's edge-collapse cost (1998; seed 003, Quadros 13–14):
//!
//! cost(u → v) = ‖u − v‖ · max_{f ∈ T_u} min_{n ∈ T_uv} (1 − f·n) / 2
//!
//! with T_u the faces around u and T_uv those on the edge, all with unit
//! normals: moving u along a flat region costs nothing, across a crease
//! the more the sharper. For an animated model the cost is the largest
//! over its frames, so one collapse order suits every pose.
//!
//! (1 − f·n)/2 is sin²(θ/2) for the angle θ between the normals: second
//! order in θ, so on a smooth closed scan long runs of collapses each look
//! nearly free and pile up in one gently curved patch (nefertiti-100k at
//! 20 %: 1.9× the quadric simplifier's Hausdorff distance). The default,
//! [`MelaxCost::Sine`], takes sin(θ/2), its square root: the cost is then a
//! length of the order of how far the surface moves (first order in θ),
//! and the same scan comes to 0.98× (docs/bench-log/2026-12-03-session-15-melax.md).

use glam::DVec3;

use crate::collapse::topology::normal;
use crate::collapse::working::WorkingMesh;

/// The crease term of the cost.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MelaxCost {
    /// sin(θ/2) = √((1 − f·n)/2): first order in the crease angle.
    #[default]
    Sine,
    /// The seed's (1 − f·n)/2 = sin²(θ/2), as Melax (1998) wrote it.
    Seed,
}

impl MelaxCost {
    /// The crease term for unit normals `f` and `n`.
    fn crease(self, f: DVec3, n: DVec3) -> f64 {
        let half = ((1.0 - f.dot(n)) / 2.0).max(0.0);
        match self {
            MelaxCost::Sine => half.sqrt(),
            MelaxCost::Seed => half,
        }
    }
}

/// Unit normal of live face `f` (zero for a degenerate one).
fn face_normal(mesh: &WorkingMesh, f: u32) -> DVec3 {
    normal(&mesh.triangles[f as usize].map(|w| mesh.point(w))).normalize_or_zero()
}

/// cost(u → v) on one frame; `edge` receives the faces on the edge.
fn cost_in(kind: MelaxCost, mesh: &WorkingMesh, u: u32, v: u32, edge: &mut Vec<DVec3>) -> f64 {
    edge.clear();
    edge.extend(
        mesh.faces_of[u as usize]
            .iter()
            .filter(|&&f| mesh.triangles[f as usize].contains(&v))
            .map(|&f| face_normal(mesh, f)),
    );
    let curvature = mesh.faces_of[u as usize]
        .iter()
        .map(|&f| {
            let n = face_normal(mesh, f);
            edge.iter().map(|e| kind.crease(n, *e)).fold(1.0, f64::min)
        })
        .fold(0.0, f64::max);
    mesh.point(u).distance(mesh.point(v)) * curvature
}

/// cost(u → v), the largest over the frames.
pub(super) fn cost(
    kind: MelaxCost,
    frames: &[WorkingMesh],
    u: u32,
    v: u32,
    edge: &mut Vec<DVec3>,
) -> f64 {
    frames
        .iter()
        .map(|m| cost_in(kind, m, u, v, edge))
        .fold(0.0, f64::max)
}
