//! Levels of detail, and animation, as one GLB.
//!
//! Every level indexes the same vertices (levels made by collapses that
//! never move a vertex), so the BIN chunk holds the positions once, then
//! one index list per level. With several levels the first node carries
//! `MSFT_lod` naming the others, coarsest last, and
//! `extras.MSFT_screencoverage` the screen coverage below which each level
//! gives way to the next. With several frames, frame 0 is the base and
//! every other frame a morph target (`POSITION` deltas); one LINEAR
//! animation per level node steps the weights through the frames at `fps`,
//! so at time `k / fps` the mesh is frame `k` and between two key times it
//! is their linear interpolation.
//!
//! What the model has goes out with it: `TEXCOORD_0` and the texture as an
//! embedded PNG (the base colour texture of one material every level
//! uses), and `COLOR_0` (linear, as glTF defines it) for per-vertex colour.
//! A texture seam needs two GLB vertices where the model has one:
//! [`corner_vertices`] makes them from the levels' per-corner texture
//! coordinate ids.

use std::fmt::Write as _;
use std::io::Write;

use crate::import::srgb_u8_to_linear;
use crate::{Error, Result};

/// What [`write_lod_glb`] writes.
#[derive(Clone, Debug)]
pub struct LodGlb<'a> {
    /// Frames of positions (Y-up), all of one length; at least one.
    pub frames: &'a [Vec<[f32; 3]>],
    /// Counter-clockwise triangles of each level, finest first.
    pub levels: &'a [Vec<[u32; 3]>],
    /// Key frames per second of the animation (ignored with one frame).
    pub fps: f32,
    /// Texture coordinates, one per vertex (glTF's: row 0 is the image's top).
    pub uvs: Option<&'a [[f32; 2]]>,
    /// The base colour texture (needs `uvs`), embedded as PNG.
    pub texture: Option<&'a image::RgbImage>,
    /// sRGB vertex colours, one per vertex.
    pub colors: Option<&'a [[u8; 3]]>,
}

/// GLB vertices for levels whose corners carry texture coordinate ids.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CornerVertices {
    /// Per GLB vertex: the model's vertex…
    pub vertex: Vec<u32>,
    /// …and the texture coordinate id its corners have.
    pub uv: Vec<u32>,
    /// Each level's triangles in GLB vertices.
    pub levels: Vec<Vec<[u32; 3]>>,
}

/// A level's triangles and, per triangle, its corners' texture coordinate ids.
pub type LevelCorners<'a> = (&'a [[u32; 3]], &'a [[u32; 3]]);

