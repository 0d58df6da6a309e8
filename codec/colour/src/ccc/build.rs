//! Building the complex from the full-resolution surface: cells, centres of
//! projection, and one tile of colour per face the surface shows through.

use glam::{DVec2, DVec3, IVec3};
use rayon::prelude::*;

use super::grid::{for_each_overlapped_cube, Grid, MAX_CUBES};
use super::projection::{face_point, other_axes, FACES};
use super::{CccOptions, ColourSource};
use vitrine_codec::{Error, IndexedMesh, Quantization, Result};
use vitrine_mesh::texel::sample_bilinear;

/// Rays look this far past the cube's face (in units of the distance to it),
/// so a coarse face bulging just outside the fine surface still finds colour.
const RAY_REACH: f64 = 1.5;
/// Triangles are binned into cubes grown by this fraction of the edge.
const BIN_MARGIN: f64 = 0.25;
/// Two hits inside a cube farther apart than this (fraction of the edge)
/// make a texel ambiguous: the surface folds within the cell.
const AMBIGUITY_GAP: f64 = 0.1;

/// One cell of the complex during construction.
#[derive(Clone, Debug)]
pub(crate) struct Cell {
    /// Centre of projection as bytes of the cube's edge (`CCC.md`).
    pub centre: [u8; 3],
    /// Tiles of the faces the surface shows through, by face.
    pub tiles: [Option<Vec<[u8; 3]>>; FACES],
    pub mean: [u8; 3],
}

/// The complex before its images are written.
pub(crate) struct Built {
    pub grid: Grid,
    /// Cell number of each cube, `u32::MAX` for an empty cube.
    pub cell_of_cube: Vec<u32>,
    pub cells: Vec<Cell>,
    pub tile_size: u32,
    pub ambiguous_texels: u64,
    pub covered_texels: u64,
}

/// The surface the rays hit and how to colour a hit.
struct ColourSurface<'a> {
    positions: Vec<DVec3>,
    triangles: &'a [[u32; 3]],
    colour: SurfaceColour<'a>,
}

enum SurfaceColour<'a> {
    Vertex(&'a [[u8; 3]]),
    Texture {
        uvs: &'a [[f32; 2]],
        image: &'a image::RgbImage,
    },
}

impl ColourSurface<'_> {
    fn colour(&self, tri: usize, bary: [f64; 3]) -> [f64; 3] {
        let t = self.triangles[tri];
        match &self.colour {
            SurfaceColour::Vertex(c) => {
                let mut out = [0.0; 3];
                for k in 0..3 {
                    for (ch, o) in out.iter_mut().enumerate() {
                        *o += bary[k] * c[t[k] as usize][ch] as f64;
                    }
                }
                out
            }
            SurfaceColour::Texture { uvs, image } => {
                let mut uv = DVec2::ZERO;
                for k in 0..3 {
                    uv += bary[k] * DVec2::from(uvs[t[k] as usize].map(f64::from));
                }
                sample_bilinear(image, uv)
            }
        }
    }
}

/// The default cube edge: the thesis picks it per model (30 units for small
/// objects, 6 for statues); here it follows the vertex count.
fn default_cell_size(extent: DVec3, vertices: usize) -> f64 {
    let longest = extent.max_element().max(f64::MIN_POSITIVE);
    // A few base-mesh edges (1 % of the vertices) per cube: the guard then
    // rarely fires, and tiles stay large next to their gutters (docs/bench-log/).
    let cubes = (0.08 * (vertices as f64).sqrt()).clamp(12.0, 200.0);
    longest / cubes
}

/// Tile side from a texel budget of a few texels per input vertex, at least
/// a 1024² atlas, at most a 4096² one (tablets' texture limit).
fn default_tile_size(vertices: usize, cells: usize) -> u32 {
    let texels = (4.0 * vertices as f64).clamp(1024.0 * 1024.0, 4096.0 * 4096.0 * 0.9);
    // About three faces per cell carry a tile on scanned surfaces.
    let side = (texels / (3.0 * cells.max(1) as f64)).sqrt();
    // Even, so tiles with a one-texel gutter stay aligned with JPEG's 2×2 chroma.
    ((side.floor() as u32).clamp(2, 64)) & !1
}

