//! Quality metrics: Hausdorff, Roy colour RMSE, the CPU rasterizer
//! and the Lindstrom–Turk image RMSE.

use glam::Vec3;
use vitrine_codec::IndexedMesh;
use vitrine_quality::metrics::{
    self, default_shader, hausdorff, image_rmse, render, roy_colour_rmse, views, Camera,
    ColourError, ConstantColour, Frame, Lighting, RenderOptions, SurfaceShader, VertexColours,
};
use vitrine_samples::{add_noise, compact, icosphere, paint, torus};

fn scaled(mesh: &IndexedMesh, s: f32) -> IndexedMesh {
    IndexedMesh {
        positions: mesh.positions.iter().map(|p| p.map(|c| c * s)).collect(),
        ..mesh.clone()
    }
}

fn painted(mut mesh: IndexedMesh) -> IndexedMesh {
    paint(&mut mesh);
    mesh
}

#[test]
fn hausdorff_of_a_mesh_with_itself_is_zero() {
    let mesh = torus(48, 24, 1.0, 0.3);
    let h = hausdorff(&mesh, &mesh, 20_000);
    for d in [
        h.a_to_b,
        h.b_to_a,
        h.symmetric,
        h.mean_a_to_b,
        h.mean_b_to_a,
    ] {
        assert!(d < 1e-9, "{h:?}");
    }
    // The torus spans 2.6 × 2.6 × 0.6.
    let diagonal = (2.6f64 * 2.6 * 2.0 + 0.6 * 0.6).sqrt();
    assert!((h.diagonal - diagonal).abs() < 1e-3, "{h:?}");
}

#[test]
fn hausdorff_of_a_sphere_and_the_same_sphere_scaled_by_1_01_is_a_hundredth_of_the_radius() {
    let a = icosphere(4);
    let b = scaled(&a, 1.01);
    let h = hausdorff(&a, &b, 50_000);
    for d in [h.a_to_b, h.b_to_a, h.symmetric] {
        assert!((d - 0.01).abs() < 2e-4, "{h:?}");
    }
    // Flat faces sit just inside the unit sphere, so the mean is a little below 0.01.
    for d in [h.mean_a_to_b, h.mean_b_to_a] {
        assert!(d > 0.0097 && d <= h.symmetric, "{h:?}");
    }
    assert!((h.relative() - 0.01 / 12f64.sqrt()).abs() < 1e-4, "{h:?}");
}

#[test]
fn hausdorff_of_part_of_a_surface_is_zero_one_way_only() {
    let whole = torus(40, 16, 1.0, 0.3);
    let half = compact(IndexedMesh {
        triangles: whole.triangles[..whole.triangles.len() / 2].to_vec(),
        ..whole.clone()
    });
    let h = hausdorff(&half, &whole, 20_000);
    assert!(h.a_to_b < 1e-6, "{h:?}");
    assert!(h.mean_a_to_b < 1e-6, "{h:?}");
    // The far side of the ring is about one major radius from the kept half's ends.
    assert!(h.b_to_a > 0.7 && h.b_to_a < 1.5, "{h:?}");
    assert!(h.mean_b_to_a > 0.05, "{h:?}");
    assert_eq!(h.symmetric, h.b_to_a);
    let swapped = hausdorff(&whole, &half, 20_000);
    assert!(swapped.b_to_a < 1e-6 && swapped.a_to_b > 0.7, "{swapped:?}");
}

#[test]
fn hausdorff_towards_a_mesh_without_faces_is_infinite() {
    let a = icosphere(1);
    let empty = IndexedMesh::default();
    let h = hausdorff(&a, &empty, 100);
    assert!(h.a_to_b.is_infinite());
    assert_eq!(h.b_to_a, 0.0);
}

/// Colours kept away from 0 and 255 so a shift does not saturate.
fn mid_range(mesh: &IndexedMesh) -> Vec<[u8; 3]> {
    mesh.colors
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| c.map(|x| x.clamp(10, 245)))
        .collect()
}

