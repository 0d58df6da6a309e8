//! Meshes generated in code, for tests, benchmarks and the demo model.
//! The project ships no third-party scans; these stand in for them.

use crate::IndexedMesh;
use std::collections::HashMap;
use std::f32::consts::TAU;

/// An open `n × n` grid of unit squares in z = 0, each split in two
/// (a flat surface with a border of `4n` vertices).
pub fn grid(n: u32) -> IndexedMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f32, j as f32, 0.0]);
        }
    }
    let id = |i: u32, j: u32| j * (n + 1) + i;
    let mut triangles = Vec::new();
    for j in 0..n {
        for i in 0..n {
            triangles.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            triangles.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    IndexedMesh {
        positions,
        colors: None,
        triangles,
    }
}

/// A torus of `rings × sides` vertices (genus 1, valence 6 everywhere).
pub fn torus(rings: u32, sides: u32, major: f32, minor: f32) -> IndexedMesh {
    let mut positions = Vec::with_capacity((rings * sides) as usize);
    for i in 0..rings {
        let u = i as f32 / rings as f32 * TAU;
        for j in 0..sides {
            let v = j as f32 / sides as f32 * TAU;
            let r = major + minor * v.cos();
            positions.push([r * u.cos(), r * u.sin(), minor * v.sin()]);
        }
    }
    let id = |i: u32, j: u32| (i % rings) * sides + (j % sides);
    let mut triangles = Vec::with_capacity(2 * positions.len());
    for i in 0..rings {
        for j in 0..sides {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    IndexedMesh {
        positions,
        colors: None,
        triangles,
    }
}

/// An icosahedron subdivided `levels` times and projected on the unit sphere.
pub fn icosphere(levels: u32) -> IndexedMesh {
    let t = (1.0 + 5f32.sqrt()) / 2.0;
    let mut positions: Vec<[f32; 3]> = [
        [-1.0, t, 0.0],
        [1.0, t, 0.0],
        [-1.0, -t, 0.0],
        [1.0, -t, 0.0],
        [0.0, -1.0, t],
        [0.0, 1.0, t],
        [0.0, -1.0, -t],
        [0.0, 1.0, -t],
        [t, 0.0, -1.0],
        [t, 0.0, 1.0],
        [-t, 0.0, -1.0],
        [-t, 0.0, 1.0],
    ]
    .to_vec();
    let mut triangles: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut mid = HashMap::new();
        let mut midpoint = |a: u32, b: u32, positions: &mut Vec<[f32; 3]>| {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                let (p, q) = (positions[a as usize], positions[b as usize]);
                positions.push([
                    (p[0] + q[0]) / 2.0,
                    (p[1] + q[1]) / 2.0,
                    (p[2] + q[2]) / 2.0,
                ]);
                positions.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(triangles.len() * 4);
        for [a, b, c] in triangles {
            let ab = midpoint(a, b, &mut positions);
            let bc = midpoint(b, c, &mut positions);
            let ca = midpoint(c, a, &mut positions);
            next.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        triangles = next;
    }
    for p in &mut positions {
        let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
        *p = p.map(|x| x / l);
    }
    IndexedMesh {
        positions,
        colors: None,
        triangles,
    }
}

/// A plate with `genus` square tunnels: the boundary of a voxel solid,
/// `cells` grid steps per voxel. Irregular valences, flat regions, sharp edges.
pub fn plate_with_tunnels(genus: u32, cells: u32) -> IndexedMesh {
    let (nx, ny, nz) = (2 * genus as i32 + 1, 3, 1);
    let solid = |x: i32, y: i32, z: i32| {
        (0..nx).contains(&x)
            && (0..ny).contains(&y)
            && (0..nz).contains(&z)
            && !(y == 1 && x % 2 == 1)
    };
    let mut ids: HashMap<[i32; 3], u32> = HashMap::new();
    let mut positions = Vec::new();
    let mut triangles = Vec::new();
    let n = cells as i32;
    let mut vertex = |p: [i32; 3], positions: &mut Vec<[f32; 3]>| {
        *ids.entry(p).or_insert_with(|| {
            positions.push(p.map(|c| c as f32 / n as f32));
            positions.len() as u32 - 1
        })
    };
    // For each solid voxel face exposed to empty space, a cells × cells grid.
    for x in -1..=nx {
        for y in -1..=ny {
            for z in -1..=nz {
                if !solid(x, y, z) {
                    continue;
                }
                for axis in 0..3 {
                    for dir in [-1i32, 1] {
                        let mut d = [0; 3];
                        d[axis] = dir;
                        if solid(x + d[0], y + d[1], z + d[2]) {
                            continue;
                        }
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let mut origin = [x * n, y * n, z * n];
                        if dir > 0 {
                            origin[axis] += n;
                        }
                        for i in 0..n {
                            for j in 0..n {
                                let corner = |di: i32, dj: i32| {
                                    let mut p = origin;
                                    p[u] += i + di;
                                    p[v] += j + dj;
                                    p
                                };
                                let q = [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                                    .map(|p| vertex(p, &mut positions));
                                // Outward orientation: (u, v, axis) is right-handed.
                                let (a, b, c, d) = if dir > 0 {
                                    (q[0], q[1], q[2], q[3])
                                } else {
                                    (q[0], q[3], q[2], q[1])
                                };
                                if (i + j) % 2 == 0 {
                                    triangles.extend_from_slice(&[[a, b, c], [a, c, d]]);
                                } else {
                                    triangles.extend_from_slice(&[[a, b, d], [b, c, d]]);
                                }
                            }
                        }
                    }
                }
            }
        }
    }
    IndexedMesh {
        positions,
        colors: None,
        triangles,
    }
}

/// Removes the faces whose centroid lies within `radius` of any of `centres`: holes.
pub fn punch_holes(mesh: &IndexedMesh, centres: &[[f32; 3]], radius: f32) -> IndexedMesh {
    let inside = |t: &[u32; 3]| {
        let c = [0, 1, 2].map(|k| {
            t.iter()
                .map(|&v| mesh.positions[v as usize][k])
                .sum::<f32>()
                / 3.0
        });
        centres
            .iter()
            .any(|h| (0..3).map(|k| (c[k] - h[k]).powi(2)).sum::<f32>() < radius * radius)
    };
    let triangles = mesh
        .triangles
        .iter()
        .copied()
        .filter(|t| !inside(t))
        .collect();
    compact(IndexedMesh {
        triangles,
        ..mesh.clone()
    })
}

/// Drops unreferenced vertices, keeping order.
pub fn compact(mesh: IndexedMesh) -> IndexedMesh {
    let mut map = vec![u32::MAX; mesh.positions.len()];
    let mut order = Vec::new();
    for t in &mesh.triangles {
        for &v in t {
            if map[v as usize] == u32::MAX {
                map[v as usize] = 0;
            }
        }
    }
    for (v, m) in map.iter_mut().enumerate() {
        if *m == 0 {
            *m = order.len() as u32;
            order.push(v);
        }
    }
    IndexedMesh {
        positions: order.iter().map(|&v| mesh.positions[v]).collect(),
        colors: mesh
            .colors
            .as_ref()
            .map(|c| order.iter().map(|&v| c[v]).collect()),
        triangles: mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| map[v as usize]))
            .collect(),
    }
}

/// Several meshes side by side as one mesh with several components.
pub fn merge(meshes: &[IndexedMesh], spacing: f32) -> IndexedMesh {
    let mut out = IndexedMesh {
        colors: meshes.iter().all(|m| m.colors.is_some()).then(Vec::new),
        ..Default::default()
    };
    for (i, m) in meshes.iter().enumerate() {
        let base = out.positions.len() as u32;
        out.positions.extend(
            m.positions
                .iter()
                .map(|p| [p[0] + i as f32 * spacing, p[1], p[2]]),
        );
        if let (Some(c), Some(mc)) = (&mut out.colors, &m.colors) {
            c.extend_from_slice(mc);
        }
        out.triangles
            .extend(m.triangles.iter().map(|t| t.map(|v| v + base)));
    }
    out
}

/// Displaces every vertex by up to `amplitude` (deterministic for a seed): scan noise.
pub fn add_noise(mesh: &mut IndexedMesh, amplitude: f32, seed: u64) {
    let mut state = seed;
    let mut rand = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((state >> 40) as f32 / (1u64 << 24) as f32) * 2.0 - 1.0
    };
    for p in &mut mesh.positions {
        for c in p.iter_mut() {
            *c += amplitude * rand();
        }
    }
}

/// Paints a smooth pattern with sharp stripes, as a stand-in for a photographed surface.
pub fn paint(mesh: &mut IndexedMesh) {
    let colours = mesh
        .positions
        .iter()
        .map(|p| {
            let stripe =
                ((p[0] * 6.0).floor() as i32 + (p[2] * 6.0).floor() as i32).rem_euclid(2) == 0;
            let r = 0.5 + 0.5 * (p[1] * 3.0).sin();
            let g = 0.5 + 0.5 * (p[0] * 2.0 + 1.0).cos();
            let b = if stripe { 0.85 } else { 0.2 };
            [r, g, b].map(|c| (c * 255.0).round().clamp(0.0, 255.0) as u8)
        })
        .collect();
    mesh.colors = Some(colours);
}
