//! A small z-buffered CPU rasterizer for the image metric, lit like the WebGL
//! viewer (`web/src/shading.js`) so snapshots look like what visitors see.
//!
//! Rendering is deferred: a first pass rasterizes every triangle into a depth
//! buffer (1/z, interpolated linearly in screen space, which is exact under
//! perspective) and keeps the nearest triangle's index per pixel; a second pass
//! shades each covered pixel once, intersecting the pixel-centre ray with that
//! triangle to get perspective-correct barycentric coordinates and the exact
//! world-space position. Triangles are two-sided (the viewer does not cull:
//! scans have holes) and clipped against the near plane; pixels are sampled at
//! their centres, without anti-aliasing.

use glam::Vec3;
use vitrine_codec::IndexedMesh;

/// Where a fragment's colour comes from.
///
/// `Sync` so the views of the image metric can render on several threads.
pub trait SurfaceShader: Sync {
    /// The surface's albedo at a fragment, **sRGB-encoded, each channel in
    /// `0..=1`** (as the viewer's vertex colours and textures are); lighting
    /// linearises it. `triangle` indexes `mesh.triangles`, `barycentric`
    /// weighs its three corners in their order (perspective-correct, summing
    /// to 1), and `world` is the fragment's interpolated world-space position.
    fn colour(&self, triangle: usize, barycentric: [f32; 3], world: Vec3) -> [f32; 3];
}

/// Per-vertex sRGB colours, interpolated across each triangle (in sRGB, like the viewer).
#[derive(Clone, Copy, Debug)]
pub struct VertexColours<'a> {
    colours: &'a [[u8; 3]],
    triangles: &'a [[u32; 3]],
}

impl<'a> VertexColours<'a> {
    /// `None` unless the mesh has exactly one colour per vertex.
    pub fn new(mesh: &'a IndexedMesh) -> Option<Self> {
        let colours = mesh.colors.as_deref()?;
        (colours.len() == mesh.positions.len()).then_some(Self {
            colours,
            triangles: &mesh.triangles,
        })
    }
}

impl SurfaceShader for VertexColours<'_> {
    fn colour(&self, triangle: usize, barycentric: [f32; 3], _world: Vec3) -> [f32; 3] {
        let t = self.triangles[triangle];
        let mut c = [0.0f32; 3];
        for (v, b) in t.iter().zip(barycentric) {
            let vc = self.colours[*v as usize];
            for k in 0..3 {
                c[k] += b * f32::from(vc[k]);
            }
        }
        c.map(|x| x / 255.0)
    }
}

/// One sRGB colour (channels `0..=1`) everywhere.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ConstantColour(pub [f32; 3]);

impl ConstantColour {
    /// The viewer's clay grey for streams without colour.
    pub const CLAY: Self = Self([0.78, 0.75, 0.70]);
}

impl SurfaceShader for ConstantColour {
    fn colour(&self, _triangle: usize, _barycentric: [f32; 3], _world: Vec3) -> [f32; 3] {
        self.0
    }
}

/// What the viewer shows for a mesh: its vertex colours, or clay without them.
pub fn default_shader(mesh: &IndexedMesh) -> Box<dyn SurfaceShader + '_> {
    match VertexColours::new(mesh) {
        Some(v) => Box::new(v),
        None => Box::new(ConstantColour::CLAY),
    }
}

/// A pinhole camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub eye: Vec3,
    /// The point at the image centre.
    pub target: Vec3,
    /// Roughly up; need not be orthogonal to the view direction, only not parallel.
    pub up: Vec3,
    /// Vertical field of view in radians.
    pub fov_y: f32,
    /// Distance of the near clipping plane (> 0). There is no far plane.
    pub near: f32,
}

/// Lighting in view space (+x right, +y up, +z towards the viewer), so it turns
/// with the camera like a headlight. Albedo is linearised with gamma 2.2, lit,
/// and re-encoded with 1/2.2, exactly as the viewer's fragment shader does:
/// `albedo^2.2 · (ambient + Σ intensity · max(n·l, 0)) + specular`, where the
/// ambient term blends `ground` to `sky` by the normal's height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    pub ground: f32,
    pub sky: f32,
    /// Unit direction towards the key light.
    pub key: Vec3,
    pub key_intensity: f32,
    /// Unit direction towards the fill light.
    pub fill: Vec3,
    pub fill_intensity: f32,
    /// Blinn–Phong highlight of the key light (white, added after the albedo).
    pub specular: f32,
    pub shininess: f32,
}

