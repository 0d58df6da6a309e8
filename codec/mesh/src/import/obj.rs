//! Wavefront OBJ reader, with its MTL materials' `map_Kd` texture on request.
//!
//! Hand-written rather than built on `tobj`: `tobj` splits the file into one
//! model per `o`/`g` group with renumbered vertices, reports errors without a
//! line number, and does not follow backslash line continuations. What is
//! needed here is small: `v` (with the `v x y z r g b` colour extension) and
//! `f` (any corner form, negative indices, polygons fan-triangulated). For a
//! textured import ([`read_textured`]) `vt`, the corners' `vt` indices,
//! `usemtl` and `mtllib` are read too; every other statement (`vn`, `g`,
//! `o`, `s`, …) is ignored. Memory grows with the file only: there are no
//! header counts.

use std::collections::HashMap;
use std::path::Path;

use super::texture::{self, Resolved};
use super::{finish, push_triangle, unit_to_u8, ImportOptions, TexturedSurface};
use crate::{Error, IndexedMesh, Result};

/// Marks a corner without a `vt` index, or a face without a material.
const NONE: u32 = u32::MAX;

/// What a textured import reads on top of the geometry.
#[derive(Default)]
struct TexState {
    /// `vt u v`, as in the file (`v` up).
    uvs: Vec<[f32; 2]>,
    /// Per triangle: the `vt` index of each corner (`NONE` if absent).
    tri_uvs: Vec<[u32; 3]>,
    /// Per triangle: the index in `materials` of its `usemtl` (`NONE` before any).
    tri_material: Vec<u32>,
    materials: Vec<String>,
    material_ids: HashMap<String, u32>,
    current: u32,
    /// `mtllib` arguments, as written.
    mtllibs: Vec<String>,
    /// Faces that refer to a `vt` defined later in the file: (line, face, index).
    forward: Vec<(usize, usize, i64)>,
    /// `vt` indices of the face being read (reused).
    corners: Vec<u32>,
    /// The first problem with the texture coordinates: the geometry is still
    /// read, the texture is not.
    broken: Option<Error>,
}

const WHAT: &str = "OBJ file";

struct Reader<'o> {
    opts: &'o ImportOptions,
    positions: Vec<[f32; 3]>,
    /// Raw colours, once any vertex has had one (earlier vertices get white).
    colors: Option<Vec<[f32; 3]>>,
    max_colour: f32,
    triangles: Vec<[u32; 3]>,
    faces: usize,
    /// Faces that refer to a vertex defined later in the file: (line, face, index).
    forward: Vec<(usize, usize, i64)>,
    /// Corner indices of the face being read (reused).
    corners: Vec<u32>,
    /// Present for a textured import.
    tex: Option<Box<TexState>>,
}

fn err(line: usize, detail: impl std::fmt::Display) -> Error {
    Error::input(WHAT, format!("line {line}: {detail}"))
}

fn token_str(t: &[u8], line: usize) -> Result<&str> {
    std::str::from_utf8(t)
        .map_err(|_| err(line, format!("bad number {:?}", String::from_utf8_lossy(t))))
}

