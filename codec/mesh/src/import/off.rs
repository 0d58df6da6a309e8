//! Geomview OFF reader: `OFF`, `COFF`, `NOFF`, `CNOFF`, `STOFF`… (ascii).
//!
//! Vertex lines are `x y z [nx ny nz] [r g b [a]] [s t]`, one vertex per
//! line; face lines are `n i0 … i(n-1) [colour]` (face colours are ignored).
//! COFF colours are 0–255 integers or 0–1 floats: floats when any colour
//! value is written with a `.` (or exponent), or when all values are ≤ 1.

use super::{check_count, finish, push_triangle, unit_to_u8, ImportOptions};
use crate::{Error, IndexedMesh, Result};

const WHAT: &str = "OFF file";

struct Flags {
    texture: bool,
    colour: bool,
    normal: bool,
}

/// Parses `[ST][C][N]OFF`; `4OFF`, `nOFF` and other variants are not read.
fn parse_keyword(word: &[u8]) -> Option<std::result::Result<Flags, String>> {
    let mut w = word;
    let mut flags = Flags {
        texture: false,
        colour: false,
        normal: false,
    };
    if let Some(r) = w.strip_prefix(b"ST") {
        flags.texture = true;
        w = r;
    }
    if let Some(r) = w.strip_prefix(b"C") {
        flags.colour = true;
        w = r;
    }
    if let Some(r) = w.strip_prefix(b"N") {
        flags.normal = true;
        w = r;
    }
    match w {
        b"OFF" => Some(Ok(flags)),
        b"4OFF" | b"nOFF" | b"4nOFF" => Some(Err(format!(
            "{} (homogeneous or n-dimensional) is not supported",
            String::from_utf8_lossy(word)
        ))),
        _ => None,
    }
}

pub(super) fn is_off_keyword(word: &[u8]) -> bool {
    parse_keyword(word).is_some()
}

fn err(line: usize, detail: impl std::fmt::Display) -> Error {
    Error::input(WHAT, format!("line {line}: {detail}"))
}

/// Non-blank lines with comments removed, numbered from 1.
struct Lines<'a> {
    bytes: &'a [u8],
    /// Offset just past the last line returned.
    consumed: usize,
    line: usize,
}

impl<'a> Lines<'a> {
    fn new(bytes: &'a [u8]) -> Self {
        Lines {
            bytes,
            consumed: 0,
            line: 0,
        }
    }

    fn remaining(&self) -> usize {
        self.bytes.len() - self.consumed
    }

    fn next_line(&mut self) -> Option<(usize, &'a [u8])> {
        while self.consumed < self.bytes.len() {
            let rest = &self.bytes[self.consumed..];
            let raw = match rest.iter().position(|&b| b == b'\n') {
                Some(p) => &rest[..p],
                None => rest,
            };
            self.consumed = (self.consumed + raw.len() + 1).min(self.bytes.len());
            self.line += 1;
            let line = match raw.iter().position(|&b| b == b'#') {
                Some(p) => &raw[..p],
                None => raw,
            };
            let line = line.trim_ascii();
            if !line.is_empty() {
                return Some((self.line, line));
            }
        }
        None
    }
}

fn tokens(line: &[u8]) -> impl Iterator<Item = &[u8]> {
    line.split(|b| b.is_ascii_whitespace())
        .filter(|t| !t.is_empty())
}

fn number<T: std::str::FromStr>(t: &[u8], line: usize, what: &str) -> Result<T> {
    std::str::from_utf8(t)
        .ok()
        .and_then(|s| s.parse().ok())
        .ok_or_else(|| err(line, format!("bad {what} {:?}", String::from_utf8_lossy(t))))
}

pub(super) fn read(bytes: &[u8], opts: &ImportOptions) -> Result<IndexedMesh> {
    let mut lines = Lines::new(bytes);
    let header = read_header(&mut lines, opts)?;
    let Vertices { positions, colors } = read_vertices(&mut lines, &header)?;
    let triangles = read_faces(&mut lines, &header, opts)?;
    finish(
        WHAT,
        IndexedMesh {
            positions,
            colors,
            triangles,
        },
    )
}

/// What the first lines of an OFF file say.
struct Header {
    flags: Flags,
    /// Vertex count, checked.
    nv: usize,
    /// Face count, checked.
    nf: usize,
}