/// One GLB vertex per distinct (vertex, texture coordinate id) pair that
/// any level's corners use, numbered in order of first use; `levels` are
/// `(triangles, corner_uvs)` of the same length.
pub fn corner_vertices(levels: &[LevelCorners<'_>]) -> Result<CornerVertices> {
    let mut index = std::collections::HashMap::new();
    let (mut vertex, mut uv) = (Vec::new(), Vec::new());
    let mut out = Vec::with_capacity(levels.len());
    for &(triangles, corners) in levels {
        if triangles.len() != corners.len() {
            return Err(Error::Parameter(format!(
                "{} triangles but {} corner texture coordinates",
                triangles.len(),
                corners.len()
            )));
        }
        let level = triangles
            .iter()
            .zip(corners)
            .map(|(t, c)| {
                std::array::from_fn(|k| {
                    *index.entry((t[k], c[k])).or_insert_with(|| {
                        vertex.push(t[k]);
                        uv.push(c[k]);
                        (vertex.len() - 1) as u32
                    })
                })
            })
            .collect();
        out.push(level);
    }
    Ok(CornerVertices {
        vertex,
        uv,
        levels: out,
    })
}

/// The screen coverage hint of level `i` of `n`: halved at each level, 0
/// for the coarsest (it is kept however small the model gets).
pub fn screen_coverage(i: usize, n: usize) -> f64 {
    if i + 1 >= n {
        0.0
    } else {
        0.5f64.powi(i as i32 + 1)
    }
}

/// Per-axis minimum and maximum.
fn bounds(points: impl Iterator<Item = [f32; 3]>) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

fn check(g: &LodGlb<'_>) -> Result<usize> {
    let Some(first) = g.frames.first() else {
        return Err(Error::Parameter("a GLB needs at least one frame".into()));
    };
    let n = first.len();
    if n == 0 || g.levels.is_empty() || g.levels.iter().any(|l| l.is_empty()) {
        return Err(Error::Parameter(
            "cannot write an empty level as glTF (accessors need at least one element)".into(),
        ));
    }
    if g.frames.iter().any(|f| f.len() != n) {
        return Err(Error::Parameter("frames differ in vertex count".into()));
    }
    if g.frames.iter().flatten().flatten().any(|x| !x.is_finite()) {
        return Err(Error::Parameter("a position is not finite".into()));
    }
    if g.levels
        .iter()
        .flatten()
        .flatten()
        .any(|&v| v as usize >= n)
    {
        return Err(Error::Parameter("a level refers past the vertices".into()));
    }
    if g.uvs.is_some_and(|u| u.len() != n) || g.colors.is_some_and(|c| c.len() != n) {
        return Err(Error::Parameter(
            "texture coordinates and colours need one value per vertex".into(),
        ));
    }
    if g.uvs
        .into_iter()
        .flatten()
        .flatten()
        .any(|x| !x.is_finite())
    {
        return Err(Error::Parameter(
            "a texture coordinate is not finite".into(),
        ));
    }
    if g.texture.is_some() && g.uvs.is_none() {
        return Err(Error::Parameter(
            "a texture needs texture coordinates".into(),
        ));
    }
    if g.frames.len() > 1 && !(g.fps.is_finite() && g.fps > 0.0) {
        return Err(Error::Parameter(format!(
            "fps must be positive, got {}",
            g.fps
        )));
    }
    Ok(n)
}

/// The BIN chunk and its views: `(offset, length, target)`.
struct Bin {
    data: Vec<u8>,
    views: Vec<(usize, usize, Option<u32>)>,
}

impl Bin {
    /// Appends a view, 4-byte aligned (an image's length need not be).
    fn view(&mut self, bytes: impl IntoIterator<Item = u8>, target: Option<u32>) -> usize {
        self.data.resize(self.data.len().next_multiple_of(4), 0);
        let start = self.data.len();
        self.data.extend(bytes);
        self.views.push((start, self.data.len() - start, target));
        self.views.len() - 1
    }
}

fn f32s(v: impl IntoIterator<Item = f32>) -> impl Iterator<Item = u8> {
    v.into_iter().flat_map(f32::to_le_bytes)
}

fn vec3(v: [f32; 3]) -> String {
    format!("[{},{},{}]", v[0], v[1], v[2])
}

/// Writes the levels (and frames) as one GLB.
pub fn write_lod_glb(g: &LodGlb<'_>, w: &mut impl Write) -> Result<()> {
    let n = check(g)?;
    let base = &g.frames[0];
    let mut bin = Bin {
        data: Vec::new(),
        views: Vec::new(),
    };
    let mut accessors: Vec<String> = Vec::new();
    const ARRAY: Option<u32> = Some(34962);
    const ELEMENTS: Option<u32> = Some(34963);

    let view = bin.view(f32s(base.iter().flatten().copied()), ARRAY);
    let (lo, hi) = bounds(base.iter().copied());
    accessors.push(format!(
        r#"{{"bufferView":{view},"componentType":5126,"count":{n},"type":"VEC3","min":{},"max":{}}}"#,
        vec3(lo),
        vec3(hi)
    ));
    let mut attributes = r#""POSITION":0"#.to_string();
    if let Some(uvs) = g.uvs {
        let view = bin.view(f32s(uvs.iter().flatten().copied()), ARRAY);
        let _ = write!(attributes, r#","TEXCOORD_0":{}"#, accessors.len());
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{n},"type":"VEC2"}}"#
        ));
    }
    if let Some(colors) = g.colors {
        let linear = colors.iter().flatten().map(|&c| srgb_u8_to_linear(c));
        let view = bin.view(f32s(linear), ARRAY);
        let _ = write!(attributes, r#","COLOR_0":{}"#, accessors.len());
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{n},"type":"VEC3"}}"#
        ));
    }
    let mut targets = Vec::new();
    for frame in &g.frames[1..] {
        let delta: Vec<[f32; 3]> = frame
            .iter()
            .zip(base)
            .map(|(p, b)| std::array::from_fn(|k| p[k] - b[k]))
            .collect();
        let view = bin.view(f32s(delta.iter().flatten().copied()), ARRAY);
        let (lo, hi) = bounds(delta.iter().copied());
        targets.push(accessors.len());
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{n},"type":"VEC3","min":{},"max":{}}}"#,
            vec3(lo),
            vec3(hi)
        ));
    }
    let mut index_accessors = Vec::new();
    for level in g.levels {
        let view = bin.view(
            level.iter().flatten().flat_map(|v| v.to_le_bytes()),
            ELEMENTS,
        );
        index_accessors.push(accessors.len());
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5125,"count":{},"type":"SCALAR"}}"#,
            3 * level.len()
        ));
    }
    let frames = g.frames.len();
    let mut animation = None;
    if frames > 1 {
        let times: Vec<f32> = (0..frames).map(|k| k as f32 / g.fps).collect();
        let view = bin.view(f32s(times.iter().copied()), None);
        let input = accessors.len();
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{frames},"type":"SCALAR","min":[0],"max":[{}]}}"#,
            times[frames - 1]
        ));
        // At key k the weight of target k (frame k) is 1, all others 0.
        let weights =
            (0..frames).flat_map(|k| (1..frames).map(move |t| f32::from(u8::from(t == k))));
        let view = bin.view(f32s(weights), None);
        let output = accessors.len();
        accessors.push(format!(
            r#"{{"bufferView":{view},"componentType":5126,"count":{},"type":"SCALAR"}}"#,
            frames * (frames - 1)
        ));
        animation = Some((input, output));
    }

    let mut json = String::from(r#"{"asset":{"version":"2.0","generator":"vitrine lod"},"#);
    let levels = g.levels.len();
    if levels > 1 {
        json += r#""extensionsUsed":["MSFT_lod"],"#;
    }
    json += r#""scene":0,"scenes":[{"nodes":[0]}],"nodes":["#;
    for i in 0..levels {
        if i > 0 {
            json += ",";
        }
        let _ = write!(json, r#"{{"mesh":{i},"name":"level{i}""#);
        if i == 0 && levels > 1 {
            let ids: Vec<String> = (1..levels).map(|k| k.to_string()).collect();
            let coverage: Vec<String> = (0..levels)
                .map(|k| screen_coverage(k, levels).to_string())
                .collect();
            let _ = write!(
                json,
                r#","extensions":{{"MSFT_lod":{{"ids":[{}]}}}},"extras":{{"MSFT_screencoverage":[{}]}}"#,
                ids.join(","),
                coverage.join(",")
            );
        }
        json += "}";
    }
    json += r#"],"meshes":["#;
    let target_list: Vec<String> = targets
        .iter()
        .map(|a| format!(r#"{{"POSITION":{a}}}"#))
        .collect();
    for (i, idx) in index_accessors.iter().enumerate() {
        if i > 0 {
            json += ",";
        }
        let _ = write!(
            json,
            r#"{{"primitives":[{{"attributes":{{{attributes}}},"indices":{idx},"mode":4"#
        );
        if g.texture.is_some() {
            json += r#","material":0"#;
        }
        if !targets.is_empty() {
            let _ = write!(json, r#","targets":[{}]"#, target_list.join(","));
        }
        json += "}]";
        if !targets.is_empty() {
            let zeros = vec!["0"; targets.len()].join(",");
            let _ = write!(json, r#","weights":[{zeros}]"#);
        }
        json += "}";
    }
    json += "]";
    if let Some((input, output)) = animation {
        let samplers: Vec<String> = (0..levels)
            .map(|_| format!(r#"{{"input":{input},"output":{output},"interpolation":"LINEAR"}}"#))
            .collect();
        let channels: Vec<String> = (0..levels)
            .map(|i| format!(r#"{{"sampler":{i},"target":{{"node":{i},"path":"weights"}}}}"#))
            .collect();
        let _ = write!(
            json,
            r#","animations":[{{"name":"frames","samplers":[{}],"channels":[{}]}}]"#,
            samplers.join(","),
            channels.join(",")
        );
    }
    if let Some(image) = g.texture {
        let mut png = std::io::Cursor::new(Vec::new());
        image
            .write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| Error::Parameter(format!("the texture cannot be written as PNG: {e}")))?;
        let view = bin.view(png.into_inner(), None);
        let _ = write!(
            json,
            r#","materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0}},"metallicFactor":0}}}}],"textures":[{{"sampler":0,"source":0}}],"samplers":[{{"magFilter":9729,"minFilter":9729}}],"images":[{{"bufferView":{view},"mimeType":"image/png"}}]"#
        );
    }
    bin.data.resize(bin.data.len().next_multiple_of(4), 0);
    let _ = write!(
        json,
        r#","buffers":[{{"byteLength":{}}}],"bufferViews":["#,
        bin.data.len()
    );
    for (i, (offset, length, target)) in bin.views.iter().enumerate() {
        if i > 0 {
            json += ",";
        }
        let _ = write!(
            json,
            r#"{{"buffer":0,"byteOffset":{offset},"byteLength":{length}"#
        );
        if let Some(t) = target {
            let _ = write!(json, r#","target":{t}"#);
        }
        json += "}";
    }
    let _ = write!(json, r#"],"accessors":[{}]}}"#, accessors.join(","));
    while json.len() % 4 != 0 {
        json.push(' ');
    }
    // Every view starts 4-byte aligned (all elements are 4 bytes).
    let total = 12 + 8 + json.len() + 8 + bin.data.len();
    let total = u32::try_from(total)
        .map_err(|_| Error::Limit(format!("GLB would be {total} bytes, over 4 GiB")))?;
    let mut out = Vec::with_capacity(total as usize);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&total.to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(json.as_bytes());
    out.extend_from_slice(&(bin.data.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin.data);
    w.write_all(&out)?;
    Ok(())
}