pub(crate) fn build_cells(
    mesh: &IndexedMesh,
    quantization: &Quantization,
    source: ColourSource<'_>,
    options: &CccOptions,
) -> Result<Built> {
    // The decoded surface: what the viewer shows at the final level.
    let positions: Vec<DVec3> = mesh
        .positions
        .iter()
        .map(|&p| {
            DVec3::from(
                quantization
                    .dequantize(quantization.quantize(p))
                    .map(f64::from),
            )
        })
        .collect();
    if positions.is_empty() || mesh.triangles.is_empty() {
        return Err(Error::input(
            "mesh",
            "no triangles to build a cell complex on",
        ));
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
    for p in &positions {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let cell_size = match options.cell_size {
        Some(s) if s.is_finite() && s > 0.0 => s as f64,
        Some(s) => {
            return Err(Error::Parameter(format!(
                "cell size must be positive, got {s}"
            )))
        }
        None => default_cell_size(hi - lo, positions.len()),
    };
    let mut grid = Grid::around(lo, hi, cell_size);
    // The viewer gets the grid as f32: build with exactly those values.
    grid.origin = grid.origin.as_vec3().as_dvec3();
    grid.cell_size = grid.cell_size as f32 as f64;
    if grid.cube_count() > MAX_CUBES {
        return Err(Error::Parameter(format!(
            "cell size {cell_size} gives {} cubes; at most {MAX_CUBES} fit the cell texture",
            grid.cube_count()
        )));
    }

    // Cells: cubes the decoded surface crosses.
    let mut cell_of_cube = vec![u32::MAX; grid.cube_count() as usize];
    let mut cubes = Vec::new();
    let crossed = overlaps_on_every_core(&grid, &positions, &mesh.triangles, 0.0, |_, i, out| {
        out.push(i as u32);
    });
    for i in crossed {
        let i = i as usize;
        if cell_of_cube[i] == u32::MAX {
            cell_of_cube[i] = 0;
            cubes.push(i);
        }
    }
    // Number cells in cube order so the result does not depend on face order.
    cubes.sort_unstable();
    for (n, &i) in cubes.iter().enumerate() {
        cell_of_cube[i] = n as u32;
    }

    let surface = colour_surface(mesh, &positions, source)?;
    let binned = bin_triangles(&grid, &cell_of_cube, &surface, cubes.len());
    let tile_size = match options.tile_size {
        Some(t) if (1..=256).contains(&t) => t,
        Some(t) => {
            return Err(Error::Parameter(format!(
                "tile size must be 1–256, got {t}"
            )))
        }
        None => default_tile_size(positions.len(), cubes.len()),
    };

    // Each cell is rendered from its own triangles alone, so the cells are
    // shared out among the cores (rayon), and collected in cube order: the
    // same complex, bit for bit, on any number of threads. Rendering is
    // most of the build (800 k vertices: 3.8 of 5.6 s on one core).
    let rendered: Vec<(Cell, u64, u64)> = cubes
        .par_iter()
        .enumerate()
        .map(|(n, &i)| {
            let cube = IVec3::new(
                (i % grid.dims.x as usize) as i32,
                ((i / grid.dims.x as usize) % grid.dims.y as usize) as i32,
                (i / (grid.dims.x as usize * grid.dims.y as usize)) as i32,
            );
            let tris = &binned.tris[binned.start[n] as usize..binned.start[n + 1] as usize];
            render_cell(&grid, cube, tris, &surface, tile_size)
        })
        .collect();
    let (mut ambiguous, mut covered) = (0u64, 0u64);
    let mut cells = Vec::with_capacity(rendered.len());
    for (cell, a, c) in rendered {
        ambiguous += a;
        covered += c;
        cells.push(cell);
    }
    Ok(Built {
        grid,
        cell_of_cube,
        cells,
        tile_size,
        ambiguous_texels: ambiguous,
        covered_texels: covered,
    })
}

fn colour_surface<'a>(
    mesh: &'a IndexedMesh,
    positions: &[DVec3],
    source: ColourSource<'a>,
) -> Result<ColourSurface<'a>> {
    Ok(match source {
        ColourSource::PerVertex(m) => {
            let colours = m.colors.as_deref().ok_or_else(|| {
                Error::Parameter("per-vertex colour source has no colours".into())
            })?;
            if colours.len() != positions.len() {
                return Err(Error::Parameter(
                    "colour count differs from vertex count".into(),
                ));
            }
            ColourSurface {
                positions: positions.to_vec(),
                triangles: &mesh.triangles,
                colour: SurfaceColour::Vertex(colours),
            }
        }
        ColourSource::Texture(t) => {
            if t.uvs.len() != t.positions.len() {
                return Err(Error::Parameter(
                    "texture UV count differs from its vertex count".into(),
                ));
            }
            if t.image.width() == 0 || t.image.height() == 0 {
                return Err(Error::input("texture", "image is empty"));
            }
            if let Some(bad) = t
                .triangles
                .iter()
                .flatten()
                .find(|&&v| v as usize >= t.positions.len())
            {
                return Err(Error::input(
                    "texture",
                    format!("triangle uses vertex {bad} of {}", t.positions.len()),
                ));
            }
            ColourSurface {
                positions: t
                    .positions
                    .iter()
                    .map(|p| DVec3::from(p.map(f64::from)))
                    .collect(),
                triangles: &t.triangles,
                colour: SurfaceColour::Texture {
                    uvs: &t.uvs,
                    image: &t.image,
                },
            }
        }
    })
}

