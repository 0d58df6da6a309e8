//! A CPU ray-cast of splats against the cube [−1, 1]³ they sample, as the
//! viewer's renderer draws them (`web/src/splats/`): each splat is a disc
//! (centre, normal, radius) intersected with every pixel's ray; a clipped
//! splat drops the hits its partner planes clip, as the fragment shader
//! does (union mode clips where any plane does, intersection mode where all
//! do). The silhouette test and the prefix example measure with it.

use crate::splat::{ClipMode, Splats, PLANE_FLOATS};

/// Image side in pixels.
pub const SIZE: usize = 512;
/// The viewer draws a point's disc at this multiple of its radius
/// (`POINT_RADIUS_SCALE`, web/src/splats/point-stream.js). The
/// mean distance to the 5 nearest neighbours leaves gaps in a random
/// sample: on this cube 1,741 hole pixels at 1.0, 61 at 1.2, 1 at 1.35,
/// none from 1.5.
pub const DRAWN_RADIUS_SCALE: f32 = 1.5;
/// Half the width the image covers, in model units (the cube is [−1, 1]³).
pub const EXTENT: f32 = 1.9;

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

fn normalise(a: [f32; 3]) -> [f32; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// An orthographic view: the direction it looks along and the image axes.
pub struct View {
    pub dir: [f32; 3],
    pub u: [f32; 3],
    pub v: [f32; 3],
}

impl View {
    /// 24 directions spread over the sphere (a Fibonacci spiral), none along
    /// an axis, so every view sees edges and corners.
    pub fn all() -> Vec<View> {
        (0..24)
            .map(|k| {
                let z = 1.0 - (k as f32 + 0.5) / 12.0;
                let r = (1.0 - z * z).sqrt();
                let phi = k as f32 * 2.399_963;
                let dir = normalise([r * phi.cos(), r * phi.sin(), z]);
                let up = if dir[2].abs() < 0.9 {
                    [0.0, 0.0, 1.0]
                } else {
                    [1.0, 0.0, 0.0]
                };
                let u = normalise(cross(up, dir));
                let v = cross(dir, u);
                View { dir, u, v }
            })
            .collect()
    }

    /// The ray through pixel (x, y): its origin, 10 units in front.
    pub fn origin(&self, x: usize, y: usize) -> [f32; 3] {
        let s = |p: usize| ((p as f32 + 0.5) / SIZE as f32 * 2.0 - 1.0) * EXTENT;
        let (a, b) = (s(x), s(y));
        [0, 1, 2].map(|k| a * self.u[k] + b * self.v[k] - 10.0 * self.dir[k])
    }

    /// The pixel a point projects to (may be outside the image).
    pub fn pixel(&self, p: [f32; 3]) -> (f32, f32) {
        let f = |c: f32| (c / EXTENT + 1.0) * 0.5 * SIZE as f32 - 0.5;
        (f(dot(p, self.u)), f(dot(p, self.v)))
    }
}

/// Whether the ray from `o` along `d` meets the cube [−1, 1]³ (slabs).
pub fn hits_cube(o: [f32; 3], d: [f32; 3]) -> bool {
    let (mut near, mut far) = (f32::MIN, f32::MAX);
    for k in 0..3 {
        if d[k].abs() < 1e-9 {
            if o[k].abs() > 1.0 {
                return false;
            }
            continue;
        }
        let (a, b) = ((-1.0 - o[k]) / d[k], (1.0 - o[k]) / d[k]);
        near = near.max(a.min(b));
        far = far.min(a.max(b));
    }
    near <= far
}

/// Pixels covered by the splats drawn at `radii` (the splats' own, or
/// others), clipped or not.
pub fn coverage(
    view: &View,
    pos: &[[f32; 3]],
    nrm: &[[f32; 3]],
    splats: &Splats,
    radii: &[f32],
    clip: bool,
) -> Vec<bool> {
    let mut covered = vec![false; SIZE * SIZE];
    let px = 2.0 * EXTENT / SIZE as f32;
    let c = &splats.clipping;
    for (i, (&centre, &n)) in pos.iter().zip(nrm).enumerate() {
        let r = radii[i] * DRAWN_RADIUS_SCALE;
        let dn = dot(n, view.dir);
        if dn.abs() < 1e-6 {
            continue; // edge-on: a disc covers no area
        }
        let (cx, cy) = view.pixel(centre);
        let reach = (r / px).ceil() as isize + 1;
        let (first, count) = ((c.clip[i] >> 6) as usize, (c.clip[i] & 15) as usize);
        let mode = c.mode(i);
        for y in (cy as isize - reach).max(0)..=(cy as isize + reach).min(SIZE as isize - 1) {
            for x in (cx as isize - reach).max(0)..=(cx as isize + reach).min(SIZE as isize - 1) {
                let o = view.origin(x as usize, y as usize);
                let t = dot(n, [0, 1, 2].map(|k| centre[k] - o[k])) / dn;
                let p = [0, 1, 2].map(|k| o[k] + t * view.dir[k]);
                let off = [0, 1, 2].map(|k| p[k] - centre[k]);
                if dot(off, off) > r * r {
                    continue;
                }
                if clip && count > 0 {
                    let clips = |k: usize| {
                        let q = &c.planes[k * PLANE_FLOATS..(k + 1) * PLANE_FLOATS];
                        q[0] * p[0] + q[1] * p[1] + q[2] * p[2] + q[3] > 0.0
                    };
                    let clipped = match mode {
                        ClipMode::Union => (first..first + count).any(clips),
                        ClipMode::Intersection => (first..first + count).all(clips),
                        ClipMode::None => false,
                    };
                    if clipped {
                        continue;
                    }
                }
                covered[y as usize * SIZE + x as usize] = true;
            }
        }
    }
    covered
}

/// A pixel whose 3×3 block all sees the cube: a pixel there that no splat
/// covers is a hole (the silhouette's own boundary counts in the XOR error
/// instead).
pub fn inside(truth: &[bool], i: usize) -> bool {
    let (x, y) = ((i % SIZE) as isize, (i / SIZE) as isize);
    (-1..=1).all(|dy| {
        (-1..=1).all(|dx| {
            let (a, b) = (x + dx, y + dy);
            (0..SIZE as isize).contains(&a)
                && (0..SIZE as isize).contains(&b)
                && truth[b as usize * SIZE + a as usize]
        })
    })
}

/// The cube's own pixels in a view.
pub fn truth(view: &View) -> Vec<bool> {
    (0..SIZE * SIZE)
        .map(|i| hits_cube(view.origin(i % SIZE, i / SIZE), view.dir))
        .collect()
}

/// Over the 24 views: pixels where the clipped splats drawn at `radii`
/// and the cube disagree, and hole pixels.
pub fn silhouette_error(
    pos: &[[f32; 3]],
    nrm: &[[f32; 3]],
    splats: &Splats,
    radii: &[f32],
) -> (usize, usize) {
    let (mut error, mut holes) = (0, 0);
    for view in View::all() {
        let truth = truth(&view);
        let covered = coverage(&view, pos, nrm, splats, radii, true);
        for i in 0..SIZE * SIZE {
            error += usize::from(truth[i] != covered[i]);
            holes += usize::from(!covered[i] && inside(&truth, i));
        }
    }
    (error, holes)
}