impl Lighting {
    /// The viewer's studio rig (the constants of `web/src/shading.js`).
    pub fn viewer() -> Self {
        Self {
            ground: 0.12,
            sky: 0.22,
            key: Vec3::new(-0.45, 0.6, 0.75).normalize(),
            key_intensity: 0.8,
            fill: Vec3::new(0.55, -0.15, 0.6).normalize(),
            fill_intensity: 0.35,
            specular: 0.12,
            shininess: 32.0,
        }
    }

    /// Plain Lambert from a light at the eye plus `ambient`: a surface facing
    /// the camera shows exactly its albedo.
    pub fn headlight(ambient: f32) -> Self {
        Self {
            ground: ambient,
            sky: ambient,
            key: Vec3::Z,
            key_intensity: 1.0 - ambient,
            fill: Vec3::Z,
            fill_intensity: 0.0,
            specular: 0.0,
            shininess: 1.0,
        }
    }

    /// The lit colour (sRGB, `0..=1`) of albedo `srgb` under unit view-space normal `n`.
    pub fn shade(&self, n: Vec3, srgb: [f32; 3]) -> [f32; 3] {
        self.linear(n, srgb)
            .map(|c| c.clamp(0.0, 1.0).powf(1.0 / 2.2))
    }

    /// [`Lighting::shade`] before gamma encoding (not clamped).
    fn linear(&self, n: Vec3, srgb: [f32; 3]) -> [f32; 3] {
        let ambient = self.ground + (self.sky - self.ground) * (0.5 + 0.5 * n.y);
        let light = ambient
            + self.key_intensity * n.dot(self.key).max(0.0)
            + self.fill_intensity * n.dot(self.fill).max(0.0);
        let spec = if self.specular > 0.0 {
            let half = (self.key + Vec3::Z).normalize();
            let cos = n.dot(half).max(0.0);
            let power = if self.shininess.fract() == 0.0 && self.shininess.abs() < 256.0 {
                cos.powi(self.shininess as i32)
            } else {
                cos.powf(self.shininess)
            };
            self.specular * power
        } else {
            0.0
        };
        srgb.map(|c| c.clamp(0.0, 1.0).powf(2.2) * light + spec)
    }
}

/// `round(255 · clamp(x, 0, 1)^(1/2.2))`, the viewer's gamma encoding to 8 bits,
/// through a table (exactly, up to rounding of the thresholds).
fn encode(x: f32) -> u8 {
    const BUCKETS: usize = 1 << 14;
    struct Table {
        /// The code of the bucket's lower end.
        start: Vec<u8>,
        /// The linear value from which code k applies.
        threshold: [f32; 256],
    }
    static TABLE: std::sync::OnceLock<Table> = std::sync::OnceLock::new();
    let table = TABLE.get_or_init(|| {
        let code = |x: f32| (x.powf(1.0 / 2.2) * 255.0).round() as u8;
        Table {
            start: (0..BUCKETS)
                .map(|i| code(i as f32 / BUCKETS as f32))
                .collect(),
            threshold: std::array::from_fn(|k| ((k as f32 - 0.5).max(0.0) / 255.0).powf(2.2)),
        }
    });
    let x = x.clamp(0.0, 1.0);
    let mut k = table.start[((x * BUCKETS as f32) as usize).min(BUCKETS - 1)];
    while k < 255 && x >= table.threshold[k as usize + 1] {
        k += 1;
    }
    k
}

impl Default for Lighting {
    fn default() -> Self {
        Self::viewer()
    }
}

/// Image size, background and lighting.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    pub width: u32,
    pub height: u32,
    /// sRGB, `0..=1`; the viewer's canvas colour by default.
    pub background: [f32; 3],
    pub lighting: Lighting,
}

impl RenderOptions {
    /// The viewer's background and lighting at `size × size` pixels.
    pub fn square(size: u32) -> Self {
        Self {
            width: size,
            height: size,
            background: [0.13, 0.14, 0.16],
            lighting: Lighting::viewer(),
        }
    }
}