/// Triangles per task of [`overlaps_on_every_core`].
const TRIANGLE_CHUNK: usize = 8192;

/// What `gather` makes of every cube (its index) each triangle overlaps,
/// grown by `margin`, with the triangle's index: the triangles are split
/// among the cores (rayon), and their results come back in triangle order.
fn overlaps_on_every_core<T: Send + Copy>(
    grid: &Grid,
    positions: &[DVec3],
    triangles: &[[u32; 3]],
    margin: f64,
    gather: impl Fn(u32, usize, &mut Vec<T>) + Sync,
) -> Vec<T> {
    let parts: Vec<Vec<T>> = triangles
        .par_chunks(TRIANGLE_CHUNK)
        .enumerate()
        .map(|(chunk, triangles)| {
            let mut out = Vec::new();
            for (k, t) in triangles.iter().enumerate() {
                let index = (chunk * TRIANGLE_CHUNK + k) as u32;
                let tri = t.map(|v| positions[v as usize]);
                for_each_overlapped_cube(grid, tri, margin, |c| {
                    gather(index, grid.index(c), &mut out);
                });
            }
            out
        })
        .collect();
    parts.concat()
}

/// Triangles of the colour surface near each cell (grown cubes), in CSR form.
struct Binned {
    start: Vec<u32>,
    tris: Vec<u32>,
}

fn bin_triangles(
    grid: &Grid,
    cell_of_cube: &[u32],
    surface: &ColourSurface,
    cells: usize,
) -> Binned {
    let margin = BIN_MARGIN * grid.cell_size;
    // (cell, triangle) pairs as `cell << 32 | triangle`, radix-sorted: the
    // order of sorting the pairs, several times faster on the millions a
    // large scan gives (about 7 per triangle).
    let positions = &surface.positions;
    let mut pairs =
        overlaps_on_every_core(grid, positions, surface.triangles, margin, |t, i, out| {
            let cell = cell_of_cube[i];
            if cell != u32::MAX {
                out.push(u64::from(cell) << 32 | u64::from(t));
            }
        });
    radsort::sort(&mut pairs);
    let mut start = vec![0u32; cells + 1];
    for &pair in &pairs {
        start[(pair >> 32) as usize + 1] += 1;
    }
    for i in 0..cells {
        start[i + 1] += start[i];
    }
    Binned {
        start,
        tris: pairs.into_iter().map(|pair| pair as u32).collect(),
    }
}

/// A triangle ready for ray tests (Möller–Trumbore).
struct RayTriangle {
    index: usize,
    v0: DVec3,
    e1: DVec3,
    e2: DVec3,
}

impl RayTriangle {
    /// The triangle ready for rays from `origin`.
    fn seen_from(&self, origin: DVec3) -> RaysFrom {
        let s = origin - self.v0;
        let q = s.cross(self.e1);
        RaysFrom {
            index: self.index,
            e1: self.e1,
            e2: self.e2,
            s,
            q,
            h: self.e2.dot(q),
        }
    }
}

/// A triangle and the parts of the Möller–Trumbore test that depend only
/// on the rays' common origin (a cell's centre): computed once per cell,
/// not once per texel. The very same operations as the test from scratch,
/// so the same bits.
struct RaysFrom {
    index: usize,
    e1: DVec3,
    e2: DVec3,
    /// `origin − v0`, `s × e1` and `e2 · q`.
    s: DVec3,
    q: DVec3,
    h: f64,
}

