//! The 24 viewpoints of Lindstrom and Turk's image metric.

use super::raster::Camera;
use glam::Vec3;
use vitrine_codec::IndexedMesh;

/// Vertical field of view of every snapshot: the viewer's 40°.
pub const FOV_Y: f32 = 40.0 * std::f32::consts::PI / 180.0;

/// The centre and half diagonal of the bounding box of the vertices: the sphere
/// the viewer frames (radius at least 1e-6; the origin for an empty mesh).
pub fn bounding_sphere(mesh: &IndexedMesh) -> (Vec3, f32) {
    bounding_sphere_of(&mesh.positions)
}

/// [`bounding_sphere`] of bare positions (a point cloud).
pub fn bounding_sphere_of(positions: &[[f32; 3]]) -> (Vec3, f32) {
    let (mut min, mut max) = (Vec3::INFINITY, Vec3::NEG_INFINITY);
    for p in positions {
        min = min.min(Vec3::from(*p));
        max = max.max(Vec3::from(*p));
    }
    if positions.is_empty() {
        return (Vec3::ZERO, 1e-6);
    }
    ((min + max) * 0.5, ((max - min).length() * 0.5).max(1e-6))
}

/// Unit directions to the 24 vertices of a small rhombicuboctahedron: every
/// permutation of (±1, ±1, ±(1 + √2)), normalised. Ordered by which coordinate
/// is the large one (x, y, z), then by the signs.
pub fn directions() -> [Vec3; 24] {
    let big = 1.0 + std::f32::consts::SQRT_2;
    std::array::from_fn(|i| {
        let (axis, signs) = (i / 8, i % 8);
        let s = |bit: usize| if signs & (1 << bit) == 0 { 1.0 } else { -1.0 };
        let mut v = [s(0), s(1), s(2)];
        v[axis] *= big;
        Vec3::from(v).normalize()
    })
}

/// A camera on the ray from `center` along unit `direction`, looking at the
/// centre, far enough that a sphere of `radius` fits in the 40° field of view
/// with a 10 % margin (the viewer's home distance), with +Y up.
pub fn looking_from(center: Vec3, radius: f32, direction: Vec3) -> Camera {
    let distance = 1.1 * radius / (FOV_Y * 0.5).sin();
    let far = distance + 2.0 * radius;
    // No direction of the rhombicuboctahedron is parallel to Y; others may be.
    let up = if direction.cross(Vec3::Y).length_squared() > 1e-6 {
        Vec3::Y
    } else {
        Vec3::Z
    };
    Camera {
        eye: center + direction * distance,
        target: center,
        up,
        fov_y: FOV_Y,
        near: (distance - 2.0 * radius).max(far / 1000.0),
    }
}

/// The 24 snapshot cameras of Lindstrom and Turk, "Image-driven
/// simplification" (ACM TOG 19(3), 2000): at the vertices of a small
/// rhombicuboctahedron around the bounding sphere (`center`, `radius`),
/// each looking at the centre (see [`directions`] and [`looking_from`]).
pub fn rhombicuboctahedron(center: Vec3, radius: f32) -> [Camera; 24] {
    directions().map(|d| looking_from(center, radius, d))
}