#[test]
fn roy_rmse_of_identical_meshes_is_zero_even_reordered() {
    let original = painted(icosphere(4));
    assert_eq!(roy_colour_rmse(&original, &original), Ok(0.0));
    // Reverse the vertex order: the nearest vertex is found by position, not index.
    let n = original.positions.len() as u32;
    let reversed = IndexedMesh {
        positions: original.positions.iter().rev().copied().collect(),
        colors: original
            .colors
            .as_ref()
            .map(|c| c.iter().rev().copied().collect()),
        triangles: original
            .triangles
            .iter()
            .map(|t| t.map(|v| n - 1 - v))
            .collect(),
    };
    assert_eq!(roy_colour_rmse(&original, &reversed), Ok(0.0));
}

#[test]
fn roy_rmse_of_a_recoloured_mesh_is_the_known_value() {
    let mut original = painted(icosphere(3));
    original.colors = Some(mid_range(&original));
    let mut approx = original.clone();
    // Every other vertex moves by (3, 4, 0): a colour distance of 5.
    for (i, c) in approx.colors.as_mut().unwrap().iter_mut().enumerate() {
        if i.is_multiple_of(2) {
            *c = [c[0] + 3, c[1] - 4, c[2]];
        }
    }
    let n = original.positions.len();
    let expected = (25.0 * n.div_ceil(2) as f64 / n as f64).sqrt();
    let rmse = roy_colour_rmse(&original, &approx).unwrap();
    assert!((rmse - expected).abs() < 1e-12, "{rmse} vs {expected}");
}

#[test]
fn roy_rmse_against_a_coarser_mesh_matches_a_brute_force_nearest_vertex() {
    let original = painted(torus(30, 12, 1.0, 0.35));
    // Keep every third vertex (positions only matter) and shift the colours a little.
    let mut approx = IndexedMesh::default();
    let mut colours = Vec::new();
    for (i, (p, c)) in original
        .positions
        .iter()
        .zip(original.colors.as_ref().unwrap())
        .enumerate()
    {
        if i.is_multiple_of(3) {
            approx.positions.push([p[0] * 1.02, p[1], p[2] + 0.01]);
            colours.push([c[0] / 2, c[1], 255 - c[2]]);
        }
    }
    approx.colors = Some(colours);
    let oc = original.colors.as_ref().unwrap();
    let ac = approx.colors.as_ref().unwrap();
    let mut sum = 0.0;
    for (p, c) in original.positions.iter().zip(oc) {
        let d2 = |q: &[f32; 3]| {
            (0..3)
                .map(|k| (f64::from(p[k]) - f64::from(q[k])).powi(2))
                .sum::<f64>()
        };
        let nearest = (0..approx.positions.len())
            .min_by(|&i, &j| d2(&approx.positions[i]).total_cmp(&d2(&approx.positions[j])))
            .unwrap();
        sum += (0..3)
            .map(|k| (f64::from(c[k]) - f64::from(ac[nearest][k])).powi(2))
            .sum::<f64>();
    }
    let expected = (sum / original.positions.len() as f64).sqrt();
    let rmse = roy_colour_rmse(&original, &approx).unwrap();
    assert!(expected > 10.0);
    assert!((rmse - expected).abs() < 1e-9, "{rmse} vs {expected}");
}

#[test]
fn roy_rmse_needs_colour_on_both_meshes() {
    let coloured = painted(icosphere(1));
    let plain = icosphere(1);
    assert_eq!(
        roy_colour_rmse(&plain, &coloured),
        Err(ColourError::OriginalHasNoColour)
    );
    assert_eq!(
        roy_colour_rmse(&coloured, &plain),
        Err(ColourError::ApproximationHasNoColour)
    );
    let mut short = coloured.clone();
    short.colors.as_mut().unwrap().pop();
    assert!(matches!(
        roy_colour_rmse(&coloured, &short),
        Err(ColourError::ColourCountMismatch { .. })
    ));
}

