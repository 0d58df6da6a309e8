//! glTF with compressed geometry, as gltfpack, gltf-transform and Blender
//! write it: `EXT_meshopt_compression` buffer views and
//! `KHR_draco_mesh_compression` primitives, each on a file built here with
//! the peers' own encoders (the `meshopt` and `draco-core` crates). A
//! compressed file must import to exactly the mesh its uncompressed twin
//! gives; a hostile one is a clear error before anything big is allocated.

use draco_core::{
    DataType, DecoderBuffer, EncoderBuffer, EncoderOptions, FaceIndex, GeometryAttributeType, Mesh,
    MeshDecoder, MeshEncoder, PointAttribute, PointIndex,
};
use vitrine_codec::IndexedMesh;
use vitrine_mesh::import::{import_bytes, ImportOptions, MeshFormat};

mod common;
use common::{le, Glb};

fn import(bytes: &[u8]) -> vitrine_codec::Result<IndexedMesh> {
    import_bytes(bytes, MeshFormat::Glb, &ImportOptions::default())
}

/// A coloured torus, 1,200 vertices: enough for the codecs' real paths.
fn sample() -> IndexedMesh {
    let mut m = vitrine_samples::torus(40, 30, 1.0, 0.35);
    vitrine_samples::paint(&mut m);
    m
}

fn bounds(p: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for v in p {
        for k in 0..3 {
            lo[k] = lo[k].min(v[k]);
            hi[k] = hi[k].max(v[k]);
        }
    }
    (lo, hi)
}

fn vec3_accessor(
    view: Option<usize>,
    count: usize,
    component: u32,
    lo: [f32; 3],
    hi: [f32; 3],
) -> String {
    let view = view
        .map(|v| format!(r#""bufferView":{v},"#))
        .unwrap_or_default();
    format!(
        r#"{view}"componentType":{component},"count":{count},"type":"VEC3","min":{lo:?},"max":{hi:?}"#
    )
}

fn colour_accessor(view: Option<usize>, count: usize) -> String {
    let view = view
        .map(|v| format!(r#""bufferView":{v},"#))
        .unwrap_or_default();
    format!(r#"{view}"componentType":5121,"normalized":true,"count":{count},"type":"VEC4""#)
}

fn index_accessor(view: Option<usize>, count: usize) -> String {
    let view = view
        .map(|v| format!(r#""bufferView":{v},"#))
        .unwrap_or_default();
    format!(r#"{view}"componentType":5125,"count":{count},"type":"SCALAR""#)
}

/// One primitive under one node; `prim_extra` goes inside the primitive.
fn document(
    position: usize,
    colour: usize,
    indices: usize,
    prim_extra: &str,
    extra: &str,
) -> String {
    format!(
        r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{position},"COLOR_0":{colour}}},"indices":{indices}{prim_extra}}}]}}]{extra}"#
    )
}

/// The plain GLB of `positions`, RGBA8 `colours` and `indices`.
fn plain(positions: &[[f32; 3]], colours: &[[u8; 4]], indices: &[u32]) -> Vec<u8> {
    let mut g = Glb::default();
    let (lo, hi) = bounds(positions);
    let pv = g.view(&le(positions.as_flattened(), f32::to_le_bytes));
    let p = g.accessor(vec3_accessor(Some(pv), positions.len(), 5126, lo, hi));
    let cv = g.view(colours.as_flattened());
    let c = g.accessor(colour_accessor(Some(cv), colours.len()));
    let iv = g.view(&le(indices, u32::to_le_bytes));
    let i = g.accessor(index_accessor(Some(iv), indices.len()));
    g.bytes(&document(p, c, i, "", ""))
}

fn rgba(mesh: &IndexedMesh) -> Vec<[u8; 4]> {
    // COLOR_0 is linear; any bytes will do, the twin holds the same ones.
    mesh.colors
        .as_ref()
        .unwrap()
        .iter()
        .map(|c| [c[0], c[1], c[2], 255])
        .collect()
}

