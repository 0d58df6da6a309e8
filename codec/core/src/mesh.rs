//! The indexed triangle mesh every importer produces and every level decodes to.

/// A triangle mesh with shared vertices and optional per-vertex colour.
///
/// Triangles are counter-clockwise seen from outside. After
/// `vitrine_mesh::repair::prepare` the mesh is an oriented 2-manifold (with
/// boundary allowed): the only kind the progressive encoder accepts.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IndexedMesh {
    pub positions: Vec<[f32; 3]>,
    /// One sRGB colour per vertex, when the source had colour.
    pub colors: Option<Vec<[u8; 3]>>,
    pub triangles: Vec<[u32; 3]>,
}

impl IndexedMesh {
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    pub fn face_count(&self) -> usize {
        self.triangles.len()
    }
}
