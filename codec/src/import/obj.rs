//! Wavefront OBJ reader (geometry only).
//!
//! Hand-written rather than built on `tobj`: `tobj` splits the file into one
//! model per `o`/`g` group with renumbered vertices, reports errors without a
//! line number, and does not follow backslash line continuations. What is
//! needed here is small: `v` (with the `v x y z r g b` colour extension) and
//! `f` (any corner form, negative indices, polygons fan-triangulated). Every
//! other statement (`vt`, `vn`, `g`, `o`, `s`, `usemtl`, `mtllib`, …) is
//! ignored. Memory grows with the file only: there are no header counts.

use super::{finish, push_triangle, unit_to_u8, ImportOptions};
use crate::{Error, IndexedMesh, Result};

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
            _ => Ok(()),
        }
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
        for t in tokens {
            // `v`, `v/vt`, `v//vn` or `v/vt/vn`: the vertex index comes first.
            let v = t.split(|&b| b == b'/').next().unwrap_or(t);
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
            self.corners.push(index as u32);
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
        let first = self.corners[0];
        for k in 2..self.corners.len() {
            let t = [first, self.corners[k - 1], self.corners[k]];
            push_triangle(&mut self.triangles, t, WHAT, self.opts.max_faces)?;
        }
        Ok(())
    }
}

pub(super) fn read(bytes: &[u8], opts: &ImportOptions) -> Result<IndexedMesh> {
    let mut r = Reader {
        opts,
        positions: Vec::new(),
        colors: None,
        max_colour: 0.0,
        triangles: Vec::new(),
        faces: 0,
        forward: Vec::new(),
        corners: Vec::new(),
    };
    // Lines ending in a backslash continue on the next line.
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
            r.line(raw, no)?;
        } else {
            joined.extend_from_slice(raw);
            r.line(&joined, joined_from)?;
            joined.clear();
        }
    }
    if !joined.is_empty() {
        r.line(&joined, joined_from)?;
    }

    let nv = r.positions.len();
    if let Some(&(line, face, i)) = r.forward.iter().find(|f| f.2 > nv as i64) {
        return Err(err(
            line,
            format!("face {face}: vertex index {i} is out of range: the file has {nv} vertices"),
        ));
    }
    // Colours are 0–1 floats; files whose colours exceed 1 wrote 0–255.
    let colors = r.colors.map(|cols| {
        let scale = if r.max_colour > 1.0 { 1.0 / 255.0 } else { 1.0 };
        cols.iter()
            .map(|c| c.map(|v| unit_to_u8(v as f64 * scale)))
            .collect()
    });
    finish(
        WHAT,
        IndexedMesh {
            positions: r.positions,
            colors,
            triangles: r.triangles,
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
    fn forward_references_are_allowed() {
        let m = read_str("f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2]]);
    }
}
