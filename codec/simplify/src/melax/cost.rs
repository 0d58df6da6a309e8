//! Melax's edge-collapse cost (1998; seed 003, Quadros 13–14):
//!
//! cost(u → v) = ‖u − v‖ · max_{f ∈ T_u} min_{n ∈ T_uv} (1 − f·n) / 2
//!
//! with T_u the faces around u and T_uv those on the edge, all with unit
//! normals: moving u along a flat region costs nothing, across a crease
//! the more the sharper. For an animated model the cost is the largest
//! over its frames, so one collapse order suits every pose.

use glam::DVec3;

use crate::collapse::topology::normal;
use crate::collapse::working::WorkingMesh;

/// Unit normal of live face `f` (zero for a degenerate one).
fn face_normal(mesh: &WorkingMesh, f: u32) -> DVec3 {
    normal(&mesh.triangles[f as usize].map(|w| mesh.point(w))).normalize_or_zero()
}

/// cost(u → v) on one frame; `edge` receives the faces on the edge.
fn cost_in(mesh: &WorkingMesh, u: u32, v: u32, edge: &mut Vec<DVec3>) -> f64 {
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
            edge.iter()
                .map(|e| (1.0 - n.dot(*e)) / 2.0)
                .fold(1.0, f64::min)
        })
        .fold(0.0, f64::max);
    mesh.point(u).distance(mesh.point(v)) * curvature
}

/// cost(u → v), the largest over the frames.
pub(super) fn cost(frames: &[WorkingMesh], u: u32, v: u32, edge: &mut Vec<DVec3>) -> f64 {
    frames
        .iter()
        .map(|m| cost_in(m, u, v, edge))
        .fold(0.0, f64::max)
}
