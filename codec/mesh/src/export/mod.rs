//! Mesh writers: binary PLY, OBJ and GLB. Each output reads back through
//! [`crate::import`] as the same mesh: bit-exact positions, colours and
//! triangles. [`md2`] writes Quake II models (quantized to bytes, so only
//! an MD2 read back re-writes bit for bit).

use std::io::Write;

mod lod_glb;
pub mod md2;
mod md2_repair;
mod md2_sample;
mod normal_table;

pub use lod_glb::{
    corner_vertices, screen_coverage, write_lod_glb, CornerVertices, LevelCorners, LodGlb,
};
pub use md2::{mesh_to_md2, write_md2, write_mesh_md2};
pub use md2_sample::{sample_md2, SAMPLE_SKIN};
pub use normal_table::{nearest_normal, normal_table, NORMAL_COUNT};

use crate::import::srgb_u8_to_linear;
use crate::{Error, IndexedMesh, Result};

/// Bytes gathered before each write to `w` (callers need not buffer).
const CHUNK: usize = 1 << 16;

fn validate(mesh: &IndexedMesh) -> Result<()> {
    let n = mesh.positions.len();
    if let Some(c) = &mesh.colors {
        if c.len() != n {
            return Err(Error::Parameter(format!(
                "mesh has {} colours for {n} vertices",
                c.len()
            )));
        }
    }
    if let Some((f, t)) = mesh
        .triangles
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&i| i as usize >= n))
    {
        return Err(Error::Parameter(format!(
            "triangle {f} {t:?} refers past the {n} vertices"
        )));
    }
    if n > u32::MAX as usize {
        return Err(Error::Limit(format!("{n} vertices")));
    }
    Ok(())
}