fn front_camera(distance: f32) -> Camera {
    Camera {
        eye: Vec3::new(0.0, 0.0, distance),
        target: Vec3::ZERO,
        up: Vec3::Y,
        fov_y: 40f32.to_radians(),
        near: 0.1,
    }
}

#[test]
fn a_sphere_renders_as_a_centred_filled_disc_of_the_right_size_and_colour() {
    let sphere = icosphere(5);
    let albedo = [0.8, 0.4, 0.2];
    let options = RenderOptions {
        lighting: Lighting::headlight(0.2),
        ..RenderOptions::square(512)
    };
    let frame = render(
        &sphere,
        &ConstantColour(albedo),
        &front_camera(3.0),
        &options,
    );
    // A sphere seen from distance d subtends asin(r / d); its outline is a circle.
    let radius_px = (1f32 / 3.0).asin().tan() / 20f32.to_radians().tan() * 256.0;
    let expected = std::f32::consts::PI * radius_px * radius_px;
    let covered = frame.covered() as f32;
    assert!(
        (covered / expected - 1.0).abs() < 0.005,
        "{covered} vs {expected}"
    );
    // Centred, and filled: every pixel well inside the outline is covered.
    let (mut sx, mut sy) = (0.0f64, 0.0f64);
    for y in 0..512u32 {
        for x in 0..512u32 {
            let i = (y * 512 + x) as usize;
            let r = ((x as f32 + 0.5 - 256.0).powi(2) + (y as f32 + 0.5 - 256.0).powi(2)).sqrt();
            let hit = frame.triangle[i] != Frame::BACKGROUND;
            if r < radius_px - 2.0 {
                assert!(hit, "hole at {x}, {y}");
            }
            if r > radius_px + 2.0 {
                assert!(!hit, "outside the disc at {x}, {y}");
            }
            if hit {
                sx += f64::from(x) + 0.5;
                sy += f64::from(y) + 0.5;
            }
        }
    }
    let n = frame.covered() as f64;
    assert!((sx / n - 256.0).abs() < 0.25 && (sy / n - 256.0).abs() < 0.25);
    // Facing the headlight, the surface shows its albedo exactly.
    let centre = frame.pixel(256, 256);
    let want = albedo.map(|c| (c * 255.0).round() as i32);
    for k in 0..3 {
        assert!(
            (i32::from(centre[k]) - want[k]).abs() <= 1,
            "{centre:?} vs {want:?}"
        );
    }
    // Darker towards the rim, background outside.
    assert!(frame.luminance[256 * 512 + 256] > frame.luminance[256 * 512 + 256 + 240]);
    let bg = RenderOptions::default()
        .background
        .map(|c| (c * 255.0).round() as u8);
    assert_eq!(frame.pixel(0, 0), bg);
    assert_eq!(frame.rgb.len(), 512 * 512);
}

/// Colours each fragment by which side of x = 0.3 its world position lies.
struct SplitAtX;

impl SurfaceShader for SplitAtX {
    fn colour(&self, _triangle: usize, _barycentric: [f32; 3], world: Vec3) -> [f32; 3] {
        if world.x > 0.3 {
            [1.0; 3]
        } else {
            [0.0; 3]
        }
    }
}