/// The keyword, and the vertex and face counts (on the keyword's line or
/// the next) checked against the options and the bytes that remain.
fn read_header(lines: &mut Lines<'_>, opts: &ImportOptions) -> Result<Header> {
    let (kw_line, first) = lines
        .next_line()
        .ok_or_else(|| Error::input(WHAT, "is empty"))?;
    let mut toks = tokens(first);
    let flags = keyword_flags(toks.next().unwrap_or_default(), kw_line)?;
    // Counts may follow the keyword on the same line.
    let mut rest: Vec<&[u8]> = toks.collect();
    if rest.first() == Some(&&b"BINARY"[..]) {
        return Err(Error::Unsupported(format!(
            "{WHAT}: binary OFF is not supported"
        )));
    }
    let mut counts_line = kw_line;
    if rest.is_empty() {
        let (n, l) = lines
            .next_line()
            .ok_or_else(|| Error::input(WHAT, "truncated: no vertex/face counts"))?;
        counts_line = n;
        rest = tokens(l).collect();
    }
    if rest.len() < 2 {
        return Err(err(counts_line, "expected vertex and face counts"));
    }
    let nv: u64 = number(rest[0], counts_line, "vertex count")?;
    let nf: u64 = number(rest[1], counts_line, "face count")?;
    // Shortest vertex line "0 0 0\n" is 6 bytes, shortest face line "3 0 0 0\n" 8.
    let remaining = lines.remaining();
    let nv = check_count(WHAT, "vertices", nv, 6, remaining, opts.max_vertices)?;
    let nf = check_count(WHAT, "faces", nf, 8, remaining - nv * 6, opts.max_faces)?;
    Ok(Header { flags, nv, nf })
}

/// The flags of the first word of the file, `kw_line`; anything but an
/// `[ST][C][N]OFF` keyword is refused.
fn keyword_flags(word: &[u8], kw_line: usize) -> Result<Flags> {
    match parse_keyword(word) {
        Some(Ok(f)) => Ok(f),
        Some(Err(e)) => Err(Error::Unsupported(format!("{WHAT}: {e}"))),
        None => Err(err(
            kw_line,
            format!(
                "not an OFF file: expected OFF or COFF, found {:?}",
                String::from_utf8_lossy(word)
            ),
        )),
    }
}

/// What the vertex lines hold.
struct Vertices {
    positions: Vec<[f32; 3]>,
    /// For a COFF file.
    colors: Option<Vec<[u8; 3]>>,
}

/// The vertex lines: positions, and colours for a COFF file.
fn read_vertices(lines: &mut Lines<'_>, header: &Header) -> Result<Vertices> {
    let (flags, nv) = (&header.flags, header.nv);
    let mut positions = Vec::with_capacity(nv);
    let mut colours = RawColours {
        values: Vec::with_capacity(if flags.colour { nv } else { 0 }),
        floats: false,
        max: 0.0,
    };
    for i in 0..nv {
        let (no, line) = lines.next_line().ok_or_else(|| {
            Error::input(
                WHAT,
                format!("truncated: the file ends after {i} of {nv} vertices"),
            )
        })?;
        let vals: Vec<&[u8]> = tokens(line).collect();
        positions.push(vertex_position(&vals, i, no)?);
        if flags.colour {
            colours.push(&vals, flags, i, no)?;
        }
    }
    Ok(Vertices {
        positions,
        colors: flags.colour.then(|| colours.to_srgb()),
    })
}

/// The finite position of vertex `i`, the first three values of line `no`.
fn vertex_position(vals: &[&[u8]], i: usize, no: usize) -> Result<[f32; 3]> {
    if vals.len() < 3 {
        return Err(err(
            no,
            format!("vertex {i} has {} values, expected 3", vals.len()),
        ));
    }
    let mut p = [0f32; 3];
    for k in 0..3 {
        p[k] = number(vals[k], no, "coordinate")?;
    }
    if !p.iter().all(|v| v.is_finite()) {
        return Err(err(
            no,
            format!("vertex {i} has a non-finite coordinate {p:?}"),
        ));
    }
    Ok(p)
}

/// COFF vertex colours as written, until their scale is known.
struct RawColours {
    values: Vec<[f32; 3]>,
    /// Some value is written with a `.` or an exponent.
    floats: bool,
    /// The largest value.
    max: f32,
}

impl RawColours {
    /// The colour of vertex `i` on line `no`: the values after the position
    /// (and normal), before the texture coordinates.
    fn push(&mut self, vals: &[&[u8]], flags: &Flags, i: usize, no: usize) -> Result<()> {
        let skip = if flags.normal { 6 } else { 3 };
        let end = vals.len() - if flags.texture { 2 } else { 0 };
        let c = vals.get(skip..end).unwrap_or_default();
        if c.len() < 3 {
            return Err(err(
                no,
                format!(
                    "COFF vertex {i} has {} colour values, expected 3 or 4",
                    c.len()
                ),
            ));
        }
        let mut rgb = [0f32; 3];
        for k in 0..3 {
            rgb[k] = number(c[k], no, "colour value")?;
            self.max = self.max.max(rgb[k]);
            self.floats |= c[k].iter().any(|b| matches!(b, b'.' | b'e' | b'E'));
        }
        self.values.push(rgb);
        Ok(())
    }