impl Reader<'_> {
    fn line(&mut self, line: &[u8], no: usize) -> Result<()> {
        let line = match line.iter().position(|&b| b == b'#') {
            Some(p) => &line[..p],
            None => line,
        };
        let mut tokens = line
            .split(|b| b.is_ascii_whitespace())
            .filter(|t| !t.is_empty());
        match tokens.next() {
            Some(b"v") => self.vertex(tokens, no),
            Some(b"f") => self.face(tokens, no),
            Some(b"vt") if self.tex.as_ref().is_some_and(|t| t.broken.is_none()) => {
                if let Err(e) = self.tex_coord(tokens, no) {
                    if let Some(tex) = self.tex.as_mut() {
                        tex.broken = Some(e);
                    }
                }
                Ok(())
            }
            Some(b"usemtl") => {
                if let Some(tex) = self.tex.as_mut() {
                    let name = rest_of_line(line, b"usemtl");
                    let next = tex.materials.len() as u32;
                    tex.current = *tex.material_ids.entry(name.clone()).or_insert(next);
                    if tex.current == next {
                        tex.materials.push(name);
                    }
                }
                Ok(())
            }
            Some(b"mtllib") => {
                if let Some(tex) = self.tex.as_mut() {
                    tex.mtllibs.push(rest_of_line(line, b"mtllib"));
                }
                Ok(())
            }
            _ => Ok(()),
        }
    }

    fn tex_coord<'a>(&mut self, tokens: impl Iterator<Item = &'a [u8]>, no: usize) -> Result<()> {
        let mut uv = [0f32; 2];
        let mut n = 0;
        for t in tokens.take(2) {
            let s = token_str(t, no)?;
            uv[n] = s
                .parse::<f32>()
                .map_err(|_| err(no, format!("bad number {s:?} in texture coordinate")))?;
            n += 1;
        }
        let Some(tex) = self.tex.as_mut() else {
            return Ok(());
        };
        let index = tex.uvs.len();
        if n == 0 {
            return Err(err(no, "texture coordinate has no values"));
        }
        if !uv.iter().all(|v| v.is_finite()) {
            return Err(err(
                no,
                format!("texture coordinate {} is not finite {uv:?}", index + 1),
            ));
        }
        if index >= self.opts.max_vertices {
            return Err(Error::Limit(format!(
                "{WHAT} has more than {} texture coordinates",
                self.opts.max_vertices
            )));
        }
        tex.uvs.push(uv);
        Ok(())
    }

    fn vertex<'a>(&mut self, tokens: impl Iterator<Item = &'a [u8]>, no: usize) -> Result<()> {
        let mut vals = [0f32; 7];
        let mut n = 0;
        for t in tokens {
            if n == vals.len() {
                break; // extra values are ignored
            }
            let s = token_str(t, no)?;
            vals[n] = s
                .parse::<f32>()
                .map_err(|_| err(no, format!("bad number {s:?} in vertex")))?;
            n += 1;
        }
        if n < 3 {
            return Err(err(no, format!("vertex has {n} coordinates, expected 3")));
        }
        let p = [vals[0], vals[1], vals[2]];
        let index = self.positions.len();
        if !p.iter().all(|v| v.is_finite()) {
            return Err(err(
                no,
                format!("vertex {} has a non-finite coordinate {p:?}", index + 1),
            ));
        }
        if index >= self.opts.max_vertices {
            return Err(Error::Limit(format!(
                "{WHAT} has more than {} vertices",
                self.opts.max_vertices
            )));
        }
        self.positions.push(p);
        // `x y z r g b` (and `x y z r g b a`); `x y z w` has no colour.
        let colour = (n >= 6).then(|| [vals[3], vals[4], vals[5]]);
        match (&mut self.colors, colour) {
            (Some(cols), c) => cols.push(c.unwrap_or([1.0; 3])),
            (None, Some(_)) => {
                let mut cols = Vec::with_capacity(self.positions.capacity());
                cols.resize(index, [1.0; 3]);
                cols.push(colour.unwrap_or([1.0; 3]));
                self.colors = Some(cols);
            }
            (None, None) => {}
        }
        if let Some(c) = colour {
            self.max_colour = c.iter().fold(self.max_colour, |m, &v| m.max(v));
        }
        Ok(())
    }

    fn face<'a>(&mut self, tokens: impl Iterator<Item = &'a [u8]>, no: usize) -> Result<()> {
        let face = self.faces;
        self.faces += 1;
        let nv = self.positions.len() as i64;
        self.corners.clear();
        if let Some(tex) = self.tex.as_mut() {
            tex.corners.clear();
        }
        for t in tokens {
            // `v`, `v/vt`, `v//vn` or `v/vt/vn`: the vertex index comes first.
            let mut parts = t.split(|&b| b == b'/');
            let v = parts.next().unwrap_or(t);
            if let Some(tex) = self.tex.as_mut() {
                tex.push_corner(parts.next(), no, face);
            }
            let index = self.vertex_index(v, no, face, nv)?;
            self.corners.push(index);
        }
        if self.corners.len() < 3 {
            return Err(err(
                no,
                format!(
                    "face {} has {} vertices, expected at least 3",
                    face + 1,
                    self.corners.len()
                ),
            ));
        }
        self.push_fan()
    }

    /// A corner's vertex index `v`, 0-based, with `nv` vertices read so far
    /// (forward references are checked at the end).
    fn vertex_index(&mut self, v: &[u8], no: usize, face: usize, nv: i64) -> Result<u32> {
        let s = token_str(v, no)?;
        let i: i64 = s
            .parse()
            .map_err(|_| err(no, format!("face {}: bad vertex index {s:?}", face + 1)))?;
        let index = match i {
            0 => {
                return Err(err(
                    no,
                    format!("face {}: vertex index 0 (OBJ indices start at 1)", face + 1),
                ))
            }
            i if i < 0 => {
                let abs = nv + i;
                if abs < 0 {
                    return Err(err(
                        no,
                        format!(
                            "face {}: relative index {i} reaches before the first vertex \
                             (only {nv} vertices so far)",
                            face + 1
                        ),
                    ));
                }
                abs
            }
            i => {
                if i > nv {
                    if i > u32::MAX as i64 {
                        return Err(err(
                            no,
                            format!("face {}: vertex index {i} is out of range", face + 1),
                        ));
                    }
                    self.forward.push((no, face + 1, i));
                }
                i - 1
            }
        };
        Ok(index as u32)
    }

    /// Fan-triangulates the face just read (`corners`).
    fn push_fan(&mut self) -> Result<()> {
        let first = self.corners[0];
        for k in 2..self.corners.len() {
            let t = [first, self.corners[k - 1], self.corners[k]];
            push_triangle(&mut self.triangles, t, WHAT, self.opts.max_faces)?;
            if let Some(tex) = self.tex.as_mut() {
                let c = &tex.corners;
                tex.tri_uvs.push([c[0], c[k - 1], c[k]]);
                tex.tri_material.push(tex.current);
            }
        }
        Ok(())
    }

    /// Reads every line, joining those that end in a backslash to the next.
    fn read_lines(&mut self, bytes: &[u8]) -> Result<()> {
        let mut joined: Vec<u8> = Vec::new();
        let mut joined_from = 0usize;
        for (i, raw) in bytes.split(|&b| b == b'\n').enumerate() {
            let no = i + 1;
            let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
            if let Some(body) = raw.trim_ascii_end().strip_suffix(b"\\") {
                if joined.is_empty() {
                    joined_from = no;
                }
                joined.extend_from_slice(body);
                joined.push(b' ');
                continue;
            }
            if joined.is_empty() {
                self.line(raw, no)?;
            } else {
                joined.extend_from_slice(raw);
                self.line(&joined, joined_from)?;
                joined.clear();
            }
        }
        if !joined.is_empty() {
            self.line(&joined, joined_from)?;
        }
        Ok(())
    }

    /// Indices that referred forward, now that the whole file is read: a
    /// vertex index past the end is an error, a texture coordinate index
    /// past the end costs the texture.
    fn check_forward_references(&mut self) -> Result<()> {
        let nv = self.positions.len();
        if let Some(&(line, face, i)) = self.forward.iter().find(|f| f.2 > nv as i64) {
            return Err(err(
                line,
                format!(
                    "face {face}: vertex index {i} is out of range: the file has {nv} vertices"
                ),
            ));
        }
        if let Some(tex) = self.tex.as_mut().filter(|t| t.broken.is_none()) {
            let n = tex.uvs.len();
            if let Some(&(line, face, i)) = tex.forward.iter().find(|f| f.2 > n as i64) {
                tex.broken = Some(err(
                    line,
                    format!(
                        "face {face}: texture coordinate index {i} is out of range: \
                         the file has {n} texture coordinates"
                    ),
                ));
            }
        }
        Ok(())
    }
}

