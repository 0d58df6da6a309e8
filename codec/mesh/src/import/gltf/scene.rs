//! The default scene's node hierarchy: which meshes it instances, under
//! which world matrices.

use crate::{Error, Result};

pub(super) type Mat4 = [[f64; 4]; 4];

pub(super) const IDENTITY: Mat4 = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// Deepest node hierarchy followed (deeper means a cycle, in practice).
const MAX_DEPTH: usize = 512;
/// Most node visits (guards against hierarchies that share subtrees).
const MAX_NODE_VISITS: usize = 1_000_000;

fn mul(a: &Mat4, b: &Mat4) -> Mat4 {
    let mut m = [[0.0; 4]; 4];
    for (c, col) in m.iter_mut().enumerate() {
        for (r, v) in col.iter_mut().enumerate() {
            *v = (0..4).map(|k| a[k][r] * b[c][k]).sum();
        }
    }
    m
}

pub(super) fn det3(m: &Mat4) -> f64 {
    m[0][0] * (m[1][1] * m[2][2] - m[2][1] * m[1][2])
        - m[1][0] * (m[0][1] * m[2][2] - m[2][1] * m[0][2])
        + m[2][0] * (m[0][1] * m[1][2] - m[1][1] * m[0][2])
}

/// Mesh instances with their world matrices: the meshes of the default
/// scene (or the first), depth first in node order; every mesh,
/// untransformed, when no scene instances one.
pub(super) fn mesh_instances<'d>(
    doc: &'d gltf::Document,
    what: &'static str,
) -> Result<Vec<(gltf::Mesh<'d>, Mat4)>> {
    let mut instances: Vec<(gltf::Mesh<'_>, Mat4)> = Vec::new();
    if let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) {
        let mut stack: Vec<(gltf::Node<'_>, Mat4, usize)> =
            scene.nodes().map(|n| (n, IDENTITY, 0)).collect();
        stack.reverse();
        let mut visits = 0usize;
        while let Some((node, parent, depth)) = stack.pop() {
            visits += 1;
            if depth > MAX_DEPTH || visits > MAX_NODE_VISITS {
                return Err(Error::input(
                    what,
                    format!(
                        "node hierarchy too deep or too large at node {} (cycle?)",
                        node.index()
                    ),
                ));
            }
            let local = node.transform().matrix().map(|c| c.map(f64::from));
            let world = mul(&parent, &local);
            if let Some(mesh) = node.mesh() {
                instances.push((mesh, world));
            }
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world, depth + 1)));
        }
    }
    if instances.is_empty() {
        instances = doc.meshes().map(|m| (m, IDENTITY)).collect();
    }
    Ok(instances)
}
