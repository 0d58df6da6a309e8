//! Stanford PLY reader: ascii, binary_little_endian and binary_big_endian.
//!
//! Hand-written rather than built on `ply-rs`, which is unmaintained and does
//! not fit here: it materialises every element as a map of named properties
//! (an allocation per vertex), allocates from header counts it never checks
//! against the file size, has no notion of `tristrips`, and its errors carry
//! no element index. This reader walks the payload once, straight into flat
//! arrays: it
//! - checks every declared count against what the remaining bytes can hold
//!   (and against [`ImportOptions`]) before reserving anything;
//! - reads any scalar type in either byte order, skips unknown properties
//!   (list properties included) and unknown elements;
//! - fan-triangulates polygons and unrolls triangle strips (with `-1`
//!   restarts) as it reads them, validating every index on the way.

use super::{check_count, finish, push_triangle, unit_to_u8, ImportOptions};
use crate::{Error, IndexedMesh, Result};

const WHAT: &str = "PLY file";

// The point-cloud reader, a child so that it shares the private parser.
#[path = "ply_points.rs"]
pub(super) mod points;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Ty {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Ty {
    fn parse(s: &str) -> Option<Ty> {
        Some(match s {
            "char" | "int8" => Ty::I8,
            "uchar" | "uint8" => Ty::U8,
            "short" | "int16" => Ty::I16,
            "ushort" | "uint16" => Ty::U16,
            "int" | "int32" => Ty::I32,
            "uint" | "uint32" => Ty::U32,
            "float" | "float32" => Ty::F32,
            "double" | "float64" => Ty::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Ty::I8 | Ty::U8 => 1,
            Ty::I16 | Ty::U16 => 2,
            Ty::I32 | Ty::U32 | Ty::F32 => 4,
            Ty::F64 => 8,
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum Kind {
    Scalar(Ty),
    List { count: Ty, item: Ty },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: u64,
    props: Vec<Property>,
}

impl Element {
    /// Fewest bytes one record can take: every scalar, and every list's count.
    fn min_record_bytes(&self, ascii: bool) -> u64 {
        self.props
            .iter()
            .map(|p| match (ascii, p.kind) {
                // A token and its separator.
                (true, _) => 2,
                (false, Kind::Scalar(t)) => t.size() as u64,
                (false, Kind::List { count, .. }) => count.size() as u64,
            })
            .sum()
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Encoding {
    Ascii,
    LittleEndian,
    BigEndian,
}

struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    /// Offset of the first payload byte.
    data_start: usize,
}

fn header_err(line: usize, detail: impl std::fmt::Display) -> Error {
    Error::input(WHAT, format!("header line {line}: {detail}"))
}

fn parse_header(bytes: &[u8]) -> Result<Header> {
    let mut pos = 0usize;
    let mut line_no = 0usize;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    // Old Mac exporters end lines in CR alone: the "ply" line says which
    // terminator the whole header uses (a binary body may hold any byte
    // right after end_header, so the style is never guessed per line).
    let terminator = if bytes.starts_with(b"ply\r") && !bytes.starts_with(b"ply\r\n") {
        b'\r'
    } else {
        b'\n'
    };
    loop {
        let Some(nl) = bytes[pos..].iter().position(|&b| b == terminator) else {
            return Err(Error::input(
                WHAT,
                if line_no == 0 {
                    "not a PLY file (no header)".to_string()
                } else {
                    format!("header has no end_header line (file ends after line {line_no})")
                },
            ));
        };
        let raw = &bytes[pos..pos + nl];
        pos += nl + 1;
        line_no += 1;
        let raw = raw.strip_suffix(b"\r").unwrap_or(raw);
        if line_no == 1 {
            if raw.trim_ascii() != b"ply" {
                return Err(Error::input(
                    WHAT,
                    "not a PLY file (first line is not \"ply\")",
                ));
            }
            continue;
        }
        let line = String::from_utf8_lossy(raw);
        let mut words = line.split_ascii_whitespace();
        let Some(keyword) = words.next() else {
            continue; // blank line
        };
        match keyword {
            "comment" | "obj_info" => {}
            "format" => encoding = Some(parse_format(words.next(), line_no)?),
            "element" => elements.push(parse_element(words, line_no)?),
            "property" => {
                let Some(element) = elements.last_mut() else {
                    return Err(header_err(line_no, "property before any element"));
                };
                element.props.push(parse_property(words, line_no)?);
            }
            "end_header" => break,
            other => {
                return Err(header_err(line_no, format!("unknown keyword {other:?}")));
            }
        }
    }
    let encoding = encoding.ok_or_else(|| Error::input(WHAT, "header has no format line"))?;
    Ok(Header {
        encoding,
        elements,
        data_start: pos,
    })
}

/// `format ENCODING VERSION`: the encoding word.
fn parse_format(word: Option<&str>, line_no: usize) -> Result<Encoding> {
    Ok(match word {
        Some("ascii") => Encoding::Ascii,
        Some("binary_little_endian") => Encoding::LittleEndian,
        Some("binary_big_endian") => Encoding::BigEndian,
        other => {
            return Err(header_err(
                line_no,
                format!("unknown format {:?}", other.unwrap_or("")),
            ))
        }
    })
}

/// `element NAME COUNT`: the words after the keyword.
fn parse_element<'a>(mut words: impl Iterator<Item = &'a str>, line_no: usize) -> Result<Element> {
    let (Some(name), Some(count)) = (words.next(), words.next()) else {
        return Err(header_err(line_no, "expected \"element NAME COUNT\""));
    };
    let count: u64 = count
        .parse()
        .map_err(|_| header_err(line_no, format!("element {name}: bad count {count:?}")))?;
    Ok(Element {
        name: name.to_string(),
        count,
        props: Vec::new(),
    })
}

/// `property TYPE NAME` or `property list COUNT_TYPE ITEM_TYPE NAME`: the
/// words after the keyword.
fn parse_property<'a>(
    mut words: impl Iterator<Item = &'a str>,
    line_no: usize,
) -> Result<Property> {
    let ty = |s: Option<&str>| -> Result<Ty> {
        let s = s.unwrap_or("");
        Ty::parse(s).ok_or_else(|| header_err(line_no, format!("unknown property type {s:?}")))
    };
    let first = words.next();
    let (kind, name) = if first == Some("list") {
        let count = ty(words.next())?;
        let item = ty(words.next())?;
        if matches!(count, Ty::F32 | Ty::F64) {
            return Err(header_err(line_no, "list count type must be an integer"));
        }
        (Kind::List { count, item }, words.next())
    } else {
        (Kind::Scalar(ty(first)?), words.next())
    };
    let Some(name) = name else {
        return Err(header_err(line_no, "property has no name"));
    };
    Ok(Property {
        name: name.to_string(),
        kind,
    })
}

/// Why a read from the payload failed; the caller adds where.
enum Fail {
    Eof,
    Number(String),
}

/// One payload encoding: ascii tokens or binary scalars.
trait Source {
    /// A coordinate, converted to f32 exactly as the file means it.
    fn coord(&mut self, ty: Ty) -> Result<f32, Fail>;
    fn real(&mut self, ty: Ty) -> Result<f64, Fail>;
    fn int(&mut self, ty: Ty) -> Result<i64, Fail>;
    fn skip(&mut self, ty: Ty, n: u64) -> Result<(), Fail>;
    /// Where the last read was, for error messages.
    fn location(&self) -> String;
}

struct Binary<'a> {
    data: &'a [u8],
    pos: usize,
    big_endian: bool,
}

impl Binary<'_> {
    #[inline]
    fn take<const N: usize>(&mut self) -> Result<[u8; N], Fail> {
        let end = self.pos.checked_add(N).ok_or(Fail::Eof)?;
        let s = self.data.get(self.pos..end).ok_or(Fail::Eof)?;
        let mut a = [0u8; N];
        a.copy_from_slice(s);
        self.pos = end;
        Ok(a)
    }
}

macro_rules! num {
    ($self:ident, $t:ty) => {{
        let b = $self.take::<{ std::mem::size_of::<$t>() }>()?;
        if $self.big_endian {
            <$t>::from_be_bytes(b)
        } else {
            <$t>::from_le_bytes(b)
        }
    }};
}

impl Source for Binary<'_> {
    #[inline]
    fn coord(&mut self, ty: Ty) -> Result<f32, Fail> {
        Ok(match ty {
            Ty::F32 => num!(self, f32),
            other => self.real(other)? as f32,
        })
    }