impl TexState {
    /// Records a corner's `vt` index (`NONE` without one); an unreadable
    /// one breaks the texture, not the geometry.
    fn push_corner(&mut self, vt: Option<&[u8]>, no: usize, face: usize) {
        let vt = match vt {
            Some(vt) if !vt.is_empty() && self.broken.is_none() => {
                self.corner(vt, no, face).unwrap_or_else(|e| {
                    self.broken = Some(e);
                    NONE
                })
            }
            _ => NONE,
        };
        self.corners.push(vt);
    }

    /// A corner's `vt` index, 0-based (forward references are checked at the end).
    fn corner(&mut self, vt: &[u8], no: usize, face: usize) -> Result<u32> {
        let s = token_str(vt, no)?;
        let i: i64 = s.parse().map_err(|_| {
            err(
                no,
                format!("face {}: bad texture coordinate index {s:?}", face + 1),
            )
        })?;
        let n = self.uvs.len() as i64;
        let index = match i {
            0 => {
                return Err(err(
                    no,
                    format!(
                        "face {}: texture coordinate index 0 (OBJ indices start at 1)",
                        face + 1
                    ),
                ))
            }
            i if i < 0 => {
                if n + i < 0 {
                    return Err(err(
                        no,
                        format!(
                            "face {}: relative texture coordinate index {i} reaches before the \
                             first one (only {n} so far)",
                            face + 1
                        ),
                    ));
                }
                n + i
            }
            i => {
                if i >= NONE as i64 {
                    return Err(err(
                        no,
                        format!(
                            "face {}: texture coordinate index {i} is out of range",
                            face + 1
                        ),
                    ));
                }
                if i > n {
                    self.forward.push((no, face + 1, i));
                }
                i - 1
            }
        };
        Ok(index as u32)
    }
}