#[test]
fn fragments_get_perspective_correct_world_positions_and_barycentrics() {
    // A square in the plane z = -x, receding to the right: affine interpolation
    // would put the boundary at x = 0.3 in the wrong column.
    let quad = IndexedMesh {
        positions: vec![
            [-1.0, -1.0, 1.0],
            [1.0, -1.0, -1.0],
            [1.0, 1.0, -1.0],
            [-1.0, 1.0, 1.0],
        ],
        colors: Some(vec![[0, 0, 0], [255, 255, 255], [255, 255, 255], [0, 0, 0]]),
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let camera = front_camera(4.0);
    let options = RenderOptions {
        lighting: Lighting::headlight(1.0),
        ..RenderOptions::square(256)
    };
    let frame = render(&quad, &SplitAtX, &camera, &options);
    // Where world x = 0.3 (so z = -0.3) lands on the middle row.
    let column = (0.3 / (4.0 + 0.3)) / 20f32.to_radians().tan() * 128.0 + 128.0;
    let row = 128 * 256;
    for x in 0..256usize {
        let centre = x as f32 + 0.5;
        if frame.triangle[row + x] == Frame::BACKGROUND || (centre - column).abs() < 1.0 {
            continue;
        }
        let white = frame.rgb[row + x][0] > 128;
        assert_eq!(white, centre > column, "column {x}, boundary at {column}");
    }
    // Vertex colours: the interpolated grey is linear in world x, so mid-grey at x = 0.
    let grey = render(
        &quad,
        &VertexColours::new(&quad).unwrap(),
        &camera,
        &options,
    );
    let mid = (0.0f32 / 4.0) / 20f32.to_radians().tan() * 128.0 + 128.0;
    let value = grey.rgb[row + mid as usize][0];
    assert!((i32::from(value) - 128).abs() <= 2, "{value}");
}

#[test]
fn the_24_views_are_the_vertices_of_a_small_rhombicuboctahedron() {
    let dirs = views::directions();
    assert!(dirs.iter().sum::<Vec3>().length() < 1e-5);
    let angle = |a: Vec3, b: Vec3| a.dot(b).clamp(-1.0, 1.0).acos();
    let edge = angle(dirs[0], dirs[1]).min(angle(dirs[0], dirs[8]));
    for (i, &a) in dirs.iter().enumerate() {
        assert!((a.length() - 1.0).abs() < 1e-6);
        let mut neighbours = 0;
        for (j, &b) in dirs.iter().enumerate() {
            if i != j {
                let t = angle(a, b);
                assert!(t > edge - 1e-4, "{i} {j}");
                neighbours += usize::from(t < edge + 1e-4);
            }
        }
        assert_eq!(neighbours, 4, "vertex {i}");
    }
    // Equal edges of a unit-circumradius small rhombicuboctahedron: 2 / sqrt(5 + 2√2).
    let chord = 2.0 * (edge / 2.0).sin();
    assert!((chord - 2.0 / (5.0 + 2.0 * 2f32.sqrt()).sqrt()).abs() < 1e-4);
    let center = Vec3::new(1.0, 2.0, 3.0);
    for camera in views::rhombicuboctahedron(center, 2.0) {
        assert_eq!(camera.target, center);
        let d = (camera.eye - center).length();
        assert!((d - 1.1 * 2.0 / 20f32.to_radians().sin()).abs() < 1e-3);
        assert!(camera.near > 0.0 && camera.near < d - 2.0);
    }
}

#[test]
fn image_rmse_is_zero_for_identical_meshes_and_grows_with_noise() {
    let reference = painted(icosphere(4));
    let shader = VertexColours::new(&reference).unwrap();
    assert_eq!(
        image_rmse((&reference, &shader), (&reference, &shader), 96),
        0.0
    );
    let mut previous = 0.0;
    for amplitude in [0.003, 0.012, 0.05] {
        let mut noisy = reference.clone();
        add_noise(&mut noisy, amplitude, 7);
        let noisy_shader = VertexColours::new(&noisy).unwrap();
        let e = image_rmse((&reference, &shader), (&noisy, &noisy_shader), 96);
        assert!(
            e > previous * 1.2,
            "amplitude {amplitude}: {e} after {previous}"
        );
        previous = e;
    }
    // Geometry alone: clay against colour differs.
    let clay = image_rmse(
        (&reference, &shader),
        (&reference, &ConstantColour::CLAY),
        64,
    );
    assert!(clay > 5.0, "{clay}");
    let per_view = metrics::image_rmse_per_view(
        (&reference, &*default_shader(&reference)),
        (&reference, &ConstantColour::CLAY),
        &RenderOptions::square(64),
    );
    let rms = (per_view.iter().map(|e| e * e).sum::<f64>() / 24.0).sqrt();
    assert!((rms - clay).abs() < 1e-9);
}

#[test]
fn rendering_clips_against_the_near_plane() {
    // The camera sits inside the sphere: it sees the inside everywhere.
    let sphere = icosphere(3);
    let camera = Camera {
        eye: Vec3::new(0.0, 0.0, 0.5),
        near: 0.05,
        ..front_camera(0.5)
    };
    let frame = render(
        &sphere,
        &ConstantColour::CLAY,
        &camera,
        &RenderOptions::square(64),
    );
    assert_eq!(frame.covered(), 64 * 64);
}

/// Timings quoted in the report: `cargo test --release -p vitrine-quality --test metrics -- --ignored --nocapture`.
#[test]
#[ignore]
fn timing_on_100k_meshes() {
    use std::time::Instant;
    let a = painted(torus(400, 125, 1.0, 0.3)); // 50k vertices, 100k triangles
    let mut b = a.clone();
    add_noise(&mut b, 0.002, 1);
    let big = painted(torus(500, 200, 1.0, 0.3)); // 100k vertices, 200k triangles
    let mut big_noisy = big.clone();
    add_noise(&mut big_noisy, 0.002, 1);
    let t = Instant::now();
    let h = hausdorff(&big, &big_noisy, 100_000);
    println!(
        "hausdorff 100k vertices, 100k samples per mesh: {:?} {h:?}",
        t.elapsed()
    );
    let t = Instant::now();
    let r = roy_colour_rmse(&big, &big_noisy).unwrap();
    println!("roy 100k vertices: {:?} ({r})", t.elapsed());
    let (sa, sb) = (
        VertexColours::new(&a).unwrap(),
        VertexColours::new(&b).unwrap(),
    );
    let t = Instant::now();
    let e = image_rmse((&a, &sa), (&b, &sb), 512);
    println!(
        "image_rmse 2 × 24 views of 100k triangles at 512²: {:?} ({e})",
        t.elapsed()
    );
    let (c, r) = views::bounding_sphere(&a);
    let camera = views::rhombicuboctahedron(c, r)[0];
    let t = Instant::now();
    for _ in 0..10 {
        std::hint::black_box(render(&a, &sa, &camera, &RenderOptions::default()));
    }
    println!("one 512² view of 100k triangles: {:?}", t.elapsed() / 10);
}

/// Points on a mesh's surface are at distance 0 from it; points lifted off
/// a flat face by h are at h (up to f32 positions).
#[test]
fn distances_to_surface_measure_points_off_the_surface() {
    use glam::DVec3;
    let sphere = icosphere(3);
    let on: Vec<DVec3> = sphere
        .positions
        .iter()
        .map(|p| DVec3::from(p.map(f64::from)))
        .collect();
    let d = vitrine_quality::metrics::distances_to_surface(&on, &sphere);
    assert!(
        d.iter().all(|&x| x < 1e-6),
        "{:?}",
        d.iter().cloned().fold(0.0, f64::max)
    );
    let square = IndexedMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        colors: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    };
    let lifted = [
        DVec3::new(0.25, 0.5, 0.3),
        DVec3::new(0.9, 0.1, -0.05),
        DVec3::new(2.0, 0.5, 0.0),
    ];
    let d = vitrine_quality::metrics::distances_to_surface(&lifted, &square);
    assert!(
        (d[0] - 0.3).abs() < 1e-9 && (d[1] - 0.05).abs() < 1e-9,
        "{d:?}"
    );
    assert!((d[2] - 1.0).abs() < 1e-9, "beside the square: {}", d[2]);
}