impl RaysFrom {
    /// Ray parameter and barycentrics of the hit, if any.
    fn hit(&self, dir: DVec3) -> Option<(f64, [f64; 3])> {
        let p = dir.cross(self.e2);
        let det = self.e1.dot(p);
        if det.abs() < 1e-300 {
            return None;
        }
        let inv = 1.0 / det;
        let u = self.s.dot(p) * inv;
        if !(0.0..=1.0).contains(&u) {
            return None;
        }
        let v = dir.dot(self.q) * inv;
        if v < 0.0 || u + v > 1.0 {
            return None;
        }
        Some((self.h * inv, [1.0 - u - v, u, v]))
    }
}

/// Places the cell's centre of projection and renders its tiles.
/// Returns the cell, its ambiguous texels and its covered texels.
fn render_cell(
    grid: &Grid,
    cube: IVec3,
    tris: &[u32],
    surface: &ColourSurface,
    tile_size: u32,
) -> (Cell, u64, u64) {
    let s = grid.cell_size;
    let min = grid.cube_min(cube);
    let local: Vec<RayTriangle> = tris
        .iter()
        .map(|&t| {
            let [a, b, c] = surface.triangles[t as usize].map(|v| surface.positions[v as usize]);
            RayTriangle {
                index: t as usize,
                v0: a,
                e1: b - a,
                e2: c - a,
            }
        })
        .collect();

    // Behind the surface: area-weighted centroid minus half an edge along the
    // mean normal, so rays cross the surface once where it is a sheet.
    let (mut centroid, mut normal, mut area) = (DVec3::ZERO, DVec3::ZERO, 0.0);
    for t in &local {
        let n = t.e1.cross(t.e2);
        let a = n.length();
        centroid += (t.v0 + (t.e1 + t.e2) / 3.0) * a;
        normal += n;
        area += a;
    }
    let mut centre = if area > 0.0 {
        (centroid / area - min) / s
    } else {
        DVec3::splat(0.5)
    };
    let len = normal.length();
    if len > 0.25 * area && area > 0.0 {
        centre -= normal / len * 0.5;
    } else {
        centre = DVec3::splat(0.5);
    }
    let centre_bytes = centre
        .to_array()
        .map(|c| (c * 256.0 - 0.5).round().clamp(13.0, 242.0) as u8);
    // Rays start from the decoded centre, exactly what the viewer uses.
    let centre = DVec3::from(centre_bytes.map(|b| (b as f64 + 0.5) / 256.0));
    let origin = min + centre * s;
    let rays: Vec<RaysFrom> = local.iter().map(|t| t.seen_from(origin)).collect();

    let t = tile_size as usize;
    let mut tiles: [Option<Vec<[u8; 3]>>; FACES] = Default::default();
    let (mut ambiguous, mut covered) = (0u64, 0u64);
    let mut sum = [0.0f64; 3];
    let local_min = |p: DVec3| (p - min) / s;
    let mut bins = TexelBins::default();
    for (face, slot) in tiles.iter_mut().enumerate() {
        bins.fill(
            face,
            centre,
            t,
            local
                .iter()
                .map(|r| [r.v0, r.v0 + r.e1, r.v0 + r.e2].map(local_min)),
        );
        let mut texels: Vec<Option<[f64; 3]>> = vec![None; t * t];
        for j in 0..t {
            for i in 0..t {
                let uv = [(i as f64 + 0.5) / t as f64, (j as f64 + 0.5) / t as f64];
                let dir = (face_point(face, uv) - centre) * s;
                let mut first: Option<(f64, usize, [f64; 3])> = None;
                let (mut near, mut far) = (f64::INFINITY, f64::NEG_INFINITY);
                for &k in bins.texel(j * t + i) {
                    let tri = &rays[k as usize];
                    let Some((h, bary)) = tri.hit(dir) else {
                        continue;
                    };
                    if h <= 0.0 || h > RAY_REACH {
                        continue;
                    }
                    if h <= 1.0 {
                        near = near.min(h);
                        far = far.max(h);
                    }
                    if first.is_none_or(|(b, _, _)| h < b) {
                        first = Some((h, tri.index, bary));
                    }
                }
                if let Some((_, tri, bary)) = first {
                    covered += 1;
                    if (far - near) * dir.length() > AMBIGUITY_GAP * s {
                        ambiguous += 1;
                    }
                    let c = surface.colour(tri, bary);
                    (0..3).for_each(|k| sum[k] += c[k]);
                    texels[j * t + i] = Some(c);
                }
            }
        }
        if texels.iter().any(Option::is_some) {
            *slot = Some(fill_holes(texels, t));
        }
    }
    let n = covered.max(1) as f64;
    let mean = sum.map(|v| (v / n).round().clamp(0.0, 255.0) as u8);
    (
        Cell {
            centre: centre_bytes,
            tiles,
            mean,
        },
        ambiguous,
        covered,
    )
}