/// The statement's argument: the rest of the line after the keyword, trimmed
/// (file and material names may hold spaces).
fn rest_of_line(line: &[u8], keyword: &[u8]) -> String {
    let line = line.trim_ascii_start();
    let rest = line.get(keyword.len()..).unwrap_or_default().trim_ascii();
    String::from_utf8_lossy(rest).into_owned()
}

pub(super) fn read(bytes: &[u8], opts: &ImportOptions) -> Result<IndexedMesh> {
    parse(bytes, opts, None).map(|(mesh, _)| mesh)
}

fn parse(
    bytes: &[u8],
    opts: &ImportOptions,
    tex: Option<Box<TexState>>,
) -> Result<(IndexedMesh, Option<Box<TexState>>)> {
    let mut r = Reader {
        tex,
        opts,
        positions: Vec::new(),
        colors: None,
        max_colour: 0.0,
        triangles: Vec::new(),
        faces: 0,
        forward: Vec::new(),
        corners: Vec::new(),
    };
    r.read_lines(bytes)?;
    r.check_forward_references()?;
    // Colours are 0–1 floats; files whose colours exceed 1 wrote 0–255.
    let colors = r.colors.map(|cols| {
        let scale = if r.max_colour > 1.0 { 1.0 / 255.0 } else { 1.0 };
        cols.iter()
            .map(|c| c.map(|v| unit_to_u8(v as f64 * scale)))
            .collect()
    });
    let mesh = finish(
        WHAT,
        IndexedMesh {
            positions: r.positions,
            colors,
            triangles: r.triangles,
        },
    )?;
    Ok((mesh, r.tex))
}

/// Reads the OBJ and, when one of its materials has a `map_Kd` image, the
/// textured surface. `base` is the OBJ's folder: `mtllib` and `map_Kd` are
/// resolved against it (see [`texture::resolve`]). Missing material files
/// and images are warnings; a malformed image is an error.
pub(super) fn read_textured(
    bytes: &[u8],
    opts: &ImportOptions,
    base: &Path,
    max_pixels: u64,
    warnings: &mut Vec<String>,
) -> Result<(IndexedMesh, Option<TexturedSurface>)> {
    let state = Box::new(TexState {
        current: NONE,
        ..TexState::default()
    });
    let (mesh, tex) = parse(bytes, opts, Some(state))?;
    let Some(tex) = tex else {
        return Ok((mesh, None));
    };
    if tex.mtllibs.is_empty() {
        return Ok((mesh, None));
    }
    if let Some(e) = &tex.broken {
        warnings.push(format!("{e}; imported without texture"));
        return Ok((mesh, None));
    }
    let maps = MaterialMaps::new(read_mtllibs(&tex.mtllibs, base, warnings)?, &tex.materials);
    let Some(chosen) = most_used_map(&tex, &maps, warnings) else {
        return Ok((mesh, None));
    };
    let Some(image) = load_map(base, chosen.reference, max_pixels, warnings)? else {
        return Ok((mesh, None));
    };
    let left_out = mesh.triangles.len() - chosen.used;
    if left_out > 0 {
        warnings.push(format!(
            "{left_out} of {} OBJ triangles have no texture coordinates or another material's \
             texture; they are left out of the textured surface",
            mesh.triangles.len()
        ));
    }
    let surface = assemble_surface(&mesh, &tex, &maps, &chosen, image);
    Ok((mesh, Some(surface)))
}

