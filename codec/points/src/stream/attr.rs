//! A point's coded attributes, octahedral normal quantization and the
//! residual predictions of normals and colours.

/// A point's coded attributes (only the ones the stream has are used).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Attr {
    pub normal: [u16; 2],
    pub colour: [u8; 3],
}

/// What the root's representative is predicted from.
pub(crate) fn root_prediction(normal_bits: u8) -> Attr {
    let mid = if normal_bits == 0 {
        0
    } else {
        1u16 << (normal_bits - 1)
    };
    Attr {
        normal: [mid, mid],
        colour: [128; 3],
    }
}

/// A unit normal to octahedral coordinates of `bits` bits each (Meyer et
/// al. 2010): the octahedron |x| + |y| + |z| = 1, its lower half folded
/// over the upper, mapped to a square grid.
pub fn octahedral_encode(n: [f32; 3], bits: u8) -> [u16; 2] {
    let l1 = n[0].abs() + n[1].abs() + n[2].abs();
    let (mut u, mut v) = if l1 > 0.0 && l1.is_finite() {
        (n[0] / l1, n[1] / l1)
    } else {
        (0.0, 0.0)
    };
    if n[2] < 0.0 {
        let (ou, ov) = (u, v);
        u = (1.0 - ov.abs()) * ou.signum();
        v = (1.0 - ou.abs()) * ov.signum();
    }
    let max = ((1u32 << bits) - 1) as f32;
    let q = |x: f32| (((x + 1.0) * 0.5 * max).round().clamp(0.0, max)) as u16;
    [q(u), q(v)]
}

/// Octahedral coordinates back to a unit normal.
pub fn octahedral_decode(q: [u16; 2], bits: u8) -> [f32; 3] {
    let max = ((1u32 << bits) - 1) as f32;
    let u = f32::from(q[0]) / max * 2.0 - 1.0;
    let v = f32::from(q[1]) / max * 2.0 - 1.0;
    let z = 1.0 - u.abs() - v.abs();
    let (x, y) = if z < 0.0 {
        ((1.0 - v.abs()) * u.signum(), (1.0 - u.abs()) * v.signum())
    } else {
        (u, v)
    };
    let l = (x * x + y * y + z * z).sqrt();
    [x / l, y / l, z / l]
}

/// The colour residual against a prediction: green, then red and blue
/// relative to green's residual (their errors move together).
pub(crate) fn colour_residual(c: [u8; 3], pred: [u8; 3]) -> [i32; 3] {
    let d = [0, 1, 2].map(|k| i32::from(c[k]) - i32::from(pred[k]));
    [d[1], d[0] - d[1], d[2] - d[1]]
}

/// Inverse of [`colour_residual`]; `None` if a channel leaves 0..=255.
pub(crate) fn colour_apply(r: [i32; 3], pred: [u8; 3]) -> Option<[u8; 3]> {
    let g = i32::from(pred[1]).checked_add(r[0])?;
    let red = i32::from(pred[0]).checked_add(r[1])?.checked_add(r[0])?;
    let b = i32::from(pred[2]).checked_add(r[2])?.checked_add(r[0])?;
    let ok = |v: i32| u8::try_from(v).ok();
    Some([ok(red)?, ok(g)?, ok(b)?])
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn octahedral_round_trip_is_close_and_stable() {
        let mut s = 3u64;
        for _ in 0..5000 {
            let v = [0, 1, 2].map(|_| crate::testing::unit(&mut s) * 2.0 - 1.0);
            let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if l < 1e-3 {
                continue;
            }
            let n = v.map(|x| x / l);
            let q = octahedral_encode(n, 11);
            let back = octahedral_decode(q, 11);
            assert!(crate::testing::angle_deg(n, back) < 0.15, "{n:?} {back:?}");
            // Re-encoding a decoded normal gives the same code.
            assert_eq!(octahedral_encode(back, 11), q);
        }
    }

    #[test]
    fn colour_residual_inverts() {
        for c in [[0, 0, 0], [255, 0, 128], [12, 250, 3]] {
            for p in [[128, 128, 128], [255, 255, 255], [0, 7, 200]] {
                assert_eq!(colour_apply(colour_residual(c, p), p), Some(c));
            }
        }
        assert_eq!(colour_apply([200, 0, 0], [128, 128, 128]), None);
    }
}