/// Triangles that may cover each texel of one face's tile: the bounding
/// box of each triangle's central projection onto the face (the whole tile
/// when the triangle reaches behind the face's half-space), in CSR form.
#[derive(Default)]
struct TexelBins {
    start: Vec<u32>,
    items: Vec<u32>,
    ranges: Vec<(u32, [usize; 4])>,
}

impl TexelBins {
    /// `triangles`: corners in cube units.
    fn fill(
        &mut self,
        face: usize,
        centre: DVec3,
        t: usize,
        triangles: impl Iterator<Item = [DVec3; 3]>,
    ) {
        let axis = face / 2;
        let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
        let plane = if face.is_multiple_of(2) { 1.0 } else { 0.0 };
        let depth = sign * (plane - centre[axis]);
        let (b0, b1) = other_axes(axis);
        self.ranges.clear();
        for (k, tri) in triangles.enumerate() {
            let w = tri.map(|p| sign * (p[axis] - centre[axis]));
            if w.iter().all(|&w| w <= 0.0) {
                continue;
            }
            let range = if w.iter().all(|&w| w > 1e-9) {
                let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
                for (p, w) in tri.iter().zip(w) {
                    let scale = depth / w;
                    for (d, b) in [b0, b1].into_iter().enumerate() {
                        let x = (centre[b] + (p[b] - centre[b]) * scale) * t as f64 - 0.5;
                        lo[d] = lo[d].min(x);
                        hi[d] = hi[d].max(x);
                    }
                }
                let first = |x: f64| (x - 1e-6).ceil().clamp(0.0, t as f64) as usize;
                let last = |x: f64| ((x + 1e-6).floor() + 1.0).clamp(0.0, t as f64) as usize;
                [first(lo[0]), last(hi[0]), first(lo[1]), last(hi[1])]
            } else {
                [0, t, 0, t]
            };
            if range[0] < range[1] && range[2] < range[3] {
                self.ranges.push((k as u32, range));
            }
        }
        self.start.clear();
        self.start.resize(t * t + 1, 0);
        for (_, [i0, i1, j0, j1]) in &self.ranges {
            for j in *j0..*j1 {
                for i in *i0..*i1 {
                    self.start[j * t + i + 1] += 1;
                }
            }
        }
        for i in 0..t * t {
            self.start[i + 1] += self.start[i];
        }
        self.items.clear();
        self.items.resize(self.start[t * t] as usize, 0);
        let mut at = self.start.clone();
        for (k, [i0, i1, j0, j1]) in &self.ranges {
            for j in *j0..*j1 {
                for i in *i0..*i1 {
                    self.items[at[j * t + i] as usize] = *k;
                    at[j * t + i] += 1;
                }
            }
        }
    }

    fn texel(&self, i: usize) -> &[u32] {
        &self.items[self.start[i] as usize..self.start[i + 1] as usize]
    }
}

/// Fills texels no ray coloured with the mean of their coloured neighbours,
/// growing inward until the tile is full (a push-pull in one direction).
fn fill_holes(mut texels: Vec<Option<[f64; 3]>>, t: usize) -> Vec<[u8; 3]> {
    loop {
        let mut next = texels.clone();
        let mut missing = false;
        for j in 0..t {
            for i in 0..t {
                if texels[j * t + i].is_some() {
                    continue;
                }
                let (mut acc, mut n) = ([0.0; 3], 0);
                for dj in -1i64..=1 {
                    for di in -1i64..=1 {
                        let (x, y) = (i as i64 + di, j as i64 + dj);
                        if x < 0 || y < 0 || x >= t as i64 || y >= t as i64 {
                            continue;
                        }
                        if let Some(c) = texels[y as usize * t + x as usize] {
                            (0..3).for_each(|k| acc[k] += c[k]);
                            n += 1;
                        }
                    }
                }
                if n > 0 {
                    next[j * t + i] = Some(acc.map(|v| v / n as f64));
                } else {
                    missing = true;
                }
            }
        }
        texels = next;
        if !missing {
            break;
        }
    }
    texels
        .into_iter()
        .map(|c| {
            c.unwrap_or_default()
                .map(|v| v.round().clamp(0.0, 255.0) as u8)
        })
        .collect()
}