/// Material name → `map_Kd` reference of the `mtllib` files, first
/// definition winning.
fn read_mtllibs(
    mtllibs: &[String],
    base: &Path,
    warnings: &mut Vec<String>,
) -> Result<HashMap<String, String>> {
    let mut maps: HashMap<String, String> = HashMap::new();
    for lib in mtllibs {
        for path in mtllib_paths(base, lib, warnings) {
            match std::fs::read(&path) {
                Ok(text) => parse_mtl(&text, &mut maps),
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => warnings.push(format!(
                    "OBJ material library {} not found; imported without texture",
                    path.display()
                )),
                Err(e) => {
                    return Err(Error::Io(std::io::Error::new(
                        e.kind(),
                        format!("OBJ material library {}: {e}", path.display()),
                    )))
                }
            }
        }
    }
    Ok(maps)
}

/// The `map_Kd` of each `usemtl` material.
struct MaterialMaps<'t> {
    /// Material name → `map_Kd` reference.
    maps: HashMap<String, String>,
    /// `usemtl` names, by material index.
    materials: &'t [String],
    /// Files without `usemtl` but with a single textured material use it.
    only: Option<String>,
}

impl<'t> MaterialMaps<'t> {
    fn new(maps: HashMap<String, String>, materials: &'t [String]) -> Self {
        let mut only = None;
        if materials.is_empty() && maps.len() == 1 {
            only = maps.values().next().cloned();
        }
        MaterialMaps {
            maps,
            materials,
            only,
        }
    }

    /// The `map_Kd` of material `m` (`NONE`: before any `usemtl`).
    fn of(&self, m: u32) -> Option<&String> {
        match m {
            NONE => self.only.as_ref(),
            m => self.maps.get(self.materials.get(m as usize)?),
        }
    }
}

/// The texture a textured surface is made for.
struct ChosenMap<'m> {
    reference: &'m String,
    /// Triangles with texture coordinates that use it.
    used: usize,
}

/// The texture used by the most triangles (with texture coordinates) wins.
fn most_used_map<'m>(
    tex: &TexState,
    maps: &'m MaterialMaps<'_>,
    warnings: &mut Vec<String>,
) -> Option<ChosenMap<'m>> {
    let mut votes: HashMap<&String, usize> = HashMap::new();
    let mut without_uvs = 0usize;
    for (uv, &m) in tex.tri_uvs.iter().zip(&tex.tri_material) {
        if let Some(map) = maps.of(m) {
            if uv.contains(&NONE) {
                without_uvs += 1;
            } else {
                *votes.entry(map).or_default() += 1;
            }
        }
    }
    let Some((&reference, &used)) = votes
        .iter()
        .max_by(|a, b| a.1.cmp(b.1).then_with(|| b.0.cmp(a.0)))
    else {
        if without_uvs > 0 {
            warnings.push(
                "OBJ file has a map_Kd texture but its faces have no texture coordinates; \
                 imported without texture"
                    .to_string(),
            );
        }
        return None;
    };
    Some(ChosenMap { reference, used })
}

