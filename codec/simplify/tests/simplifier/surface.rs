//! The input surface as a lookup for the orientation tests: which way the
//! input faced near a point.

use std::cell::RefCell;

use glam::{DVec3, I64Vec3};
use vitrine_codec::IndexedMesh;

/// The input's faces in a dense grid of cells, by bounding box.
pub struct Surface {
    faces: Vec<[DVec3; 3]>,
    lo: DVec3,
    cell: f64,
    size: I64Vec3,
    cells: Vec<Vec<u32>>,
    /// Per face, the last query that looked at it.
    seen: RefCell<(u32, Vec<u32>)>,
}

impl Surface {
    pub fn new(mesh: &IndexedMesh) -> Self {
        let (lo, hi) = bounds(mesh);
        let cell = (hi - lo).max_element() / 24.0;
        let size = ((hi - lo) / cell).floor().as_i64vec3() + 1;
        let faces: Vec<[DVec3; 3]> = mesh.triangles.iter().map(|t| corners(mesh, t)).collect();
        let mut cells = vec![Vec::new(); (size.x * size.y * size.z) as usize];
        for (f, p) in faces.iter().enumerate() {
            let key = |q: DVec3| ((q - lo) / cell).floor().as_i64vec3().min(size - 1);
            let (a, b) = (key(p[0].min(p[1]).min(p[2])), key(p[0].max(p[1]).max(p[2])));
            for x in a.x..=b.x {
                for y in a.y..=b.y {
                    for z in a.z..=b.z {
                        cells[(x + size.x * (y + size.y * z)) as usize].push(f as u32);
                    }
                }
            }
        }
        let seen = RefCell::new((0, vec![0; faces.len()]));
        Surface {
            faces,
            lo,
            cell,
            size,
            cells,
            seen,
        }
    }

    /// The input's orientation near `p`: the area-weighted normal of the
    /// input faces within `slack` of the nearest distance from `p` (a
    /// nearest face alone is arbitrary beside a crease).
    pub fn normal_near(&self, p: DVec3, slack: f64) -> DVec3 {
        let mut nearest = f64::INFINITY;
        for r in 0i64.. {
            self.visit_ring(p, r, |q| {
                nearest = nearest.min(closest_on_triangle(p, q).distance(p))
            });
            if nearest <= r as f64 * self.cell {
                break;
            }
        }
        let reach = nearest + slack;
        let mut normal = DVec3::ZERO;
        for r in 0..=(reach / self.cell).ceil() as i64 + 1 {
            self.visit_ring(p, r, |q| {
                if closest_on_triangle(p, q).distance(p) <= reach {
                    normal += (q[1] - q[0]).cross(q[2] - q[0]);
                }
            });
        }
        normal
    }

    /// Calls `f` with the corners of each face, not yet seen by this call,
    /// listed in the cells at Chebyshev distance `r` from `p`'s cell.
    fn visit_ring(&self, p: DVec3, r: i64, mut f: impl FnMut(&[DVec3; 3])) {
        let mut seen = self.seen.borrow_mut();
        let (stamp, marks) = &mut *seen;
        if r == 0 {
            *stamp += 1;
        }
        let home = ((p - self.lo) / self.cell).floor().as_i64vec3();
        for x in -r..=r {
            for y in -r..=r {
                for z in -r..=r {
                    let c = home + I64Vec3::new(x, y, z);
                    let inside = c.cmpge(I64Vec3::ZERO).all() && c.cmplt(self.size).all();
                    if x.abs().max(y.abs()).max(z.abs()) != r || !inside {
                        continue;
                    }
                    let cell = (c.x + self.size.x * (c.y + self.size.y * c.z)) as usize;
                    for &g in &self.cells[cell] {
                        if marks[g as usize] != *stamp {
                            marks[g as usize] = *stamp;
                            f(&self.faces[g as usize]);
                        }
                    }
                }
            }
        }
    }
}

fn bounds(mesh: &IndexedMesh) -> (DVec3, DVec3) {
    mesh.positions
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), p| {
            let p = DVec3::from(p.map(f64::from));
            (lo.min(p), hi.max(p))
        })
}

pub fn corners(mesh: &IndexedMesh, t: &[u32; 3]) -> [DVec3; 3] {
    t.map(|v| DVec3::from(mesh.positions[v as usize].map(f64::from)))
}

/// Ericson, Real-Time Collision Detection §5.1.5.
fn closest_on_triangle(p: DVec3, [a, b, c]: &[DVec3; 3]) -> DVec3 {
    let (ab, ac, ap) = (*b - *a, *c - *a, p - *a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return *a;
    }
    let bp = p - *b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return *b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return *a + ab * (d1 / (d1 - d3));
    }
    let cp = p - *c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return *c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return *a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return *b + (*c - *b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = 1.0 / (va + vb + vc);
    *a + ab * (vb * denom) + ac * (vc * denom)
}