    #[inline]
    fn real(&mut self, ty: Ty) -> Result<f64, Fail> {
        Ok(match ty {
            Ty::I8 => num!(self, i8) as f64,
            Ty::U8 => num!(self, u8) as f64,
            Ty::I16 => num!(self, i16) as f64,
            Ty::U16 => num!(self, u16) as f64,
            Ty::I32 => num!(self, i32) as f64,
            Ty::U32 => num!(self, u32) as f64,
            Ty::F32 => num!(self, f32) as f64,
            Ty::F64 => num!(self, f64),
        })
    }

    #[inline]
    fn int(&mut self, ty: Ty) -> Result<i64, Fail> {
        Ok(match ty {
            Ty::I8 => num!(self, i8) as i64,
            Ty::U8 => num!(self, u8) as i64,
            Ty::I16 => num!(self, i16) as i64,
            Ty::U16 => num!(self, u16) as i64,
            Ty::I32 => num!(self, i32) as i64,
            Ty::U32 => num!(self, u32) as i64,
            Ty::F32 | Ty::F64 => {
                let v = self.real(ty)?;
                float_to_int(v).ok_or_else(|| Fail::Number(v.to_string()))?
            }
        })
    }

    fn skip(&mut self, ty: Ty, n: u64) -> Result<(), Fail> {
        let bytes = n.checked_mul(ty.size() as u64).ok_or(Fail::Eof)?;
        let end = (self.pos as u64).checked_add(bytes).ok_or(Fail::Eof)?;
        if end > self.data.len() as u64 {
            self.pos = self.data.len();
            return Err(Fail::Eof);
        }
        self.pos = end as usize;
        Ok(())
    }