impl Default for RenderOptions {
    /// 512 × 512, as Lindstrom and Turk.
    fn default() -> Self {
        Self::square(512)
    }
}

/// A rendered image, row-major from the top-left corner.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    /// sRGB, 8 bits per channel.
    pub rgb: Vec<[u8; 3]>,
    /// Luma of `rgb` with Rec. 709 weights (`0.2126 R + 0.7152 G + 0.0722 B`),
    /// in 0–255 units.
    pub luminance: Vec<f32>,
    /// The triangle seen at each pixel, or [`Frame::BACKGROUND`].
    pub triangle: Vec<u32>,
}

impl Frame {
    /// `triangle` value of a pixel that shows the background.
    pub const BACKGROUND: u32 = u32::MAX;

    /// Pixels that show the mesh.
    pub fn covered(&self) -> usize {
        self.triangle
            .iter()
            .filter(|&&t| t != Self::BACKGROUND)
            .count()
    }

    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        self.rgb[(y * self.width + x) as usize]
    }

    pub fn to_image(&self) -> image::RgbImage {
        let bytes = self.rgb.iter().flatten().copied().collect();
        image::RgbImage::from_raw(self.width, self.height, bytes).expect("one pixel per triple")
    }

    pub fn write_png(&self, path: impl AsRef<std::path::Path>) -> image::ImageResult<()> {
        self.to_image()
            .save_with_format(path, image::ImageFormat::Png)
    }
}

/// Rec. 709 luma of an 8-bit sRGB pixel, 0–255.
fn luma(c: [u8; 3]) -> f32 {
    0.2126 * f32::from(c[0]) + 0.7152 * f32::from(c[1]) + 0.0722 * f32::from(c[2])
}

/// Area-weighted vertex normals (unnormalised, as the viewer's `vertexNormals`).
pub(crate) fn vertex_normals(mesh: &IndexedMesh) -> Vec<Vec3> {
    let mut normals = vec![Vec3::ZERO; mesh.positions.len()];
    for t in valid_triangles(mesh).map(|(_, t)| t) {
        let [a, b, c] = t.map(|v| Vec3::from(mesh.positions[v as usize]));
        let n = (b - a).cross(c - a);
        for v in t {
            normals[v as usize] += n;
        }
    }
    normals
}

fn valid_triangles(mesh: &IndexedMesh) -> impl Iterator<Item = (usize, [u32; 3])> + '_ {
    let n = mesh.positions.len();
    mesh.triangles
        .iter()
        .copied()
        .enumerate()
        .filter(move |(_, t)| t.iter().all(|&v| (v as usize) < n))
}

/// The camera's orthonormal frame and projection.
struct View {
    eye: Vec3,
    right: Vec3,
    up: Vec3,
    forward: Vec3,
    tan_x: f32,
    tan_y: f32,
    width: f32,
    height: f32,
}

impl View {
    fn new(camera: &Camera, width: u32, height: u32) -> Self {
        let forward = (camera.target - camera.eye).normalize();
        let right = forward.cross(camera.up).normalize();
        let up = right.cross(forward);
        let tan_y = (camera.fov_y * 0.5).tan();
        Self {
            eye: camera.eye,
            right,
            up,
            forward,
            tan_x: tan_y * width as f32 / height as f32,
            tan_y,
            width: width as f32,
            height: height as f32,
        }
    }

    /// (right, up, depth in front of the eye).
    fn to_view(&self, p: Vec3) -> Vec3 {
        let d = p - self.eye;
        Vec3::new(d.dot(self.right), d.dot(self.up), d.dot(self.forward))
    }

    /// Screen x, y in pixels (y down) and 1/depth; `v.z` must be positive.
    fn project(&self, v: Vec3) -> Vec3 {
        let iz = 1.0 / v.z;
        Vec3::new(
            (v.x * iz / self.tan_x + 1.0) * 0.5 * self.width,
            (1.0 - v.y * iz / self.tan_y) * 0.5 * self.height,
            iz,
        )
    }

    /// World-space direction of the ray through screen point (x, y).
    fn ray(&self, x: f32, y: f32) -> Vec3 {
        let nx = (2.0 * x / self.width - 1.0) * self.tan_x;
        let ny = (1.0 - 2.0 * y / self.height) * self.tan_y;
        self.forward + self.right * nx + self.up * ny
    }
}