// ------------------------------------------------------ EXT_meshopt_compression

const MESHOPT_REQUIRED: &str = r#","extensionsUsed":["EXT_meshopt_compression"],"extensionsRequired":["EXT_meshopt_compression"]"#;

impl Glb {
    /// `encoded` in the BIN chunk as a compressed view of `count` elements of
    /// `stride` bytes over the fallback buffer 1; its index.
    fn meshopt_view(
        &mut self,
        encoded: &[u8],
        count: usize,
        stride: usize,
        mode: &str,
        filter: &str,
        attribute: bool,
    ) -> usize {
        self.bin.resize(self.bin.len().next_multiple_of(4), 0);
        let stride_member = if attribute {
            format!(r#","byteStride":{stride}"#)
        } else {
            String::new()
        };
        self.views.push(format!(
            r#"{{"buffer":1,"byteLength":{}{stride_member},"extensions":{{"EXT_meshopt_compression":{{"buffer":0,"byteOffset":{},"byteLength":{},"byteStride":{stride},"count":{count},"mode":"{mode}","filter":"{filter}"}}}}}}"#,
            count * stride,
            self.bin.len(),
            encoded.len()
        ));
        self.bin.extend_from_slice(encoded);
        if self.more_buffers.is_empty() {
            self.more_buffers.push(
                r#"{"byteLength":1048576,"extensions":{"EXT_meshopt_compression":{"fallback":true}}}"#
                    .to_string(),
            );
        }
        self.views.len() - 1
    }
}

fn meshopt_glb(mesh: &IndexedMesh, index_mode: &str) -> Vec<u8> {
    let positions = &mesh.positions;
    let colours = rgba(mesh);
    let indices: Vec<u32> = mesh.triangles.as_flattened().to_vec();
    let mut g = Glb::default();
    let (lo, hi) = bounds(positions);
    let enc = meshopt::encode_vertex_buffer(positions).unwrap();
    let pv = g.meshopt_view(&enc, positions.len(), 12, "ATTRIBUTES", "NONE", true);
    let p = g.accessor(vec3_accessor(Some(pv), positions.len(), 5126, lo, hi));
    let enc = meshopt::encode_vertex_buffer(&colours).unwrap();
    let cv = g.meshopt_view(&enc, colours.len(), 4, "ATTRIBUTES", "NONE", true);
    let c = g.accessor(colour_accessor(Some(cv), colours.len()));
    let enc = if index_mode == "TRIANGLES" {
        meshopt::encode_index_buffer(&indices, positions.len()).unwrap()
    } else {
        meshopt::encode_index_sequence(&indices, positions.len()).unwrap()
    };
    let iv = g.meshopt_view(&enc, indices.len(), 4, index_mode, "NONE", false);
    let i = g.accessor(index_accessor(Some(iv), indices.len()));
    g.bytes(&document(p, c, i, "", MESHOPT_REQUIRED))
}

#[test]
fn meshopt_views_import_as_their_uncompressed_twin() {
    let mesh = sample();
    let twin = import(&plain(
        &mesh.positions,
        &rgba(&mesh),
        mesh.triangles.as_flattened(),
    ))
    .unwrap();
    for mode in ["TRIANGLES", "INDICES"] {
        let file = meshopt_glb(&mesh, mode);
        let got = import(&file).unwrap_or_else(|e| panic!("{mode}: {e}"));
        assert_eq!(got, twin, "{mode}: not the uncompressed file's mesh");
        assert!(
            file.len() < plain(&mesh.positions, &rgba(&mesh), mesh.triangles.as_flattened()).len()
        );
    }
    assert_eq!(twin.vertex_count(), mesh.vertex_count());
    assert_eq!(twin.triangles.len(), mesh.triangles.len());
}

#[test]
fn meshopt_octahedral_filter_decodes_normal_vectors() {
    // Normals are not imported, but a filtered view must decode and not
    // disturb the rest: an octahedral NORMAL beside plain positions.
    let mesh = sample();
    let normals: Vec<[f32; 4]> = mesh
        .positions
        .iter()
        .map(|p| {
            let l = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            [p[0] / l, p[1] / l, p[2] / l, 0.0]
        })
        .collect();
    let oct: Vec<[i8; 4]> = meshopt::encode_filter_oct(&normals, 8);
    let enc = meshopt::encode_vertex_buffer(&oct).unwrap();
    let mut g = Glb::default();
    let (lo, hi) = bounds(&mesh.positions);
    let pv = g.view(&le(mesh.positions.as_flattened(), f32::to_le_bytes));
    let p = g.accessor(vec3_accessor(Some(pv), mesh.positions.len(), 5126, lo, hi));
    let nv = g.meshopt_view(&enc, normals.len(), 4, "ATTRIBUTES", "OCTAHEDRAL", true);
    let n = g.accessor(format!(
        r#""bufferView":{nv},"componentType":5120,"normalized":true,"count":{},"type":"VEC3""#,
        normals.len()
    ));
    let iv = g.view(&le(mesh.triangles.as_flattened(), u32::to_le_bytes));
    let i = g.accessor(index_accessor(Some(iv), mesh.triangles.len() * 3));
    let doc = format!(
        r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0}}],
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":{p},"NORMAL":{n}}},"indices":{i}}}]}}]{MESHOPT_REQUIRED}"#
    );
    let got = import(&g.bytes(&doc)).unwrap();
    assert_eq!(got.positions.len(), mesh.positions.len());
    assert_eq!(got.triangles.len(), mesh.triangles.len());
}