    fn location(&self) -> String {
        format!("byte {}", self.pos)
    }
}

fn float_to_int(v: f64) -> Option<i64> {
    (v.fract() == 0.0 && v.abs() < 9.0e15).then_some(v as i64)
}

struct Ascii<'a> {
    data: &'a [u8],
    pos: usize,
    /// 1-based line of the last token read.
    line: usize,
    /// Line the cursor is on.
    cursor_line: usize,
}

impl<'a> Ascii<'a> {
    #[inline]
    fn token(&mut self) -> Result<&'a str, Fail> {
        let d = self.data;
        let mut p = self.pos;
        while p < d.len() && d[p].is_ascii_whitespace() {
            if d[p] == b'\n' {
                self.cursor_line += 1;
            }
            p += 1;
        }
        self.line = self.cursor_line;
        if p == d.len() {
            self.pos = p;
            return Err(Fail::Eof);
        }
        let start = p;
        while p < d.len() && !d[p].is_ascii_whitespace() {
            p += 1;
        }
        self.pos = p;
        std::str::from_utf8(&d[start..p])
            .map_err(|_| Fail::Number(String::from_utf8_lossy(&d[start..p]).into_owned()))
    }
}

impl Source for Ascii<'_> {
    #[inline]
    fn coord(&mut self, _ty: Ty) -> Result<f32, Fail> {
        // Parsing straight to f32 rounds once, so a float written with enough
        // digits reads back bit-exact whatever type the header declares.
        let t = self.token()?;
        t.parse::<f32>().map_err(|_| Fail::Number(t.to_string()))
    }

    #[inline]
    fn real(&mut self, _ty: Ty) -> Result<f64, Fail> {
        let t = self.token()?;
        t.parse::<f64>().map_err(|_| Fail::Number(t.to_string()))
    }

    #[inline]
    fn int(&mut self, _ty: Ty) -> Result<i64, Fail> {
        let t = self.token()?;
        if let Ok(v) = t.parse::<i64>() {
            return Ok(v);
        }
        t.parse::<f64>()
            .ok()
            .and_then(float_to_int)
            .ok_or_else(|| Fail::Number(t.to_string()))
    }

    fn skip(&mut self, _ty: Ty, n: u64) -> Result<(), Fail> {
        for _ in 0..n {
            self.token()?;
        }
        Ok(())
    }

    fn location(&self) -> String {
        format!("line {}", self.line)
    }
}

/// What the reader does with one property of an element it knows.
#[derive(Clone, Copy)]
enum Role {
    Coord(usize),
    Colour(usize),
    Indices,
    Skip,
}

fn colour_channel(name: &str) -> Option<usize> {
    match name {
        "red" | "diffuse_red" => Some(0),
        "green" | "diffuse_green" => Some(1),
        "blue" | "diffuse_blue" => Some(2),
        _ => None,
    }
}

