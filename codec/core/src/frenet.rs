//! Residuals in the patch's local Frenet frame, losslessly (AD01 §4;
//! Lee, Lavoué & Dupont 2009 make the rotation integer-to-integer).
//!
//! The frame's third axis is the patch normal (two Givens rotations); a
//! third rotation in the tangent plane turns the first tangent onto the
//! border polygon's major axis, so that each tangential component can be
//! coded by the polygon's spread along it. (Aligning the first tangent with
//! the gate edge, as AD01 does, gained nothing: the edge's direction says
//! little about where the removed vertex lies; the major axis does.)
//! Each Givens rotation is applied as three lifting shears with rounding,
//! so the integer map is a bijection.
//! Only `+ − × / sqrt` on `f64` are used: IEEE 754 makes them bit-identical
//! on x86_64 and wasm32, so encoder and decoder agree on every rounding.

/// One plane rotation as lifting coefficients.
#[derive(Clone, Copy, Debug)]
struct Givens {
    flip: bool,
    a: f64,
    b: f64,
}

impl Givens {
    /// The rotation taking the direction `(x, y)` onto the positive first axis.
    fn aligning(x: f64, y: f64) -> Givens {
        let r = (x * x + y * y).sqrt();
        if r == 0.0 {
            return Givens {
                flip: false,
                a: 0.0,
                b: 0.0,
            };
        }
        let inverse = 1.0 / r;
        let (mut c, mut s) = (x * inverse, y * inverse);
        // Rotating by π first keeps |a| ≤ 1 (the shear for angles near π blows up).
        let flip = c < 0.0;
        if flip {
            c = -c;
            s = -s;
        }
        // Rotation by −θ (cos θ = c, sin θ = s): shears a = (1 − c)/s = s/(1 + c), b = −s.
        Givens {
            flip,
            a: s / (1.0 + c),
            b: -s,
        }
    }

    fn apply_f64(&self, x: f64, y: f64) -> (f64, f64) {
        let (mut x, mut y) = if self.flip { (-x, -y) } else { (x, y) };
        x += self.a * y;
        y += self.b * x;
        x += self.a * y;
        (x, y)
    }

    fn forward(&self, x: &mut i64, y: &mut i64) {
        if self.flip {
            *x = -*x;
            *y = -*y;
        }
        *x += round(self.a * *y as f64);
        *y += round(self.b * *x as f64);
        *x += round(self.a * *y as f64);
    }

    fn inverse(&self, x: &mut i64, y: &mut i64) {
        *x -= round(self.a * *y as f64);
        *y -= round(self.b * *x as f64);
        *x -= round(self.a * *y as f64);
        if self.flip {
            *x = -*x;
            *y = -*y;
        }
    }
}

/// Round half away from zero with casts only (no libm), identical everywhere.
/// Branch-free: residual signs are random, and a mispredicted branch per
/// lifting step cost more than the arithmetic. `x − 0.5` is exactly
/// `−(−x + 0.5)` (IEEE rounding is symmetric) and `as` truncates toward zero,
/// so this equals `−((−x + 0.5) as i64)` for negative `x`.
#[inline]
pub(crate) fn round(x: f64) -> i64 {
    (x + 0.5f64.copysign(x)) as i64
}

/// The local frame of one patch.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Frame {
    xy: Givens,
    zx: Givens,
    /// In the tangent plane: the major axis onto the first tangent.
    plane: Givens,
}

impl Frame {
    /// `normal` need not be unit length; a zero vector gives the identity.
    /// The tangents are left where the two rotations put them.
    pub(crate) fn new(normal: [i64; 3]) -> Frame {
        let n = normal.map(|c| c as f64);
        let xy = Givens::aligning(n[0], n[1]);
        let (nx, _) = xy.apply_f64(n[0], n[1]);
        // Second rotation brings the normal onto +z: align (z, x) onto the z axis.
        let zx = Givens::aligning(n[2], nx);
        Frame {
            xy,
            zx,
            plane: Givens::aligning(0.0, 0.0),
        }
    }

    /// Coordinates of a world vector in the tangent plane (before
    /// [`Frame::align_tangent`]), in f64.
    pub(crate) fn tangent_f64(&self, v: [f64; 3]) -> (f64, f64) {
        let (x, y) = self.xy.apply_f64(v[0], v[1]);
        let (_, x) = self.zx.apply_f64(v[2], x);
        (x, y)
    }

    /// Coordinates of a world vector in the frame before
    /// [`Frame::align_tangent`] (tangent, bitangent, normal), in f64.
    pub(crate) fn local_f64(&self, v: [f64; 3]) -> [f64; 3] {
        let (x, y) = self.xy.apply_f64(v[0], v[1]);
        let (z, x) = self.zx.apply_f64(v[2], x);
        [x, y, z]
    }

    /// Coordinates of a world vector in the frame as [`Frame::to_local`]
    /// turns residuals (first tangent along the aligned axis), in f64.
    pub(crate) fn aligned_f64(&self, v: [f64; 3]) -> [f64; 3] {
        let [x, y, z] = self.local_f64(v);
        let (x, y) = self.plane.apply_f64(x, y);
        [x, y, z]
    }

    /// Turns the first tangent onto the direction `(x, y)` of the tangent plane.
    pub(crate) fn align_tangent(&mut self, x: f64, y: f64) {
        self.plane = Givens::aligning(x, y);
    }

    /// World residual → (tangent, bitangent, normal).
    pub(crate) fn to_local(self, r: [i64; 3]) -> [i64; 3] {
        let [mut x, mut y, mut z] = r;
        self.xy.forward(&mut x, &mut y);
        self.zx.forward(&mut z, &mut x);
        self.plane.forward(&mut x, &mut y);
        [x, y, z]
    }

    pub(crate) fn to_world(self, l: [i64; 3]) -> [i64; 3] {
        let [mut x, mut y, mut z] = l;
        self.plane.inverse(&mut x, &mut y);
        self.zx.inverse(&mut z, &mut x);
        self.xy.inverse(&mut x, &mut y);
        [x, y, z]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(seed: &mut u64) -> i64 {
        *seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((*seed >> 33) % 8001) as i64 - 4000
    }

    #[test]
    fn integer_rotation_is_a_bijection() {
        let mut seed = 7;
        for _ in 0..20_000 {
            let n = [lcg(&mut seed), lcg(&mut seed), lcg(&mut seed)];
            let r = [lcg(&mut seed) / 8, lcg(&mut seed) / 8, lcg(&mut seed) / 8];
            let mut f = Frame::new(n);
            assert_eq!(f.to_world(f.to_local(r)), r, "n {n:?}");
            f.align_tangent(lcg(&mut seed) as f64, lcg(&mut seed) as f64);
            assert_eq!(f.to_world(f.to_local(r)), r, "n {n:?}, aligned");
        }
    }

    #[test]
    fn normal_component_lands_on_z() {
        let f = Frame::new([0, 0, 5]);
        assert_eq!(f.to_local([0, 0, 9]), [0, 0, 9]);
        let f = Frame::new([10, 0, 0]);
        let l = f.to_local([7, 0, 0]);
        assert_eq!(l[2], 7);
        assert!(l[0].abs() <= 1 && l[1].abs() <= 1);
        let f = Frame::new([3, 4, 12]);
        let l = f.to_local([30, 40, 120]);
        assert!((l[2] - 130).abs() <= 1, "{l:?}");
    }
}
