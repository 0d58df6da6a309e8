//! Central projection from a cell's centre onto its cube's faces
//! (`CCC.md`, "Projection"); the viewer's shader does the same arithmetic.

use glam::DVec3;

/// Faces in the order of the cell texture's mask bits: +x, −x, +y, −y, +z, −z.
pub const FACES: usize = 6;

/// The face the ray from `centre` through `point` leaves the unit cube by,
/// and the exit point's coordinates on that face. Both points are in cube
/// units (the cube is `[0, 1]³`). `None` when the two points coincide.
pub fn exit_face(centre: DVec3, point: DVec3) -> Option<(usize, [f64; 2])> {
    let d = point - centre;
    let mut best: Option<(usize, f64)> = None;
    for axis in 0..3 {
        if d[axis] == 0.0 {
            continue;
        }
        let bound = if d[axis] > 0.0 { 1.0 } else { 0.0 };
        let t = (bound - centre[axis]) / d[axis];
        if best.is_none_or(|(_, b)| t < b) {
            best = Some((axis, t));
        }
    }
    let (axis, t) = best?;
    let exit = centre + d * t;
    let face = 2 * axis + usize::from(d[axis] < 0.0);
    let (b0, b1) = other_axes(axis);
    Some((face, [exit[b0].clamp(0.0, 1.0), exit[b1].clamp(0.0, 1.0)]))
}

/// The point of face `face` at face coordinates `(u, v)`, in cube units.
pub fn face_point(face: usize, uv: [f64; 2]) -> DVec3 {
    let axis = face / 2;
    let mut p = DVec3::ZERO;
    p[axis] = if face.is_multiple_of(2) { 1.0 } else { 0.0 };
    let (b0, b1) = other_axes(axis);
    p[b0] = uv[0];
    p[b1] = uv[1];
    p
}

/// The two axes spanning a face across `axis`, in the order `(u, v)`.
pub(super) fn other_axes(axis: usize) -> (usize, usize) {
    match axis {
        0 => (1, 2),
        1 => (0, 2),
        _ => (0, 1),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn face_points_project_back_to_themselves() {
        let centre = DVec3::new(0.3, 0.6, 0.45);
        for face in 0..FACES {
            for uv in [[0.1, 0.2], [0.5, 0.5], [0.9, 0.7]] {
                let p = face_point(face, uv);
                let (f, back) = exit_face(centre, p).unwrap();
                assert_eq!(f, face);
                assert!((back[0] - uv[0]).abs() < 1e-12 && (back[1] - uv[1]).abs() < 1e-12);
                // Any point on the same ray maps to the same texel.
                let mid = centre + (p - centre) * 0.37;
                let (f2, uv2) = exit_face(centre, mid).unwrap();
                assert_eq!(f2, face);
                assert!((uv2[0] - uv[0]).abs() < 1e-12 && (uv2[1] - uv[1]).abs() < 1e-12);
            }
        }
        assert!(exit_face(centre, centre).is_none());
    }
}