/// A colour value of the declared type to 8 bits: floats are 0–1, 16-bit
/// integers full range, other integers 0–255.
fn colour_u8(v: f64, ty: Ty) -> u8 {
    match ty {
        Ty::F32 | Ty::F64 => unit_to_u8(v),
        Ty::I16 | Ty::U16 => (v / 257.0).round().clamp(0.0, 255.0) as u8,
        _ => v.round().clamp(0.0, 255.0) as u8,
    }
}

/// What a PLY reader does with the payload once the header is parsed: the
/// mesh reader and the point reader (`ply_points`) share the header parser and
/// the dispatch to an ASCII or binary source through this.
trait Payload {
    type Output;
    fn read<S: Source>(
        self,
        header: &Header,
        src: &mut S,
        payload_len: usize,
    ) -> Result<Self::Output>;
}

/// Parses the header of `bytes` and hands its payload to `payload` through
/// the source its encoding needs.
fn read_with<P: Payload>(bytes: &[u8], payload: P) -> Result<P::Output> {
    let header = parse_header(bytes)?;
    let data = &bytes[header.data_start..];
    match header.encoding {
        Encoding::Ascii => {
            let first_line = bytes[..header.data_start]
                .iter()
                .filter(|&&b| b == b'\n')
                .count()
                + 1;
            let mut src = Ascii {
                data,
                pos: 0,
                line: first_line,
                cursor_line: first_line,
            };
            payload.read(&header, &mut src, data.len())
        }
        Encoding::LittleEndian | Encoding::BigEndian => {
            let mut src = Binary {
                data,
                pos: 0,
                big_endian: header.encoding == Encoding::BigEndian,
            };
            payload.read(&header, &mut src, data.len())
        }
    }
}

/// The mesh reader's payload: vertices and faces.
struct MeshPayload<'a>(&'a ImportOptions);

impl Payload for MeshPayload<'_> {
    type Output = IndexedMesh;
    fn read<S: Source>(
        self,
        header: &Header,
        src: &mut S,
        payload_len: usize,
    ) -> Result<IndexedMesh> {
        read_payload(header, src, payload_len, self.0)
    }
}

pub(super) fn read(bytes: &[u8], opts: &ImportOptions) -> Result<IndexedMesh> {
    read_with(bytes, MeshPayload(opts))
}

fn read_payload<S: Source>(
    header: &Header,
    src: &mut S,
    payload_len: usize,
    opts: &ImportOptions,
) -> Result<IndexedMesh> {
    let vertex_pos = header
        .elements
        .iter()
        .position(|e| e.name == "vertex")
        .ok_or_else(|| Error::input(WHAT, "has no \"vertex\" element"))?;
    let counts = check_counts(header, payload_len, opts)?;
    let n_vertices = counts[vertex_pos];

    let mut mesh = IndexedMesh {
        positions: Vec::new(),
        colors: None,
        triangles: Vec::new(),
    };
    let mut seen_vertex = false;
    for (element, &count) in header.elements.iter().zip(&counts) {
        let records = Records { element, count };
        match element.name.as_str() {
            "vertex" if !seen_vertex => {
                seen_vertex = true;
                mesh.colors = read_vertices(records, src, &mut mesh.positions)?;
            }
            "face" | "tristrips" => {
                let faces = Faces::new(records, n_vertices)?;
                faces.read(src, &mut mesh.triangles, opts)?;
            }
            _ if element.props.is_empty() => {} // no payload at all
            // Unknown element (or a second vertex element): skip its records.
            _ => skip_records(records, src)?,
        }
    }
    debug_assert_eq!(mesh.positions.len(), n_vertices);
    finish(WHAT, mesh)
}

/// Every element's count, checked before anything is reserved: the records
/// of all elements together must fit in the bytes after the header.
fn check_counts(header: &Header, payload_len: usize, opts: &ImportOptions) -> Result<Vec<usize>> {
    let ascii = header.encoding == Encoding::Ascii;
    // An ascii record's last token may lack a separator: allow one byte.
    let mut budget = payload_len + usize::from(ascii);
    let mut counts = Vec::with_capacity(header.elements.len());
    for e in &header.elements {
        let min = e.min_record_bytes(ascii);
        let limit = match e.name.as_str() {
            "vertex" => opts.max_vertices,
            "face" | "tristrips" => opts.max_faces,
            _ => usize::MAX,
        };
        let plural = match e.name.as_str() {
            "vertex" => "vertices".to_string(),
            "face" => "faces".to_string(),
            other => format!("{other} elements"),
        };
        let n = check_count(WHAT, &plural, e.count, min, budget, limit)?;
        budget -= e.count.saturating_mul(min) as usize;
        counts.push(n);
    }
    Ok(counts)
}

