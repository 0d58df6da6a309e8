//! Holes closed by cones (SEEDS.md 001, "holes"): the seed takes closed
//! surfaces only, and scans have holes. Each border loop gets a virtual
//! vertex joined to its edges. The cone is blocked (no distance passes
//! through it, so it pulls no path across the hole) and is a site of its
//! own; the output faces on it are dropped at the end, which leaves the
//! loop a border of the output.

use glam::DVec3;
use vitrine_codec::{IndexedMesh, Result};
use vitrine_geodesic::Surface;

/// The input's surface with its holes coned over.
pub(super) struct Closed {
    pub surface: Surface,
    /// The input's vertex count: vertices from here on are cones.
    pub first_cone: u32,
}

impl Closed {
    pub fn new(mesh: &IndexedMesh) -> Result<Self> {
        let open = Surface::new(mesh)?;
        let loops = open.boundary_loops();
        let first_cone = mesh.positions.len() as u32;
        if loops.is_empty() {
            return Ok(Closed {
                surface: open,
                first_cone,
            });
        }
        let mut positions = mesh.positions.clone();
        let mut triangles = mesh.triangles.clone();
        for ring in &loops {
            let centre: DVec3 =
                ring.iter().map(|&v| open.position(v)).sum::<DVec3>() / ring.len() as f64;
            let cone = positions.len() as u32;
            positions.push(centre.as_vec3().to_array());
            for (k, &a) in ring.iter().enumerate() {
                let b = ring[(k + 1) % ring.len()];
                // The border edge runs a → b in its face: the cone's face runs b → a.
                triangles.push([b, a, cone]);
            }
        }
        let mut surface = Surface::from_parts(&positions, &triangles)?;
        for cone in first_cone..positions.len() as u32 {
            surface.block(cone);
        }
        Ok(Closed {
            surface,
            first_cone,
        })
    }

    pub fn is_cone(&self, v: u32) -> bool {
        v >= self.first_cone
    }
}
