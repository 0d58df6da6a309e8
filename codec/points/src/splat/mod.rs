//! Splat preprocessing for the viewer's renderer (seed 002, Ivo): oriented
//! circular splats that keep sharp edges sharp (clip partners) and
//! intersecting surfaces apart (surface ids).
//!
//! 1. [`radii`]: r_i = mean distance to the 5 nearest neighbours.
//! 2. [`graph`]: E = {(i, j) : |C_i − C_j| < r_i + r_j}, built on a grid
//!    (identical to the O(n²) definition).
//! 3. Sharp edges: n_i·n_j < w_s; the rest are continuous.
//! 4. [`clip`]: crease versus crossing by the angle-gap test over continuous
//!    neighbours; clip partners where the planes' intersection line crosses
//!    both splats; concave/convex classification (split by surface id near
//!    corners); planes packed for the GPU.
//! 5. [`segment`]: surface ids by breadth-first search over continuous edges
//!    (before clipping, which groups partners by them).

pub mod clip;
pub mod graph;
pub mod radii;
pub mod segment;

pub use clip::{ClipInput, ClipMode, Clipping, PLANE_FLOATS};
pub use graph::{brute_force_graph, neighbour_graph, Graph};
pub use radii::{prefix_radius_scale, splat_radii, RADIUS_NEIGHBOURS};
pub use segment::surface_ids;

/// Parameters of the preprocessing.
#[derive(Clone, Copy, Debug)]
pub struct SplatOptions {
    /// Edges with n_i·n_j below this are sharp (seed: typically 0.9).
    pub sharp_threshold: f32,
    /// A splat whose continuous neighbours leave an angular gap wider than
    /// this (radians) lies on a crease (the seed leaves α open; π/2).
    pub crease_gap: f32,
    /// Most clip partners kept per splat (the nearest).
    pub max_partners: usize,
}

impl Default for SplatOptions {
    fn default() -> Self {
        SplatOptions {
            sharp_threshold: 0.9,
            crease_gap: std::f32::consts::FRAC_PI_2,
            max_partners: 8,
        }
    }
}

/// Everything the renderer needs beyond positions and normals.
#[derive(Clone, Debug)]
pub struct Splats {
    pub radii: Vec<f32>,
    pub graph: Graph,
    /// Edges of `graph` (each counted once) that are sharp.
    pub sharp_edges: usize,
    pub clipping: Clipping,
    pub surface_ids: Vec<u32>,
}

/// Runs the whole preprocessing on finite positions with unit normals
/// (oriented consistently, e.g. by [`crate::estimate_normals`]).
pub fn preprocess(positions: &[[f32; 3]], normals: &[[f32; 3]], opts: &SplatOptions) -> Splats {
    assert_eq!(positions.len(), normals.len(), "one normal per splat");
    let radii = splat_radii(positions);
    preprocess_with_radii(positions, normals, radii, opts)
}

/// [`preprocess`] with given radii (e.g. the full cloud's, scaled for a
/// prefix by [`prefix_radius_scale`]).
pub fn preprocess_with_radii(
    positions: &[[f32; 3]],
    normals: &[[f32; 3]],
    radii: Vec<f32>,
    opts: &SplatOptions,
) -> Splats {
    let graph = neighbour_graph(positions, &radii);
    let w = opts.sharp_threshold;
    let sharp = |i: usize, j: usize| dot(normals[i], normals[j]) < w;
    let sharp_edges = (0..positions.len())
        .map(|i| {
            graph
                .neighbours(i)
                .iter()
                .filter(|&&j| (j as usize) > i && sharp(i, j as usize))
                .count()
        })
        .sum();
    let surface_ids = surface_ids(normals, &graph, w);
    let input = ClipInput {
        positions,
        normals,
        radii: &radii,
        surface_ids: &surface_ids,
    };
    let clipping = clip::clip_partners(input, &graph, opts);
    Splats {
        radii,
        graph,
        sharp_edges,
        clipping,
        surface_ids,
    }
}

#[inline]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[inline]
pub(crate) fn sub(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

#[inline]
pub(crate) fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