/// The records of one element, for error messages.
#[derive(Clone, Copy)]
struct Records<'h> {
    element: &'h Element,
    /// Its checked count.
    count: usize,
}

impl Records<'_> {
    /// The error for a failed read in record `i`.
    fn fail<S: Source>(&self, i: usize, src: &S, f: Fail) -> Error {
        let (name, count) = (&self.element.name, self.count);
        match f {
            Fail::Eof => Error::input(
                WHAT,
                format!(
                    "truncated: the file ends inside {name} {i} of {count} ({})",
                    src.location()
                ),
            ),
            Fail::Number(t) => Error::input(
                WHAT,
                format!("{name} {i} ({}): bad number {t:?}", src.location()),
            ),
        }
    }
}

/// The roles of the vertex element's properties, and whether it has all
/// three colour channels. Refused without scalar `x`, `y` and `z`.
fn vertex_roles(e: &Element) -> Result<(Vec<Role>, bool)> {
    let roles: Vec<Role> = e
        .props
        .iter()
        .map(|p| match (p.name.as_str(), p.kind) {
            ("x", Kind::Scalar(_)) => Role::Coord(0),
            ("y", Kind::Scalar(_)) => Role::Coord(1),
            ("z", Kind::Scalar(_)) => Role::Coord(2),
            (n, Kind::Scalar(_)) if colour_channel(n).is_some() => {
                Role::Colour(colour_channel(n).unwrap_or(0))
            }
            _ => Role::Skip,
        })
        .collect();
    for axis in 0..3 {
        if !roles
            .iter()
            .any(|r| matches!(r, Role::Coord(a) if *a == axis))
        {
            return Err(Error::input(
                WHAT,
                format!(
                    "vertex element has no scalar \"{}\" property",
                    ["x", "y", "z"][axis]
                ),
            ));
        }
    }
    let has_colour = (0..3).all(|c| {
        roles
            .iter()
            .any(|r| matches!(r, Role::Colour(k) if *k == c))
    });
    Ok((roles, has_colour))
}

/// Reads the vertex element into `positions`; returns the colours when it
/// has them.
fn read_vertices<S: Source>(
    records: Records<'_>,
    src: &mut S,
    positions: &mut Vec<[f32; 3]>,
) -> Result<Option<Vec<[u8; 3]>>> {
    let (roles, has_colour) = vertex_roles(records.element)?;
    let count = records.count;
    positions.reserve_exact(count);
    let mut cols = has_colour.then(|| Vec::with_capacity(count));
    for i in 0..count {
        let (p, c) = read_vertex(records, &roles, i, src)?;
        positions.push(p);
        if let Some(cols) = cols.as_mut() {
            cols.push(c);
        }
    }
    Ok(cols)
}

/// Vertex `i`: its position (finite) and colour (black without one).
fn read_vertex<S: Source>(
    records: Records<'_>,
    roles: &[Role],
    i: usize,
    src: &mut S,
) -> Result<([f32; 3], [u8; 3])> {
    let mut p = [0f32; 3];
    let mut c = [0u8; 3];
    for (prop, role) in records.element.props.iter().zip(roles) {
        match (*role, prop.kind) {
            (Role::Coord(a), Kind::Scalar(t)) => {
                p[a] = src.coord(t).map_err(|f| records.fail(i, src, f))?
            }
            (Role::Colour(k), Kind::Scalar(t)) => {
                c[k] = colour_u8(src.real(t).map_err(|f| records.fail(i, src, f))?, t)
            }
            (_, kind) => skip(src, kind).map_err(|f| records.fail(i, src, f))?,
        }
    }
    if !p.iter().all(|v| v.is_finite()) {
        return Err(Error::input(
            WHAT,
            format!(
                "vertex {i} ({}) has a non-finite coordinate {p:?}",
                src.location()
            ),
        ));
    }
    Ok((p, c))
}

