//! A generated, animated MD2 model for tests, fuzz seeds and demos (no game
//! asset is ever copied into the repository): a torus in Quake's axes whose
//! frames breathe and sway, textured through a skin named `skin.png` with a
//! UV seam where the parameterisation wraps.

use std::f32::consts::TAU;

use super::md2::{gl_commands, quantize_frame, skin_name};
use crate::import::md2::{quake_to_y_up, Md2, Md2Triangle};

/// Skin size of [`sample_md2`].
pub const SAMPLE_SKIN: (i32, i32) = (64, 32);

/// Torus position of grid vertex (i, j) at frame `k` of `frames`, in Quake's axes.
fn position(i: u32, j: u32, rings: u32, sides: u32, k: usize, frames: usize) -> [f32; 3] {
    let (a, b) = (TAU * i as f32 / rings as f32, TAU * j as f32 / sides as f32);
    let phase = TAU * k as f32 / frames.max(1) as f32;
    let (big, small) = (20.0, 7.0 + 2.0 * phase.sin());
    let ring = big + small * b.cos();
    [
        ring * a.cos() + 3.0 * phase.cos(),
        ring * a.sin(),
        small * b.sin() * (1.0 + 0.25 * (a + phase).sin()) + 24.0,
    ]
}

/// A `rings × sides` torus with `frames` key frames (at least one); its
/// texture coordinates form a `(rings + 1) × (sides + 1)` grid, so the
/// vertices where the torus closes carry two (a seam).
pub fn sample_md2(rings: u32, sides: u32, frames: usize) -> Md2 {
    let (rings, sides, frames) = (rings.max(3), sides.max(3), frames.max(1));
    let vertex = |i: u32, j: u32| ((i % rings) * sides + (j % sides)) as u16;
    let st_index = |i: u32, j: u32| (i * (sides + 1) + j) as u16;
    let (w, h) = SAMPLE_SKIN;
    let st = (0..=rings)
        .flat_map(|i| {
            (0..=sides).map(move |j| {
                [
                    (i as i32 * (w - 1) / rings as i32) as i16,
                    (j as i32 * (h - 1) / sides as i32) as i16,
                ]
            })
        })
        .collect();
    let mut triangles = Vec::new();
    for i in 0..rings {
        for j in 0..sides {
            let c = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)];
            // Clockwise seen from outside, as MD2 winds them.
            for [x, y, z] in [[c[0], c[2], c[1]], [c[0], c[3], c[2]]] {
                triangles.push(Md2Triangle {
                    vertex: [x, y, z].map(|(a, b)| vertex(a, b)),
                    st: [x, y, z].map(|(a, b)| st_index(a, b)),
                });
            }
        }
    }
    let ccw: Vec<[u32; 3]> = triangles
        .iter()
        .map(|t: &Md2Triangle| [t.vertex[0], t.vertex[2], t.vertex[1]].map(u32::from))
        .collect();
    let frames = (0..frames)
        .map(|k| {
            let positions: Vec<[f32; 3]> = (0..rings)
                .flat_map(|i| (0..sides).map(move |j| (i, j)))
                .map(|(i, j)| quake_to_y_up(position(i, j, rings, sides, k, frames)))
                .collect();
            quantize_frame(&positions, &ccw, &format!("sway{k:02}"))
                .expect("finite sample positions")
        })
        .collect();
    let mut model = Md2 {
        skin_width: w,
        skin_height: h,
        skins: vec![skin_name("skin.png")],
        st,
        triangles,
        frames,
        gl_commands: Vec::new(),
    };
    model.gl_commands = gl_commands(&model);
    model
}
