//! Generated clouds with known normals for the tests, benches and examples:
//! a deterministic random source and samplers of a sphere, a cube and a
//! solid made of rectangles (an L-shaped block); points sampled on a mesh;
//! a CPU ray-cast of splats ([`raycast`]).

pub mod raycast;

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

/// A flat face of a solid: a rectangle from `corner` spanned by `u` and
/// `v`, with its outward normal.
#[derive(Clone, Copy, Debug)]
pub struct Rect {
    pub corner: [f32; 3],
    pub u: [f32; 3],
    pub v: [f32; 3],
    pub normal: [f32; 3],
}

impl Rect {
    fn area(&self) -> f32 {
        let c = [
            self.u[1] * self.v[2] - self.u[2] * self.v[1],
            self.u[2] * self.v[0] - self.u[0] * self.v[2],
            self.u[0] * self.v[1] - self.u[1] * self.v[0],
        ];
        (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt()
    }

    /// Whether `p` lies on the rectangle (within `eps` of its plane).
    pub fn contains(&self, p: [f32; 3], eps: f32) -> bool {
        let d = [0, 1, 2].map(|k| p[k] - self.corner[k]);
        let along = |a: [f32; 3]| {
            (d[0] * a[0] + d[1] * a[1] + d[2] * a[2]) / (a[0] * a[0] + a[1] * a[1] + a[2] * a[2])
        };
        let off = d[0] * self.normal[0] + d[1] * self.normal[1] + d[2] * self.normal[2];
        let (s, t) = (along(self.u), along(self.v));
        off.abs() < eps && (0.0..=1.0).contains(&s) && (0.0..=1.0).contains(&t)
    }
}

/// Half the height of [`l_block_faces`]' block.
pub const L_BLOCK_HALF_HEIGHT: f32 = 0.5;

/// The faces of an L-shaped block: the L [−1, 1]×[−1, 0] ∪ [−1, 0]×[0, 1]
/// in x, y, extruded over z ∈ [−0.5, 0.5]. Its one concave crease runs
/// along x = y = 0 and meets the top and bottom at two inner corners,
/// (0, 0, ±0.5), where it meets convex edges (seed 002, §7.2's mixed
/// partner sets).
pub fn l_block_faces() -> Vec<Rect> {
    let h = L_BLOCK_HALF_HEIGHT;
    let rect = |corner, u, v, normal| Rect {
        corner,
        u,
        v,
        normal,
    };
    let up = [0.0, 0.0, 2.0 * h];
    vec![
        rect(
            [-1.0, -1.0, h],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ),
        rect(
            [-1.0, 0.0, h],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
        ),
        rect(
            [-1.0, -1.0, -h],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
        ),
        rect(
            [-1.0, 0.0, -h],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, -1.0],
        ),
        rect([-1.0, -1.0, -h], [0.0, 2.0, 0.0], up, [-1.0, 0.0, 0.0]),
        rect([-1.0, -1.0, -h], [2.0, 0.0, 0.0], up, [0.0, -1.0, 0.0]),
        rect([1.0, -1.0, -h], [0.0, 1.0, 0.0], up, [1.0, 0.0, 0.0]),
        rect([0.0, 0.0, -h], [1.0, 0.0, 0.0], up, [0.0, 1.0, 0.0]),
        rect([0.0, 0.0, -h], [0.0, 1.0, 0.0], up, [1.0, 0.0, 0.0]),
        rect([-1.0, 1.0, -h], [1.0, 0.0, 0.0], up, [0.0, 1.0, 0.0]),
    ]
}

/// `n` points uniformly at random over `faces` (by area), with the faces'
/// normals.
pub fn faces_sample(faces: &[Rect], n: usize, seed: u64) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut s = seed;
    let areas: Vec<f32> = faces.iter().map(Rect::area).collect();
    let total: f32 = areas.iter().sum();
    let mut pos = Vec::with_capacity(n);
    let mut nrm = Vec::with_capacity(n);
    for _ in 0..n {
        let mut pick = unit(&mut s) * total;
        let face = faces
            .iter()
            .zip(&areas)
            .find(|(_, &a)| {
                pick -= a;
                pick < 0.0
            })
            .map_or(&faces[faces.len() - 1], |(f, _)| f);
        let (a, b) = (unit(&mut s), unit(&mut s));
        pos.push([0, 1, 2].map(|k| face.corner[k] + a * face.u[k] + b * face.v[k]));
        nrm.push(face.normal);
    }
    (pos, nrm)
}

/// `n` points uniformly on a mesh's triangles (area-weighted), seeded: a
/// cloud as a positions-only scan of the surface arrives.
pub fn sample_triangles(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> Vec<[f32; 3]> {
    sample_triangles_where(positions, triangles, n, seed)
        .into_iter()
        .map(|s| s.point)
        .collect()
}

/// A point of [`sample_triangles_where`]: where it lies, on which triangle,
/// at which barycentrics (of the triangle's second and third corners).
#[derive(Clone, Copy, Debug)]
pub struct TrianglePoint {
    pub point: [f32; 3],
    pub triangle: usize,
    pub barycentric: [f64; 2],
}

/// [`sample_triangles`] with each point's triangle and barycentrics (to
/// sample a texture or per-corner attributes there).
pub fn sample_triangles_where(
    positions: &[[f32; 3]],
    triangles: &[[u32; 3]],
    n: usize,
    seed: u64,
) -> Vec<TrianglePoint> {
    let corner = |t: &[u32; 3], i: usize| positions[t[i] as usize].map(f64::from);
    let mut cumulative = Vec::with_capacity(triangles.len());
    let mut total = 0.0f64;
    for t in triangles {
        let (a, b, c) = (corner(t, 0), corner(t, 1), corner(t, 2));
        let u = [0, 1, 2].map(|k| b[k] - a[k]);
        let v = [0, 1, 2].map(|k| c[k] - a[k]);
        let x = [
            u[1] * v[2] - u[2] * v[1],
            u[2] * v[0] - u[0] * v[2],
            u[0] * v[1] - u[1] * v[0],
        ];
        total += 0.5 * (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
        cumulative.push(total);
    }
    let mut s = seed;
    (0..n)
        .map(|_| {
            let r = (next(&mut s) >> 11) as f64 / (1u64 << 53) as f64 * total;
            let triangle = cumulative
                .partition_point(|&c| c < r)
                .min(triangles.len() - 1);
            let t = &triangles[triangle];
            let (mut e1, mut e2) = (f64::from(unit(&mut s)), f64::from(unit(&mut s)));
            if e1 + e2 > 1.0 {
                (e1, e2) = (1.0 - e1, 1.0 - e2);
            }
            let (a, b, c) = (corner(t, 0), corner(t, 1), corner(t, 2));
            let point = [0, 1, 2].map(|k| (a[k] + e1 * (b[k] - a[k]) + e2 * (c[k] - a[k])) as f32);
            TrianglePoint {
                point,
                triangle,
                barycentric: [e1, e2],
            }
        })
        .collect()
}