/// A `face` or `tristrips` element: polygons or strips of vertex indices.
struct Faces<'h> {
    records: Records<'h>,
    roles: Vec<Role>,
    strips: bool,
    n_vertices: usize,
}

impl<'h> Faces<'h> {
    /// Refused without a `vertex_indices` (or `vertex_index`) list.
    fn new(records: Records<'h>, n_vertices: usize) -> Result<Self> {
        let e = records.element;
        let roles: Vec<Role> = e
            .props
            .iter()
            .map(|p| match (p.name.as_str(), p.kind) {
                ("vertex_indices" | "vertex_index", Kind::List { .. }) => Role::Indices,
                _ => Role::Skip,
            })
            .collect();
        if !roles.iter().any(|r| matches!(r, Role::Indices)) {
            return Err(Error::input(
                WHAT,
                format!("{} element has no vertex_indices list", e.name),
            ));
        }
        Ok(Faces {
            records,
            roles,
            strips: e.name == "tristrips",
            n_vertices,
        })
    }

    /// Reads every record, its polygons or strips appended to `triangles`.
    fn read<S: Source>(
        &self,
        src: &mut S,
        triangles: &mut Vec<[u32; 3]>,
        opts: &ImportOptions,
    ) -> Result<()> {
        if triangles.is_empty() {
            // Reasonable first guess, bounded by what the file can hold.
            triangles.reserve(if self.strips { 0 } else { self.records.count });
        }
        for i in 0..self.records.count {
            // A second index list in the same element is skipped.
            let mut done_indices = false;
            for (prop, role) in self.records.element.props.iter().zip(&self.roles) {
                match (*role, prop.kind) {
                    (Role::Indices, Kind::List { count, item }) if !done_indices => {
                        done_indices = true;
                        let list = ListTypes { count, item };
                        self.read_indices(i, list, src, triangles, opts)?;
                    }
                    (_, kind) => skip(src, kind).map_err(|f| self.records.fail(i, src, f))?,
                }
            }
        }
        Ok(())
    }

    /// The index list of record `i`, triangulated into `triangles`.
    fn read_indices<S: Source>(
        &self,
        i: usize,
        list: ListTypes,
        src: &mut S,
        triangles: &mut Vec<[u32; 3]>,
        opts: &ImportOptions,
    ) -> Result<()> {
        let records = self.records;
        let name = &records.element.name;
        let k = src.int(list.count).map_err(|f| records.fail(i, src, f))?;
        if k < 0 {
            return Err(Error::input(
                WHAT,
                format!("{name} {i} ({}): negative list length {k}", src.location()),
            ));
        }
        let (strips, n_vertices) = (self.strips, self.n_vertices);
        let mut idx = |j: u64, src: &mut S| -> Result<Option<u32>> {
            let v = src.int(list.item).map_err(|f| records.fail(i, src, f))?;
            if strips && v == -1 {
                return Ok(None);
            }
            if v < 0 || v as u64 >= n_vertices as u64 {
                return Err(Error::input(
                    WHAT,
                    format!(
                        "{name} {i} ({}): vertex index {v} (entry {j}) is out of range: the file has {n_vertices} vertices",
                        src.location()
                    ),
                ));
            }
            Ok(Some(v as u32))
        };
        if strips {
            read_strip(k as u64, &mut idx, src, triangles, opts)
        } else {
            read_polygon(k as u64, &mut idx, src, triangles, opts)
        }
    }
}

/// The types of a list property: its length and its items.
#[derive(Clone, Copy)]
struct ListTypes {
    count: Ty,
    item: Ty,
}

/// Skips every record of an element that is not read.
fn skip_records<S: Source>(records: Records<'_>, src: &mut S) -> Result<()> {
    for i in 0..records.count {
        for prop in &records.element.props {
            skip(src, prop.kind).map_err(|f| records.fail(i, src, f))?;
        }
    }
    Ok(())
}

fn skip<S: Source>(src: &mut S, kind: Kind) -> Result<(), Fail> {
    match kind {
        Kind::Scalar(t) => src.skip(t, 1),
        Kind::List { count, item } => {
            let n = src.int(count)?;
            if n < 0 {
                return Err(Fail::Number(n.to_string()));
            }
            src.skip(item, n as u64)
        }
    }
}