    /// 8-bit colours: the values are 0–1 floats when any is written as a
    /// float or all are ≤ 1, 0–255 integers otherwise.
    fn to_srgb(&self) -> Vec<[u8; 3]> {
        let float_colours = self.floats || self.max <= 1.0;
        self.values
            .iter()
            .map(|c| {
                c.map(|v| {
                    if float_colours {
                        unit_to_u8(v as f64)
                    } else {
                        v.round().clamp(0.0, 255.0) as u8
                    }
                })
            })
            .collect()
    }
}

/// The face lines, fan-triangulated (face colours are ignored).
fn read_faces(
    lines: &mut Lines<'_>,
    header: &Header,
    opts: &ImportOptions,
) -> Result<Vec<[u32; 3]>> {
    let nf = header.nf;
    let mut triangles = Vec::with_capacity(nf);
    for f in 0..nf {
        let (no, line) = lines.next_line().ok_or_else(|| {
            Error::input(
                WHAT,
                format!("truncated: the file ends after {f} of {nf} faces"),
            )
        })?;
        read_face(line, (f, no), header.nv, &mut triangles, opts)?;
    }
    Ok(triangles)
}

/// Face `f` on line `no`: `n i0 … i(n-1)`, its fan appended to `triangles`.
fn read_face(
    line: &[u8],
    (f, no): (usize, usize),
    nv: usize,
    triangles: &mut Vec<[u32; 3]>,
    opts: &ImportOptions,
) -> Result<()> {
    let mut toks = tokens(line);
    let n: u64 = number(toks.next().unwrap_or_default(), no, "face vertex count")?;
    let (mut first, mut prev) = (0u32, 0u32);
    for j in 0..n {
        let t = toks
            .next()
            .ok_or_else(|| err(no, format!("face {f} declares {n} vertices but lists {j}")))?;
        let v: i64 = number(t, no, "vertex index")?;
        if v < 0 || v as u64 >= nv as u64 {
            return Err(err(
                no,
                format!("face {f}: vertex index {v} is out of range: the file has {nv} vertices"),
            ));
        }
        let v = v as u32;
        match j {
            0 => first = v,
            1 => {}
            _ => push_triangle(triangles, [first, prev, v], WHAT, opts.max_faces)?,
        }
        prev = v;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn read_str(s: &str) -> Result<IndexedMesh> {
        read(s.as_bytes(), &ImportOptions::default())
    }

    #[test]
    fn off_with_counts_on_keyword_line() {
        let m = read_str("OFF 4 1 0\n# c\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.colors.is_none());
    }

    #[test]
    fn coff_int_and_float() {
        let m = read_str(
            "COFF\n3 1 0\n0 0 0 255 0 0 255\n1 0 0 0 128 0 255\n0 1 0 0 0 1 255\n3 0 1 2 9 9 9\n",
        )
        .unwrap();
        assert_eq!(m.colors.unwrap(), vec![[255, 0, 0], [0, 128, 0], [0, 0, 1]]);
        let m =
            read_str("COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 0.5 0\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
        assert_eq!(
            m.colors.unwrap(),
            vec![[255, 0, 0], [0, 128, 0], [0, 0, 255]]
        );
        // All ≤ 1 without a dot: floats.
        let m = read_str("COFF\n3 1 0\n0 0 0 1 0 0\n1 0 0 0 1 0\n0 1 0 0 0 1\n3 0 1 2\n").unwrap();
        assert_eq!(m.colors.unwrap()[0], [255, 0, 0]);
    }

    #[test]
    fn errors() {
        let e = read_str("OFF\n4000000000 1 0\n0 0 0\n").unwrap_err();
        assert!(
            e.to_string().contains("declares 4000000000 vertices"),
            "{e}"
        );
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n").unwrap_err();
        assert!(
            e.to_string().contains("line 6: face 0: vertex index 3"),
            "{e}"
        );
        let e = read_str("OFF\n3 1 0\n0 0 0\n1 0 0\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("declares 3 vertices but only 12 bytes"),
            "{e}"
        );
        let e = read_str("OFF\n3 1 0\n0.000 0.000 0.000\n1.000 0.000 0.000\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("truncated: the file ends after 2 of 3 vertices"),
            "{e}"
        );
        let e = read_str("NOPE\n").unwrap_err();
        assert!(e.to_string().contains("not an OFF file"), "{e}");
    }
}