struct Buffers {
    width: usize,
    height: usize,
    inverse_depth: Vec<f32>,
    triangle: Vec<u32>,
}

impl Buffers {
    /// Rasterizes screen triangle `p` (x, y, 1/z) as triangle `id`: a pixel is
    /// covered when its centre is inside or on an edge; the nearest triangle wins
    /// and the first one drawn keeps a tie.
    fn triangle(&mut self, p: [Vec3; 3], id: u32) {
        let [p0, mut p1, mut p2] = p;
        let mut area = (p1.x - p0.x) * (p2.y - p0.y) - (p1.y - p0.y) * (p2.x - p0.x);
        if area.is_nan() || area == 0.0 {
            return;
        }
        if area < 0.0 {
            std::mem::swap(&mut p1, &mut p2);
            area = -area;
        }
        let min = p0.min(p1).min(p2);
        let max = p0.max(p1).max(p2);
        let x0 = (min.x - 0.5).ceil().max(0.0);
        let y0 = (min.y - 0.5).ceil().max(0.0);
        let x1 = (max.x - 0.5).floor().min(self.width as f32 - 1.0);
        let y1 = (max.y - 0.5).floor().min(self.height as f32 - 1.0);
        if x0 > x1 || y0 > y1 {
            return;
        }
        // Edge i (opposite corner i): e_i(x, y) = a_i x + b_i y + c_i, e_0 + e_1 + e_2 = area.
        let edge = |a: Vec3, b: Vec3| {
            let (ea, eb) = (a.y - b.y, b.x - a.x);
            (ea, eb, -(ea * a.x + eb * a.y))
        };
        let e = [edge(p1, p2), edge(p2, p0), edge(p0, p1)];
        let inv = 1.0 / area;
        let za = (e[0].0 * p0.z + e[1].0 * p1.z + e[2].0 * p2.z) * inv;
        let zb = (e[0].1 * p0.z + e[1].1 * p1.z + e[2].1 * p2.z) * inv;
        let zc = (e[0].2 * p0.z + e[1].2 * p1.z + e[2].2 * p2.z) * inv;
        let (x0, x1, y0, y1) = (x0 as usize, x1 as usize, y0 as usize, y1 as usize);
        for y in y0..=y1 {
            let cy = y as f32 + 0.5;
            let cx = x0 as f32 + 0.5;
            let mut w = e.map(|(a, b, c)| a * cx + b * cy + c);
            let mut z = za * cx + zb * cy + zc;
            let row = y * self.width;
            for x in x0..=x1 {
                if w[0] >= 0.0 && w[1] >= 0.0 && w[2] >= 0.0 && z > self.inverse_depth[row + x] {
                    self.inverse_depth[row + x] = z;
                    self.triangle[row + x] = id;
                }
                for k in 0..3 {
                    w[k] += e[k].0;
                }
                z += za;
            }
        }
    }
}