/// Writes a `binary_little_endian` PLY: float x, y, z (+ uchar red, green,
/// blue when the mesh has colours) and `list uchar uint vertex_indices`.
pub fn write_ply(mesh: &IndexedMesh, w: &mut impl Write) -> Result<()> {
    validate(mesh)?;
    let mut header = String::from("ply\nformat binary_little_endian 1.0\ncomment vitrine\n");
    header += &format!(
        "element vertex {}\nproperty float x\nproperty float y\nproperty float z\n",
        mesh.positions.len()
    );
    if mesh.colors.is_some() {
        header += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    }
    header += &format!(
        "element face {}\nproperty list uchar uint vertex_indices\nend_header\n",
        mesh.triangles.len()
    );
    w.write_all(header.as_bytes())?;
    let mut buf = Vec::with_capacity(CHUNK + 64);
    for (i, p) in mesh.positions.iter().enumerate() {
        for v in p {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        if let Some(c) = &mesh.colors {
            buf.extend_from_slice(&c[i]);
        }
        if buf.len() >= CHUNK {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    for t in &mesh.triangles {
        buf.push(3);
        for v in t {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        if buf.len() >= CHUNK {
            w.write_all(&buf)?;
            buf.clear();
        }
    }
    w.write_all(&buf)?;
    Ok(())
}

/// Writes an OBJ: `v x y z` (`v x y z r g b` with colours as 0–1 floats)
/// and `f a b c`. Rust's shortest round-trip float formatting makes the
/// numbers read back bit-exact.
pub fn write_obj(mesh: &IndexedMesh, w: &mut impl Write) -> Result<()> {
    use std::fmt::Write as _;
    validate(mesh)?;
    let mut buf = String::with_capacity(CHUNK + 128);
    let _ = writeln!(
        buf,
        "# vitrine\n# vertices: {}\n# faces: {}",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    for (i, p) in mesh.positions.iter().enumerate() {
        let _ = match &mesh.colors {
            Some(c) => {
                let c = c[i].map(|v| v as f32 / 255.0);
                writeln!(
                    buf,
                    "v {} {} {} {} {} {}",
                    p[0], p[1], p[2], c[0], c[1], c[2]
                )
            }
            None => writeln!(buf, "v {} {} {}", p[0], p[1], p[2]),
        };
        if buf.len() >= CHUNK {
            w.write_all(buf.as_bytes())?;
            buf.clear();
        }
    }
    for t in &mesh.triangles {
        let _ = writeln!(buf, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1);
        if buf.len() >= CHUNK {
            w.write_all(buf.as_bytes())?;
            buf.clear();
        }
    }
    w.write_all(buf.as_bytes())?;
    Ok(())
}

/// What a GLB says beside its mesh: who to credit, what the mesh is called,
/// where it stands in glTF's frame, and Dublin Core metadata. All optional;
/// the default says nothing.
#[derive(Clone, Debug, Default)]
pub struct GlbDocument {
    /// `asset.copyright`, "a copyright message suitable for display to
    /// credit the content creator" (glTF 2.0).
    pub copyright: Option<String>,
    /// The name of the mesh and of its node.
    pub name: Option<String>,
    /// Column-major 4×4 matrix of the mesh's node: what turns the mesh's
    /// coordinates into glTF's (+Y up, metres). Must be finite.
    pub matrix: Option<[f32; 16]>,
    /// A `KHR_xmp_json_ld` packet (a JSON-LD object with its `@context`)
    /// for the whole asset: title, rights, source.
    pub xmp: Option<serde_json::Value>,
}

/// Writes a glTF 2.0 binary: one mesh, one triangle primitive with
/// POSITION (float VEC3 with min/max), COLOR_0 when coloured (float VEC3,
/// linear as the spec wants: the sRGB bytes are converted exactly so that
/// the importer recovers them) and uint32 indices.
pub fn write_glb(mesh: &IndexedMesh, w: &mut impl Write) -> Result<()> {
    write_glb_document(mesh, &GlbDocument::default(), w)
}

/// [`write_glb`], saying what `doc` holds beside the mesh.
pub fn write_glb_document(mesh: &IndexedMesh, doc: &GlbDocument, w: &mut impl Write) -> Result<()> {
    validate(mesh)?;
    if doc.matrix.is_some_and(|m| m.iter().any(|x| !x.is_finite())) {
        return Err(Error::Parameter("GLB node matrix is not finite".into()));
    }
    if mesh.positions.is_empty() || mesh.triangles.is_empty() {
        return Err(Error::Parameter(
            "cannot write an empty mesh as glTF (accessors need at least one element)".into(),
        ));
    }
    let layout = BinLayout::of(mesh);
    let json = glb_json(mesh, doc, &layout);
    let bin_len = layout.len();
    let total = 12 + 8 + json.len() + 8 + bin_len;
    let total = u32::try_from(total)
        .map_err(|_| Error::Limit(format!("GLB would be {total} bytes, over 4 GiB")))?;

    let mut buf = Vec::with_capacity(CHUNK + 64);
    buf.extend_from_slice(b"glTF");
    buf.extend_from_slice(&2u32.to_le_bytes());
    buf.extend_from_slice(&total.to_le_bytes());
    buf.extend_from_slice(&(json.len() as u32).to_le_bytes());
    buf.extend_from_slice(b"JSON");
    buf.extend_from_slice(json.as_bytes());
    buf.extend_from_slice(&(bin_len as u32).to_le_bytes());
    buf.extend_from_slice(b"BIN\0");
    write_glb_bin(mesh, buf, w)
}

/// The length of the BIN chunk [`write_glb`] writes for a mesh of these
/// counts (the file adds its headers and JSON chunk), to tell a visitor a
/// download's size before it is decoded.
pub fn glb_bin_bytes(vertices: usize, triangles: usize, coloured: bool) -> usize {
    BinLayout::for_counts(vertices, triangles, coloured).len()
}

/// Byte lengths of the GLB's BIN chunk parts, in order: positions, indices,
/// colours (0 without).
struct BinLayout {
    pos_len: usize,
    idx_len: usize,
    col_len: usize,
}

impl BinLayout {
    fn of(mesh: &IndexedMesh) -> Self {
        Self::for_counts(
            mesh.positions.len(),
            mesh.triangles.len(),
            mesh.colors.is_some(),
        )
    }

    fn for_counts(vertices: usize, triangles: usize, coloured: bool) -> Self {
        BinLayout {
            pos_len: 12 * vertices,
            idx_len: 12 * triangles,
            col_len: if coloured { 12 * vertices } else { 0 },
        }
    }

    fn len(&self) -> usize {
        self.pos_len + self.idx_len + self.col_len
    }
}

/// The GLB's JSON chunk, padded with spaces to a multiple of 4 bytes.
fn glb_json(mesh: &IndexedMesh, doc: &GlbDocument, layout: &BinLayout) -> String {
    let n = mesh.positions.len();
    let BinLayout {
        pos_len,
        idx_len,
        col_len,
    } = *layout;
    let (min, max) = bounds(&mesh.positions);
    let (colour_attr, colour_view, colour_acc) = if mesh.colors.is_some() {
        (
            r#","COLOR_0":2"#.to_string(),
            format!(
                r#",{{"buffer":0,"byteOffset":{},"byteLength":{col_len},"target":34962}}"#,
                pos_len + idx_len
            ),
            format!(r#",{{"bufferView":2,"componentType":5126,"count":{n},"type":"VEC3"}}"#),
        )
    } else {
        Default::default()
    };
    let text = |s: &str| serde_json::Value::from(s).to_string();
    let mut asset = String::new();
    if let Some(copyright) = &doc.copyright {
        asset += &format!(r#","copyright":{}"#, text(copyright));
    }
    let mut named = String::new();
    if let Some(name) = &doc.name {
        named += &format!(r#","name":{}"#, text(name));
    }
    let mut node = named.clone();
    if let Some(m) = &doc.matrix {
        let m: Vec<String> = m.iter().map(|x| x.to_string()).collect();
        node += &format!(r#","matrix":[{}]"#, m.join(","));
    }
    let mut root = String::new();
    if let Some(packet) = &doc.xmp {
        asset += r#","extensions":{"KHR_xmp_json_ld":{"packet":0}}"#;
        root += &format!(
            r#","extensionsUsed":["KHR_xmp_json_ld"],"extensions":{{"KHR_xmp_json_ld":{{"packets":[{packet}]}}}}"#
        );
    }
    let mut json = format!(
        concat!(
            r#"{{"asset":{{"version":"2.0","generator":"vitrine-codec"{asset}}},"#,
            r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0{node}}}],"#,
            r#""meshes":[{{"primitives":[{{"attributes":{{"POSITION":0{ca}}},"indices":1,"mode":4}}]{named}}}],"#,
            r#""buffers":[{{"byteLength":{bin_len}}}],"#,
            r#""bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":{pos_len},"target":34962}},"#,
            r#"{{"buffer":0,"byteOffset":{pos_len},"byteLength":{idx_len},"target":34963}}{cv}],"#,
            r#""accessors":[{{"bufferView":0,"componentType":5126,"count":{n},"type":"VEC3","#,
            r#""min":[{min0},{min1},{min2}],"max":[{max0},{max1},{max2}]}},"#,
            r#"{{"bufferView":1,"componentType":5125,"count":{ni},"type":"SCALAR"}}{cacc}]{root}}}"#
        ),
        ca = colour_attr,
        bin_len = layout.len(),
        pos_len = pos_len,
        idx_len = idx_len,
        cv = colour_view,
        n = n,
        min0 = min[0],
        min1 = min[1],
        min2 = min[2],
        max0 = max[0],
        max1 = max[1],
        max2 = max[2],
        ni = 3 * mesh.triangles.len(),
        cacc = colour_acc,
        asset = asset,
        node = node,
        named = named,
        root = root,
    );
    let padded = json.len().next_multiple_of(4);
    json.extend(std::iter::repeat_n(' ', padded - json.len()));
    json
}

/// Per-axis minimum and maximum of the positions.
fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    }
    (min, max)
}

/// Appends the BIN chunk's data to `buf` (which holds what comes before it)
/// and writes it all to `w`, about [`CHUNK`] bytes at a time.
fn write_glb_bin(mesh: &IndexedMesh, mut buf: Vec<u8>, w: &mut impl Write) -> Result<()> {
    let mut flush = |buf: &mut Vec<u8>, force: bool| -> Result<()> {
        if force || buf.len() >= CHUNK {
            w.write_all(buf)?;
            buf.clear();
        }
        Ok(())
    };
    for p in &mesh.positions {
        for v in p {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        flush(&mut buf, false)?;
    }
    for t in &mesh.triangles {
        for v in t {
            buf.extend_from_slice(&v.to_le_bytes());
        }
        flush(&mut buf, false)?;
    }
    if let Some(colors) = &mesh.colors {
        for c in colors {
            for &v in c {
                buf.extend_from_slice(&srgb_u8_to_linear(v).to_le_bytes());
            }
            flush(&mut buf, false)?;
        }
    }
    flush(&mut buf, true)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::import::{import_bytes, ImportOptions, MeshFormat};

    fn mesh(colour: bool) -> IndexedMesh {
        IndexedMesh {
            positions: vec![
                [0.1, -0.0, 3.5e-8],
                [1.0 / 3.0, f32::MAX, -7.25],
                [f32::MIN_POSITIVE, 2.0, 1e30],
                [-1.5, 0.2, 0.3],
            ],
            colors: colour.then(|| vec![[0, 1, 2], [255, 128, 7], [13, 200, 254], [9, 9, 9]]),
            triangles: vec![[0, 1, 2], [0, 2, 3]],
        }
    }

    #[test]
    fn round_trips_are_exact() {
        for colour in [false, true] {
            let m = mesh(colour);
            for (format, out) in [
                (MeshFormat::Ply, {
                    let mut v = Vec::new();
                    write_ply(&m, &mut v).unwrap();
                    v
                }),
                (MeshFormat::Obj, {
                    let mut v = Vec::new();
                    write_obj(&m, &mut v).unwrap();
                    v
                }),
                (MeshFormat::Glb, {
                    let mut v = Vec::new();
                    write_glb(&m, &mut v).unwrap();
                    v
                }),
            ] {
                let back = import_bytes(&out, format, &ImportOptions::default()).unwrap();
                let bits = |m: &IndexedMesh| -> Vec<[u32; 3]> {
                    m.positions.iter().map(|p| p.map(f32::to_bits)).collect()
                };
                assert_eq!(bits(&back), bits(&m), "{format:?}");
                assert_eq!(back.colors, m.colors, "{format:?}");
                assert_eq!(back.triangles, m.triangles, "{format:?}");
            }
        }
    }

    #[test]
    fn a_document_names_credits_and_places_the_mesh() {
        let m = mesh(true);
        let doc = GlbDocument {
            copyright: Some("Scan: \"Museo\" </script>".into()),
            name: Some("Stele".into()),
            // Z up to Y up, millimetres to metres.
            matrix: Some([
                0.001, 0.0, 0.0, 0.0, 0.0, 0.0, -0.001, 0.0, 0.0, 0.001, 0.0, 0.0, 0.0, 0.0, 0.0,
                1.0,
            ]),
            xmp: Some(
                serde_json::json!({ "@context": { "dc": "http://purl.org/dc/elements/1.1/" } }),
            ),
        };
        let mut out = Vec::new();
        write_glb_document(&m, &doc, &mut out).unwrap();
        let gltf = gltf::Gltf::from_slice(&out).unwrap();
        assert_eq!(gltf.document.as_json().asset.copyright, doc.copyright);
        let json_len = u32::from_le_bytes(out[12..16].try_into().unwrap()) as usize;
        let json: serde_json::Value = serde_json::from_slice(&out[20..20 + json_len]).unwrap();
        assert_eq!(json["nodes"][0]["name"], "Stele");
        assert_eq!(json["meshes"][0]["name"], "Stele");
        assert!(gltf
            .document
            .extensions_used()
            .any(|e| e == "KHR_xmp_json_ld"));
        // Read back through the node: (x, y, z) mm -> (x, z, -y) m.
        let back = import_bytes(&out, MeshFormat::Glb, &ImportOptions::default()).unwrap();
        for (b, p) in back.positions.iter().zip(&m.positions) {
            let want = [p[0] * 0.001, p[2] * 0.001, -p[1] * 0.001];
            for k in 0..3 {
                assert!((b[k] - want[k]).abs() < 1e-6, "{b:?} against {want:?}");
            }
        }
        assert_eq!(back.triangles, m.triangles);
        let mut bad = doc.clone();
        bad.matrix.as_mut().unwrap()[0] = f32::NAN;
        assert!(write_glb_document(&m, &bad, &mut Vec::new()).is_err());
        // The default document writes what write_glb always wrote.
        let (mut plain, mut default) = (Vec::new(), Vec::new());
        write_glb(&m, &mut plain).unwrap();
        write_glb_document(&m, &GlbDocument::default(), &mut default).unwrap();
        assert_eq!(plain, default);
    }

    #[test]
    fn bad_meshes_are_refused() {
        let mut m = mesh(true);
        m.triangles.push([0, 1, 4]);
        assert!(write_ply(&m, &mut Vec::new()).is_err());
        let mut m = mesh(true);
        m.colors.as_mut().unwrap().pop();
        assert!(write_obj(&m, &mut Vec::new()).is_err());
        assert!(write_glb(&IndexedMesh::default(), &mut Vec::new()).is_err());
    }
}