/// The image of `map_Kd reference`; `None` (with a warning) when it is
/// refused, absent or in a format that is not read.
fn load_map(
    base: &Path,
    reference: &str,
    max_pixels: u64,
    warnings: &mut Vec<String>,
) -> Result<Option<image::RgbImage>> {
    let name = format!("map_Kd {reference:?}");
    let path = match texture::resolve(base, reference, &name) {
        Resolved::Inside(p) => p,
        Resolved::FileNameOnly(p, w) => {
            warnings.push(w);
            p
        }
        Resolved::Refused(w) => {
            warnings.push(w);
            return Ok(None);
        }
    };
    match texture::load(texture::Source::File(&path), &name, max_pixels)? {
        Ok(image) => Ok(Some(image)),
        Err(w) => {
            warnings.push(w);
            Ok(None)
        }
    }
}

/// The triangles that use the chosen texture, with one surface vertex per
/// distinct (v, vt) pair: UV seams stay open.
fn assemble_surface(
    mesh: &IndexedMesh,
    tex: &TexState,
    maps: &MaterialMaps<'_>,
    chosen: &ChosenMap<'_>,
    image: image::RgbImage,
) -> TexturedSurface {
    let mut index: HashMap<(u32, u32), u32> = HashMap::with_capacity(mesh.positions.len());
    let mut positions = Vec::with_capacity(mesh.positions.len());
    let mut uvs = Vec::with_capacity(mesh.positions.len());
    let mut triangles = Vec::with_capacity(chosen.used);
    for ((t, uv), &m) in mesh
        .triangles
        .iter()
        .zip(&tex.tri_uvs)
        .zip(&tex.tri_material)
    {
        if uv.contains(&NONE) || maps.of(m) != Some(chosen.reference) {
            continue;
        }
        let corner = |k: usize| (t[k], uv[k]);
        let mut out = [0u32; 3];
        for (k, o) in out.iter_mut().enumerate() {
            let key = corner(k);
            *o = *index.entry(key).or_insert_with(|| {
                positions.push(mesh.positions[key.0 as usize]);
                let [u, v] = tex.uvs[key.1 as usize];
                // OBJ's v grows upward from the bottom of the image.
                uvs.push([u, 1.0 - v]);
                (positions.len() - 1) as u32
            });
        }
        triangles.push(out);
    }
    TexturedSurface {
        positions,
        uvs,
        triangles,
        image,
    }
}

/// The files an `mtllib` statement names. The whole argument is taken as
/// one name when such a file exists (names with spaces), otherwise it is
/// split at whitespace as the format says.
fn mtllib_paths(base: &Path, arg: &str, warnings: &mut Vec<String>) -> Vec<std::path::PathBuf> {
    let whole = unquote(arg);
    let names: Vec<&str> = match texture::resolve(base, whole, "") {
        Resolved::Inside(p) if p.is_file() => vec![whole],
        _ => arg.split_ascii_whitespace().map(unquote).collect(),
    };
    let mut out = Vec::new();
    for name in names {
        let what = format!("mtllib {name:?}");
        match texture::resolve(base, name, &what) {
            Resolved::Inside(p) => out.push(p),
            Resolved::FileNameOnly(p, w) => {
                warnings.push(w);
                out.push(p);
            }
            Resolved::Refused(w) => warnings.push(w),
        }
    }
    out
}

fn unquote(s: &str) -> &str {
    let s = s.trim();
    for q in ['"', '\''] {
        if let Some(inner) = s.strip_prefix(q).and_then(|s| s.strip_suffix(q)) {
            return inner;
        }
    }
    s
}

/// Collects `newmtl` → `map_Kd` from an MTL file (first definition wins).
fn parse_mtl(text: &[u8], maps: &mut HashMap<String, String>) {
    let mut current: Option<String> = None;
    for raw in text.split(|&b| b == b'\n') {
        let line = raw.strip_suffix(b"\r").unwrap_or(raw).trim_ascii();
        let line = match line.iter().position(|&b| b == b'#') {
            Some(p) => line[..p].trim_ascii_end(),
            None => line,
        };
        let keyword = line
            .split(|b| b.is_ascii_whitespace())
            .next()
            .unwrap_or_default();
        if keyword == b"newmtl" {
            current = Some(rest_of_line(line, b"newmtl"));
        } else if keyword.eq_ignore_ascii_case(b"map_Kd") {
            let Some(material) = &current else { continue };
            if let Some(file) = map_file_name(&rest_of_line(line, keyword)) {
                maps.entry(material.clone()).or_insert(file);
            }
        }
    }
}