/// Fan-triangulates one polygon as its indices are read.
fn read_polygon<S: Source>(
    k: u64,
    idx: &mut impl FnMut(u64, &mut S) -> Result<Option<u32>>,
    src: &mut S,
    tris: &mut Vec<[u32; 3]>,
    opts: &ImportOptions,
) -> Result<()> {
    let (mut first, mut prev) = (0u32, 0u32);
    for j in 0..k {
        let Some(v) = idx(j, src)? else {
            continue; // only strips have restarts
        };
        match j {
            0 => first = v,
            1 => {}
            _ => push_triangle(tris, [first, prev, v], WHAT, opts.max_faces)?,
        }
        prev = v;
    }
    Ok(())
}

/// Unrolls one triangle strip: `-1` restarts it, every other triangle has
/// its winding swapped, and degenerate (stitching) triangles are dropped.
fn read_strip<S: Source>(
    k: u64,
    idx: &mut impl FnMut(u64, &mut S) -> Result<Option<u32>>,
    src: &mut S,
    tris: &mut Vec<[u32; 3]>,
    opts: &ImportOptions,
) -> Result<()> {
    let (mut a, mut b): (Option<u32>, Option<u32>) = (None, None);
    let mut odd = false;
    for j in 0..k {
        let Some(v) = idx(j, src)? else {
            a = None;
            b = None;
            odd = false;
            continue;
        };
        match (a, b) {
            (None, _) => a = Some(v),
            (Some(_), None) => b = Some(v),
            (Some(x), Some(y)) => {
                let t = if odd { [y, x, v] } else { [x, y, v] };
                if x != y && y != v && x != v {
                    push_triangle(tris, t, WHAT, opts.max_faces)?;
                }
                odd = !odd;
                a = Some(y);
                b = Some(v);
            }
        }
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
    fn ascii_quad_with_extra_props() {
        let m = read_str(
            "ply\r\nformat ascii 1.0\r\ncomment hi\r\nobj_info x\r\nelement vertex 4\r\n\
             property float x\r\nproperty double y\r\nproperty int z\r\nproperty list uchar int junk\r\n\
             element face 1\r\nproperty uchar flags\r\nproperty list uchar uint vertex_index\r\n\
             end_header\r\n0 0 0 2 7 7\r\n1 0 0 0\r\n1 1 0 1 5\r\n0 1 0 0\r\n9 4 0 1 2 3\r\n",
        )
        .unwrap();
        assert_eq!(m.positions.len(), 4);
        assert_eq!(m.positions[2], [1.0, 1.0, 0.0]);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert!(m.colors.is_none());
    }

    #[test]
    fn strips_restart_and_winding() {
        let m = read_str(
            "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\nproperty float z\n\
             element tristrips 1\nproperty list int int vertex_indices\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 0 0\n2 1 0\n\
             8 0 1 2 3 -1 3 4 5\n",
        )
        .unwrap();
        assert_eq!(m.triangles, vec![[0, 1, 2], [2, 1, 3], [3, 4, 5]]);
    }

    #[test]
    fn degenerate_strip_triangles_dropped_but_parity_kept() {
        let m = read_str(
            "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\n\
             element tristrips 1\nproperty list int int vertex_indices\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n1 1 0\n2 0 0\n\
             6 0 1 2 2 3 4\n",
        )
        .unwrap();
        // (0,1,2), (1,2,2) and (2,2,3) dropped, then (2,3,4) in odd position.
        assert_eq!(m.triangles, vec![[0, 1, 2], [3, 2, 4]]);
    }

    #[test]
    fn elements_without_properties() {
        let e = read_str("ply\nformat ascii 1.0\nelement vertex 3\nelement face 1\nend_header\n")
            .unwrap_err();
        assert!(e.to_string().contains("no scalar \"x\""), "{e}");
        let e = read_str(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nend_header\n0 0 0\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("no vertex_indices"), "{e}");
    }

    #[test]
    fn header_errors() {
        assert!(read_str("").unwrap_err().to_string().contains("no header"));
        assert!(read_str("plyx\n")
            .unwrap_err()
            .to_string()
            .contains("not a PLY"));
        let e = read_str("ply\nformat ascii 1.0\nelement vertex 1\nproperty flt x\nend_header\n")
            .unwrap_err();
        assert!(e.to_string().contains("line 4"), "{e}");
        let e = read_str("ply\nformat ascii 1.0\nelement vertex 1\n").unwrap_err();
        assert!(e.to_string().contains("end_header"), "{e}");
    }
}
