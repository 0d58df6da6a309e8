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
    let (kw_line, first) = lines
        .next_line()
        .ok_or_else(|| Error::input(WHAT, "is empty"))?;
    let mut toks = tokens(first);
    let word = toks.next().unwrap_or_default();
    let flags = match parse_keyword(word) {
        Some(Ok(f)) => f,
        Some(Err(e)) => return Err(Error::Unsupported(format!("{WHAT}: {e}"))),
        None => {
            return Err(err(
                kw_line,
                format!(
                    "not an OFF file: expected OFF or COFF, found {:?}",
                    String::from_utf8_lossy(word)
                ),
            ))
        }
    };
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

    let mut positions = Vec::with_capacity(nv);
    let mut raw_colours: Vec<[f32; 3]> = Vec::with_capacity(if flags.colour { nv } else { 0 });
    let mut float_colours = false;
    let mut max_colour = 0f32;
    let skip = if flags.normal { 6 } else { 3 };
    for i in 0..nv {
        let (no, line) = lines.next_line().ok_or_else(|| {
            Error::input(
                WHAT,
                format!("truncated: the file ends after {i} of {nv} vertices"),
            )
        })?;
        let vals: Vec<&[u8]> = tokens(line).collect();
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
        positions.push(p);
        if flags.colour {
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
                max_colour = max_colour.max(rgb[k]);
                float_colours |= c[k].iter().any(|b| matches!(b, b'.' | b'e' | b'E'));
            }
            raw_colours.push(rgb);
        }
    }
    let float_colours = float_colours || max_colour <= 1.0;
    let colors = flags.colour.then(|| {
        raw_colours
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
    });

    let mut triangles = Vec::with_capacity(nf);
    for f in 0..nf {
        let (no, line) = lines.next_line().ok_or_else(|| {
            Error::input(
                WHAT,
                format!("truncated: the file ends after {f} of {nf} faces"),
            )
        })?;
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
                    format!(
                        "face {f}: vertex index {v} is out of range: the file has {nv} vertices"
                    ),
                ));
            }
            let v = v as u32;
            match j {
                0 => first = v,
                1 => {}
                _ => push_triangle(&mut triangles, [first, prev, v], WHAT, opts.max_faces)?,
            }
            prev = v;
        }
    }
    finish(
        WHAT,
        IndexedMesh {
            positions,
            colors,
            triangles,
        },
    )
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