/// Renders `mesh` seen from `camera`, colouring it with `shader`, lit by
/// `options.lighting` with smooth (area-weighted) vertex normals, on
/// `options.background`. Triangles with an out-of-range index are skipped.
pub fn render(
    mesh: &IndexedMesh,
    shader: &dyn SurfaceShader,
    camera: &Camera,
    options: &RenderOptions,
) -> Frame {
    let (width, height) = (options.width as usize, options.height as usize);
    let view = View::new(camera, options.width, options.height);
    let mut buffers = Buffers {
        width,
        height,
        inverse_depth: vec![0.0; width * height],
        triangle: vec![Frame::BACKGROUND; width * height],
    };
    let near = camera.near;
    let in_view: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|p| view.to_view(Vec3::from(*p)))
        .collect();
    let projected: Vec<Vec3> = in_view
        .iter()
        .map(|&v| {
            if v.z >= near {
                view.project(v)
            } else {
                Vec3::NAN
            }
        })
        .collect();
    for (t, tri) in valid_triangles(mesh) {
        let [a, b, c] = tri.map(|v| v as usize);
        let front = [a, b, c].map(|v| in_view[v].z >= near);
        if front.iter().all(|&f| f) {
            buffers.triangle([projected[a], projected[b], projected[c]], t as u32);
        } else if front.iter().any(|&f| f) {
            // Sutherland–Hodgman against the near plane: 3 or 4 corners remain.
            let corners = [in_view[a], in_view[b], in_view[c]];
            let mut polygon = [Vec3::ZERO; 4];
            let mut n = 0;
            for i in 0..3 {
                let (p, q) = (corners[i], corners[(i + 1) % 3]);
                if p.z >= near {
                    polygon[n] = p;
                    n += 1;
                }
                if (p.z >= near) != (q.z >= near) {
                    polygon[n] = p.lerp(q, (near - p.z) / (q.z - p.z));
                    n += 1;
                }
            }
            for i in 1..n - 1 {
                buffers.triangle(
                    [polygon[0], polygon[i], polygon[i + 1]].map(|v| view.project(v)),
                    t as u32,
                );
            }
        }
    }

    let normals = vertex_normals(mesh);
    let background = options
        .background
        .map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
    let mut rgb = vec![background; width * height];
    for (i, &t) in buffers.triangle.iter().enumerate() {
        if t == Frame::BACKGROUND {
            continue;
        }
        let (x, y) = ((i % width) as f32 + 0.5, (i / width) as f32 + 0.5);
        let tri = mesh.triangles[t as usize];
        let [p0, p1, p2] = tri.map(|v| Vec3::from(mesh.positions[v as usize]));
        let dir = view.ray(x, y);
        let bary = ray_barycentric(view.eye, dir, [p0, p1, p2]);
        let world = p0 * bary[0] + p1 * bary[1] + p2 * bary[2];
        let geometric = (p1 - p0).cross(p2 - p0);
        let mut n = normals[tri[0] as usize] * bary[0]
            + normals[tri[1] as usize] * bary[1]
            + normals[tri[2] as usize] * bary[2];
        if n.length_squared() == 0.0 || !n.is_finite() {
            n = geometric;
        }
        let mut n = n.normalize_or(-dir.normalize());
        // Seen from behind (through a hole): lit like the front, as in the viewer.
        if geometric.dot(view.eye - world) < 0.0 {
            n = -n;
        }
        let n_view = Vec3::new(n.dot(view.right), n.dot(view.up), -n.dot(view.forward));
        let albedo = shader.colour(t as usize, bary, world);
        rgb[i] = options.lighting.linear(n_view, albedo).map(encode);
    }
    let luminance = rgb.iter().map(|&c| luma(c)).collect();
    Frame {
        width: options.width,
        height: options.height,
        rgb,
        luminance,
        triangle: buffers.triangle,
    }
}

/// Barycentric coordinates of the ray's hit with the plane of triangle `p`
/// (Möller–Trumbore), clamped onto the triangle; the centroid for a ray
/// parallel to it.
fn ray_barycentric(origin: Vec3, dir: Vec3, p: [Vec3; 3]) -> [f32; 3] {
    let e1 = p[1] - p[0];
    let e2 = p[2] - p[0];
    let pv = dir.cross(e2);
    let det = e1.dot(pv);
    if det == 0.0 || !det.is_finite() {
        return [1.0 / 3.0; 3];
    }
    let tv = origin - p[0];
    let u = tv.dot(pv) / det;
    let v = dir.dot(tv.cross(e1)) / det;
    let b = [1.0 - u - v, u, v].map(|x| x.max(0.0));
    let sum = b[0] + b[1] + b[2];
    if sum > 0.0 && sum.is_finite() {
        b.map(|x| x / sum)
    } else {
        [1.0 / 3.0; 3]
    }
}

#[cfg(test)]
mod tests {
    use super::encode;

    #[test]
    fn the_encoding_table_matches_the_power_law() {
        for i in 0..=200_000 {
            let x = i as f32 / 200_000.0;
            let exact = x.powf(1.0 / 2.2) * 255.0;
            let code = f32::from(encode(x));
            // Equal, except within float noise of a rounding boundary.
            assert!(
                (code - exact.round()).abs() == 0.0 || (exact.fract() - 0.5).abs() < 1e-3,
                "{x}: {code} vs {exact}"
            );
        }
        assert_eq!(encode(-1.0), 0);
        assert_eq!(encode(2.0), 255);
        assert_eq!(encode(f32::NAN), 0);
    }
}
