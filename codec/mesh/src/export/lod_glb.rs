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

use std::fmt::Write as _;
use std::io::Write;

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
    fn view(&mut self, bytes: impl IntoIterator<Item = u8>, target: Option<u32>) -> usize {
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
            r#"{{"primitives":[{{"attributes":{{"POSITION":0}},"indices":{idx},"mode":4"#
        );
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
    // Every view is 4-byte aligned: all elements are 4 bytes.
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