#[test]
fn hostile_meshopt_views_are_clear_errors() {
    let mesh = sample();
    let good = String::from_utf8_lossy(&meshopt_glb(&mesh, "TRIANGLES")).into_owned();
    let json_of =
        |file: &[u8]| -> usize { u32::from_le_bytes(file[12..16].try_into().unwrap()) as usize };
    // Rewrites the JSON chunk (padded to its length) and keeps the BIN.
    let rewrite = |from: &str, to: &str| -> Vec<u8> {
        let file = meshopt_glb(&mesh, "TRIANGLES");
        let n = json_of(&file);
        let json = std::str::from_utf8(&file[20..20 + n])
            .unwrap()
            .trim_end()
            .to_string();
        assert!(json.contains(from), "{from} not in the document");
        let mut json = json.replacen(from, to, 1).into_bytes();
        json.resize(json.len().next_multiple_of(4), b' ');
        let bin = &file[20 + n..];
        let mut out = b"glTF".to_vec();
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((20 + json.len() + bin.len()) as u32).to_le_bytes());
        out.extend_from_slice(&(json.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&json);
        out.extend_from_slice(bin);
        out
    };
    assert!(good.contains(r#""count":1200,"mode":"ATTRIBUTES""#));
    let cases = [
        // A count the encoded bytes cannot hold: refused before allocating.
        (
            r#""count":1200,"mode":"ATTRIBUTES""#,
            r#""count":4000000000,"mode":"ATTRIBUTES""#,
            "more than such a stream can hold",
        ),
        // Fewer elements than encoded: the decoder reports the mismatch.
        (
            r#""count":1200,"mode":"ATTRIBUTES""#,
            r#""count":1000,"mode":"ATTRIBUTES""#,
            "EXT_meshopt_compression",
        ),
        (r#""mode":"TRIANGLES""#, r#""mode":"QUADS""#, "unknown mode"),
        (
            r#""filter":"NONE"}}}"#,
            r#""filter":"SPIRAL"}}}"#,
            "unknown filter",
        ),
        (
            r#""buffer":0,"byteOffset":0"#,
            r#""buffer":7,"byteOffset":0"#,
            "does not exist",
        ),
        (
            r#""buffer":0,"byteOffset":0"#,
            r#""buffer":0,"byteOffset":99999999"#,
            "past the end",
        ),
        (
            r#""byteStride":12,"count""#,
            r#""byteStride":13,"count""#,
            "byteStride 13",
        ),
    ];
    for (from, to, why) in cases {
        let e = import(&rewrite(from, to)).unwrap_err().to_string();
        assert!(e.contains(why), "{to}: {e}");
    }
    // The encoded bytes cut short (the extension's byteLength): every cut
    // is the decoder's error, never a panic nor garbage.
    let key = r#""buffer":0,"byteOffset":0,"byteLength":"#;
    let at = good.find(key).unwrap() + key.len();
    let digits: String = good[at..]
        .chars()
        .take_while(char::is_ascii_digit)
        .collect();
    let full: usize = digits.parse().unwrap();
    for cut in [0, 1, 16, full / 2, full - 1] {
        let e = import(&rewrite(&format!("{key}{digits}"), &format!("{key}{cut}")))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("EXT_meshopt_compression"),
            "{cut} of {full} bytes: {e}"
        );
    }
}

// --------------------------------------------------- KHR_draco_mesh_compression

const DRACO_REQUIRED: &str = r#","extensionsUsed":["KHR_draco_mesh_compression"],"extensionsRequired":["KHR_draco_mesh_compression"]"#;

/// `mesh` as a Draco stream: positions (quantized to 14 bits), RGBA8
/// colours (normalized), faces; speed 5 (edgebreaker, as Blender writes).
fn draco_stream(mesh: &IndexedMesh) -> Vec<u8> {
    let n = mesh.positions.len();
    let mut d = Mesh::new();
    let mut pos = PointAttribute::new();
    pos.init(
        GeometryAttributeType::Position,
        3,
        DataType::Float32,
        false,
        n,
    );
    for (i, p) in mesh.positions.iter().enumerate() {
        for (k, v) in p.iter().enumerate() {
            pos.buffer_mut().write((i * 3 + k) * 4, &v.to_le_bytes());
        }
    }
    let mut col = PointAttribute::new();
    col.init(GeometryAttributeType::Color, 4, DataType::Uint8, true, n);
    for (i, c) in rgba(mesh).iter().enumerate() {
        col.buffer_mut().write(i * 4, c);
    }
    d.add_attribute(pos);
    d.add_attribute(col);
    d.set_num_faces(mesh.triangles.len());
    for (f, t) in mesh.triangles.iter().enumerate() {
        d.set_face(
            FaceIndex(f as u32),
            [PointIndex(t[0]), PointIndex(t[1]), PointIndex(t[2])],
        );
    }
    let mut options = EncoderOptions::new();
    options.set_global_int("encoding_speed", 5);
    options.set_global_int("decoding_speed", 5);
    options.set_attribute_int(0, "quantization_bits", 14);
    let mut encoder = MeshEncoder::new();
    encoder.set_mesh(d);
    let mut out = EncoderBuffer::new();
    encoder.encode(&options, &mut out).unwrap();
    out.data().to_vec()
}

/// What the stream decodes to, read with draco-core directly.
fn draco_decoded(stream: &[u8]) -> (Vec<[f32; 3]>, Vec<[u8; 4]>, Vec<u32>) {
    let mut m = Mesh::new();
    MeshDecoder::new()
        .decode(&mut DecoderBuffer::new(stream), &mut m)
        .unwrap();
    let n = m.num_points();
    let mut pos = None;
    let mut col = None;
    for a in 0..m.num_attributes() {
        let att = m.attribute(a);
        match att.attribute_type() {
            GeometryAttributeType::Position => pos = Some(att.read_f32s(n, 3)),
            GeometryAttributeType::Color => col = Some(att.read_f32s(n, 4)),
            _ => {}
        }
    }
    let positions = pos.unwrap().chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    let colours = col
        .unwrap()
        .chunks(4)
        .map(|c| [c[0] as u8, c[1] as u8, c[2] as u8, c[3] as u8])
        .collect();
    let indices = m.faces().iter().flat_map(|f| f.map(|p| p.0)).collect();
    (positions, colours, indices)
}

fn draco_glb(
    stream: &[u8],
    points: usize,
    faces: usize,
    lo: [f32; 3],
    hi: [f32; 3],
    ids: &str,
) -> Vec<u8> {
    let mut g = Glb::default();
    let view = g.view(stream);
    let p = g.accessor(vec3_accessor(None, points, 5126, lo, hi));
    let c = g.accessor(colour_accessor(None, points));
    let i = g.accessor(index_accessor(None, faces * 3));
    let ext = format!(
        r#","extensions":{{"KHR_draco_mesh_compression":{{"bufferView":{view},"attributes":{{{ids}}}}}}}"#
    );
    g.bytes(&document(p, c, i, &ext, DRACO_REQUIRED))
}

#[test]
fn draco_primitives_import_as_their_decoded_twin() {
    let mesh = sample();
    let stream = draco_stream(&mesh);
    let (positions, colours, indices) = draco_decoded(&stream);
    let (lo, hi) = bounds(&positions);
    let file = draco_glb(
        &stream,
        positions.len(),
        indices.len() / 3,
        lo,
        hi,
        r#""POSITION":0,"COLOR_0":1"#,
    );
    let got = import(&file).unwrap();
    let twin = import(&plain(&positions, &colours, &indices)).unwrap();
    assert_eq!(got, twin, "not the mesh of the stream's own decoding");
    // And that is the sample, within Draco's 14-bit quantization.
    assert_eq!(got.triangles.len(), mesh.triangles.len());
    let (mlo, mhi) = bounds(&mesh.positions);
    let step = (0..3).map(|k| mhi[k] - mlo[k]).fold(0.0f32, f32::max) / ((1 << 14) - 1) as f32;
    for (a, b) in bounds(&got.positions).0.iter().zip(mlo) {
        assert!((a - b).abs() <= step, "{a} against {b}");
    }
    assert!(
        file.len() * 3 < plain(&positions, &colours, &indices).len(),
        "Draco did not compress"
    );
}

#[test]
fn hostile_draco_primitives_are_clear_errors() {
    let mesh = sample();
    let stream = draco_stream(&mesh);
    let (positions, _, indices) = draco_decoded(&stream);
    let (lo, hi) = bounds(&positions);
    let n = positions.len();
    let f = indices.len() / 3;
    let ids = r#""POSITION":0,"COLOR_0":1"#;
    // An attribute id the stream lacks.
    let e = import(&draco_glb(
        &stream,
        n,
        f,
        lo,
        hi,
        r#""POSITION":0,"COLOR_0":9"#,
    ))
    .unwrap_err();
    assert!(e.to_string().contains("which the stream lacks"), "{e}");
    // An accessor count that is not the stream's.
    let e = import(&draco_glb(&stream, n + 1, f, lo, hi, ids)).unwrap_err();
    assert!(e.to_string().contains("but the stream decodes"), "{e}");
    // Garbage and every truncation: an error naming Draco, never a panic.
    let mut garbage = stream.clone();
    for b in garbage.iter_mut().skip(12).step_by(3) {
        *b ^= 0x5a;
    }
    let e = import(&draco_glb(&garbage, n, f, lo, hi, ids));
    assert!(e.is_err());
    for keep in [0, 4, 16, stream.len() / 2, stream.len() - 1] {
        let e = import(&draco_glb(&stream[..keep], n, f, lo, hi, ids)).unwrap_err();
        assert!(
            e.to_string().contains("KHR_draco_mesh_compression"),
            "{keep}: {e}"
        );
    }
    // Limits: a stream of more points than the import allows is refused by
    // the decoder before it allocates them.
    let small = ImportOptions {
        max_vertices: 100,
        ..ImportOptions::default()
    };
    let e = import_bytes(
        &draco_glb(&stream, n, f, lo, hi, ids),
        MeshFormat::Glb,
        &small,
    )
    .unwrap_err();
    assert!(e.to_string().contains("KHR_draco_mesh_compression"), "{e}");
}