/// The image file of a texture map statement's argument: options such as
/// `-s 1 1 1` or `-clamp on` come first, the file name (which may hold
/// spaces, and may be quoted) takes the rest of the line.
fn map_file_name(arg: &str) -> Option<String> {
    let mut rest = arg.trim_start();
    while rest.starts_with('-') {
        let (option, after) = split_word(rest);
        // Arguments each option takes: (fewest, most) numbers or words.
        let (min, max) = match option.to_ascii_lowercase().as_str() {
            "-o" | "-s" | "-t" => (1, 3),
            "-mm" => (2, 2),
            "-blendu" | "-blendv" | "-bm" | "-boost" | "-cc" | "-clamp" | "-imfchan"
            | "-texres" | "-type" => (1, 1),
            _ => (0, 0), // unknown: skip the option word alone
        };
        rest = after;
        for k in 0..max {
            let (word, after) = split_word(rest);
            if word.is_empty() || (k >= min && word.parse::<f64>().is_err()) {
                break;
            }
            rest = after;
        }
    }
    let name = unquote(rest);
    (!name.is_empty()).then(|| name.to_string())
}

fn split_word(s: &str) -> (&str, &str) {
    let s = s.trim_start();
    let end = s.find(|c: char| c.is_ascii_whitespace()).unwrap_or(s.len());
    (&s[..end], s[end..].trim_start())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(s: &str) -> Result<IndexedMesh> {
        read(s.as_bytes(), &ImportOptions::default())
    }

    #[test]
    fn corners_negative_and_continuation() {
        let m = read_str(
            "# test\nmtllib a.mtl\no thing\nv 0 0 0\nv 1 0 0\r\n v\t1 1 0\nv 0 1 0\nvt 0 0\nvn 0 0 1\n\
             usemtl m\ns off\nf 1/1/1 2//1 \\\n 3/1 4\nf -4 -2 -1\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 2, 3]]);
        assert!(m.colors.is_none());
    }

    #[test]
    fn errors_name_the_line() {
        let e = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 -4\n").unwrap_err();
        assert!(e.to_string().contains("line 4"), "{e}");
        assert!(e.to_string().contains("before the first vertex"), "{e}");
        let e = read_str("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n").unwrap_err();
        assert!(
            e.to_string().contains("line 4: face 1: vertex index 7"),
            "{e}"
        );
        let e = read_str("v 0 0 nan\n").unwrap_err();
        assert!(e.to_string().contains("non-finite"), "{e}");
        let e = read_str("v 0 0 0\n").unwrap_err();
        assert!(e.to_string().contains("no faces"), "{e}");
    }

    #[test]
    fn map_statement_options_are_skipped() {
        let f = |s: &str| map_file_name(s);
        assert_eq!(f("tex.png").as_deref(), Some("tex.png"));
        assert_eq!(f("-s 1 1 1 tex.png").as_deref(), Some("tex.png"));
        assert_eq!(f("-o 0.5 tex.png").as_deref(), Some("tex.png"));
        assert_eq!(
            f("-mm 0 1 -clamp on \"a b.png\"").as_deref(),
            Some("a b.png")
        );
        assert_eq!(f("-bm 0.5 my tex.jpg").as_deref(), Some("my tex.jpg"));
        assert_eq!(f("-s 1 1 1"), None);
        assert_eq!(f(""), None);
        let mut maps = HashMap::new();
        parse_mtl(
            b"newmtl a b\r\nmap_Kd  one.png # c\nMAP_KD two.png\nnewmtl c\nmap_Ka x.png\n",
            &mut maps,
        );
        assert_eq!(maps.len(), 1);
        assert_eq!(maps["a b"], "one.png");
    }

    #[test]
    fn forward_references_are_allowed() {
        let m = read_str("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }
}
