//! Generated clouds with known normals for the tests, benches and examples:
//! a deterministic random source and samplers of a sphere and a cube.

/// SplitMix64 step.
pub fn next(state: &mut u64) -> u64 {
    *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
    let mut z = *state;
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform in [0, 1).
pub fn unit(state: &mut u64) -> f32 {
    (next(state) >> 40) as f32 / (1u64 << 24) as f32
}

/// `n` points uniformly on a sphere, with their outward normals.
pub fn sphere(
    n: usize,
    centre: [f32; 3],
    radius: f32,
    seed: u64,
) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut s = seed;
    let mut pos = Vec::with_capacity(n);
    let mut nrm = Vec::with_capacity(n);
    while pos.len() < n {
        let v = [0, 1, 2].map(|_| unit(&mut s) * 2.0 - 1.0);
        let l2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        if !(1e-4..=1.0).contains(&l2) {
            continue;
        }
        let l = l2.sqrt();
        let u = v.map(|x| x / l);
        nrm.push(u);
        pos.push([0, 1, 2].map(|a| centre[a] + radius * u[a]));
    }
    (pos, nrm)
}

/// `n` points uniformly at random (so jittered, not on a lattice) on the
/// surface of the cube [−h, h]³, with their outward normals.
pub fn cube(n: usize, h: f32, seed: u64) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut s = seed;
    let mut pos = Vec::with_capacity(n);
    let mut nrm = Vec::with_capacity(n);
    for _ in 0..n {
        let face = (next(&mut s) % 6) as usize;
        let axis = face / 2;
        let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
        let mut p = [0f32; 3];
        for (a, v) in p.iter_mut().enumerate() {
            *v = if a == axis {
                sign * h
            } else {
                (unit(&mut s) * 2.0 - 1.0) * h
            };
        }
        let mut nv = [0f32; 3];
        nv[axis] = sign;
        pos.push(p);
        nrm.push(nv);
    }
    (pos, nrm)
}

/// Angle in degrees between two unit vectors.
pub fn angle_deg(a: [f32; 3], b: [f32; 3]) -> f32 {
    let d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
    d.clamp(-1.0, 1.0).acos().to_degrees()
}
