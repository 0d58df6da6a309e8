//! Importers, exporters and repair on generated inputs, a corpus of bad
//! inputs, and (when present) the real scans in `../shared/data/meshes`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use proptest::prelude::*;
use vitrine_codec::{Error, IndexedMesh};
use vitrine_mesh::export::{write_glb, write_obj, write_ply};
use vitrine_mesh::import::{import_bytes, import_path, ImportOptions, MeshFormat};
use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions, RepairReport};

fn opts() -> ImportOptions {
    ImportOptions::default()
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("import-tests");
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

fn err_of(bytes: &[u8], format: MeshFormat) -> String {
    match import_bytes(bytes, format, &opts()) {
        Ok(m) => panic!("expected an error, got {} vertices", m.positions.len()),
        Err(e) => e.to_string(),
    }
}

#[track_caller]
fn assert_err(bytes: &[u8], format: MeshFormat, needles: &[&str]) {
    let e = err_of(bytes, format);
    for n in needles {
        assert!(e.contains(n), "error {e:?} does not mention {n:?}");
    }
}

// ---------------------------------------------------------------- PLY

/// The test mesh: a quad (two triangles) and a triangle, with colours.
fn sample_positions() -> Vec<[f32; 3]> {
    vec![
        [0.0, 0.0, 0.0],
        [1.5, -0.0, 0.25],
        [1.0, 1.0, 1e-7],
        [-3.25, 1.0, 0.0],
        [0.1, 0.2, 0.3],
    ]
}

fn sample_colors() -> Vec<[u8; 3]> {
    vec![
        [255, 0, 0],
        [0, 255, 0],
        [0, 0, 255],
        [10, 20, 30],
        [200, 100, 1],
    ]
}

fn sample_polygons() -> Vec<Vec<i32>> {
    vec![vec![0, 1, 2, 3], vec![1, 4, 2]]
}

fn sample_triangles() -> Vec<[u32; 3]> {
    vec![[0, 1, 2], [0, 2, 3], [1, 4, 2]]
}

#[derive(Clone, Copy, PartialEq)]
enum Enc {
    Ascii,
    Le,
    Be,
}

/// A PLY with extra vertex properties (scalar and list), an unknown element
/// before the vertices, uchar colours and faces with an extra property.
fn sample_ply(enc: Enc) -> Vec<u8> {
    let format = match enc {
        Enc::Ascii => "ascii",
        Enc::Le => "binary_little_endian",
        Enc::Be => "binary_big_endian",
    };
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment generated\nobj_info test\n\
         element material 2\nproperty uchar shininess\nproperty list uchar float params\n\
         element vertex 5\nproperty float x\nproperty double confidence\nproperty float y\n\
         property float z\nproperty uchar red\nproperty uchar green\nproperty uchar blue\n\
         property list uint8 int16 junk\nproperty uchar alpha\n\
         element face 2\nproperty short flags\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n"
    )
    .into_bytes();
    let pos = sample_positions();
    let col = sample_colors();
    let be = enc == Enc::Be;
    macro_rules! put {
        ($v:expr) => {{
            let v = $v;
            if enc == Enc::Ascii {
                out.extend_from_slice(format!("{} ", v).as_bytes());
            } else if be {
                out.extend_from_slice(&v.to_be_bytes());
            } else {
                out.extend_from_slice(&v.to_le_bytes());
            }
        }};
    }
    // material elements
    for m in 0..2u8 {
        put!(m);
        put!(m);
        for k in 0..m {
            put!(k as f32 * 0.5);
        }
        if enc == Enc::Ascii {
            out.push(b'\n');
        }
    }
    for (i, (p, c)) in pos.iter().zip(&col).enumerate() {
        put!(p[0]);
        put!(0.75f64);
        put!(p[1]);
        put!(p[2]);
        put!(c[0]);
        put!(c[1]);
        put!(c[2]);
        put!(i as u8);
        for k in 0..i {
            put!(k as i16 - 3);
        }
        put!(255u8);
        if enc == Enc::Ascii {
            out.push(b'\n');
        }
    }
    for poly in sample_polygons() {
        put!(7i16);
        put!(poly.len() as u8);
        for v in poly {
            put!(v);
        }
        if enc == Enc::Ascii {
            out.push(b'\n');
        }
    }
    put!(0i32);
    put!(1i32);
    out
}

#[test]
fn ply_ascii_le_be_with_extras_and_colours() {
    for enc in [Enc::Ascii, Enc::Le, Enc::Be] {
        let m = import_bytes(&sample_ply(enc), MeshFormat::Ply, &opts()).unwrap();
        let bits =
            |p: &[[f32; 3]]| -> Vec<[u32; 3]> { p.iter().map(|p| p.map(f32::to_bits)).collect() };
        assert_eq!(bits(&m.positions), bits(&sample_positions()));
        assert_eq!(m.colors.as_deref(), Some(&sample_colors()[..]));
        assert_eq!(m.triangles, sample_triangles());
    }
}

#[test]
fn ply_float_colours_doubles_and_vertex_index() {
    let mut s = String::from(
        "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n\
         property double y\nproperty double z\nproperty float diffuse_red\nproperty float diffuse_green\n\
         property float diffuse_blue\nelement face 1\nproperty list uint uint vertex_index\nend_header\n",
    )
    .into_bytes();
    let verts = [[0.5f64, 1.0, 2.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let cols = [[0.0f32, 0.5, 1.0], [1.0, 1.0, 1.0], [0.2, 0.4, 0.6]];
    for (p, c) in verts.iter().zip(&cols) {
        for v in p {
            s.extend_from_slice(&v.to_le_bytes());
        }
        for v in c {
            s.extend_from_slice(&v.to_le_bytes());
        }
    }
    for v in [3u32, 2, 1, 0] {
        s.extend_from_slice(&v.to_le_bytes());
    }
    let m = import_bytes(&s, MeshFormat::Ply, &opts()).unwrap();
    assert_eq!(
        m.positions,
        vec![[0.5, 1.0, 2.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(
        m.colors.unwrap(),
        vec![[0, 128, 255], [255, 255, 255], [51, 102, 153]]
    );
    assert_eq!(m.triangles, vec![[2, 1, 0]]);
}

#[test]
fn ply_binary_tristrips() {
    let mut s = String::from(
        "ply\nformat binary_big_endian 1.0\nelement vertex 6\nproperty float x\nproperty float y\n\
         property float z\nelement tristrips 2\nproperty list int int vertex_indices\nend_header\n",
    )
    .into_bytes();
    for i in 0..6 {
        for v in [i as f32, (i % 2) as f32, 0.0] {
            s.extend_from_slice(&v.to_be_bytes());
        }
    }
    // Strip 0: 0 1 2 3 -1 2 3 4 5 (restart); strip 1: 4 4 5 (all degenerate).
    for list in [&[0i32, 1, 2, 3, -1, 2, 3, 4, 5][..], &[4, 4, 5][..]] {
        s.extend_from_slice(&(list.len() as i32).to_be_bytes());
        for v in list {
            s.extend_from_slice(&v.to_be_bytes());
        }
    }
    let m = import_bytes(&s, MeshFormat::Ply, &opts()).unwrap();
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [2, 1, 3], [2, 3, 4], [4, 3, 5]]
    );
}

// ---------------------------------------------------------------- OBJ

#[test]
fn obj_corners_negative_quads_colours_whitespace() {
    let src = "# generated\r\nmtllib scan.mtl\r\no scan\r\n\
               v 0 0 0 1 0 0\r\nv\t1.5   -0 0.25 0 1 0\r\n  v 1 1 1e-7 0 0 1\r\n\
               v -3.25 1 0 0.039215688 0.078431375 0.11764706\r\n\
               v 0.1 0.2 0.3 0.78431374 0.39215687 0.003921569\r\n\
               vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\ng part\nusemtl skin\ns 1\n\
               f 1/1/1 2/2/1 3/3/1 4/1/1\n\
               f -4//1 \\\n  -1//1 -3//1\n\
               l 1 2\n";
    let m = import_bytes(src.as_bytes(), MeshFormat::Obj, &opts()).unwrap();
    assert_eq!(m.positions, sample_positions());
    assert_eq!(m.colors.unwrap(), sample_colors());
    assert_eq!(m.triangles, sample_triangles());
}

#[test]
fn obj_without_colours() {
    let m = import_bytes(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0 1.0\nf 1 2 3\n",
        MeshFormat::Obj,
        &opts(),
    )
    .unwrap();
    assert!(m.colors.is_none());
    assert_eq!(m.triangles, vec![[0, 1, 2]]);
}

// ---------------------------------------------------------------- OFF

#[test]
fn off_and_coff() {
    let off = "OFF\n# comment\n5 2 0\n0 0 0\n1.5 -0 0.25\n1 1 1e-7\n-3.25 1 0\n0.1 0.2 0.3\n\
               4 0 1 2 3\n3 1 4 2 255 0 0\n";
    let m = import_bytes(off.as_bytes(), MeshFormat::Off, &opts()).unwrap();
    assert_eq!(m.positions, sample_positions());
    assert_eq!(m.triangles, sample_triangles());
    assert!(m.colors.is_none());

    let coff = "COFF 5 2 0\n0 0 0 255 0 0 255\n1.5 -0 0.25 0 255 0 255\n1 1 1e-7 0 0 255 255\n\
                -3.25 1 0 10 20 30 255\n0.1 0.2 0.3 200 100 1 255\n4 0 1 2 3\n3 1 4 2\n";
    let m = import_bytes(coff.as_bytes(), MeshFormat::Off, &opts()).unwrap();
    assert_eq!(m.colors.unwrap(), sample_colors());

    let coff = "COFF\n3 1 0\n0 0 0 0.304688 0.203125 0.144531\n1 0 0 1 1 1\n0 1 0 0 0 0\n3 0 1 2\n";
    let m = import_bytes(coff.as_bytes(), MeshFormat::Off, &opts()).unwrap();
    assert_eq!(
        m.colors.unwrap(),
        vec![[78, 52, 37], [255, 255, 255], [0, 0, 0]]
    );
}

// ---------------------------------------------------------------- glTF

fn glb(json: &str, bin: &[u8]) -> Vec<u8> {
    let mut json = json.as_bytes().to_vec();
    json.resize(json.len().next_multiple_of(4), b' ');
    let mut bin = bin.to_vec();
    bin.resize(bin.len().next_multiple_of(4), 0);
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

fn base64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            if k <= c.len() {
                s.push(T[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                s.push('=');
            }
        }
    }
    s
}

/// A quad: 4 float positions (48 bytes), 4 RGBA ubyte colours (16 bytes),
/// 6 ushort indices (12 bytes).
fn quad_bin() -> Vec<u8> {
    let mut bin = Vec::new();
    for p in [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
    ] {
        for v in p {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    for c in [
        [255u8, 0, 0, 255],
        [0, 255, 0, 255],
        [0, 0, 255, 255],
        [255, 255, 255, 128],
    ] {
        bin.extend_from_slice(&c);
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes());
    }
    bin
}

fn quad_json(buffer: &str, nodes: &str, scene_nodes: &str) -> String {
    format!(
        r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":{scene_nodes}}}],"nodes":{nodes},
        "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"COLOR_0":1}},"indices":2}}]}}],
        "buffers":[{buffer}],
        "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":16}},
                       {{"buffer":0,"byteOffset":64,"byteLength":12}}],
        "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                     {{"bufferView":1,"componentType":5121,"normalized":true,"count":4,"type":"VEC4"}},
                     {{"bufferView":2,"componentType":5123,"count":6,"type":"SCALAR"}}]}}"#
    )
}

#[test]
fn glb_with_instances_and_mirroring() {
    // Node 0: translated parent of node 1 (the mesh, scaled); node 2: mirrored instance.
    let nodes = r#"[{"translation":[10,0,0],"children":[1]},{"mesh":0,"scale":[2,2,2]},
                    {"mesh":0,"scale":[-1,1,1]}]"#;
    let json = quad_json(r#"{"byteLength":76}"#, nodes, "[0,2]");
    let m = import_bytes(&glb(&json, &quad_bin()), MeshFormat::Glb, &opts()).unwrap();
    assert_eq!(m.positions.len(), 8);
    assert_eq!(
        &m.positions[..4],
        &[
            [10.0, 0.0, 0.0],
            [12.0, 0.0, 0.0],
            [12.0, 2.0, 0.0],
            [10.0, 2.0, 0.0]
        ]
    );
    assert_eq!(
        &m.positions[4..],
        &[
            [0.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0]
        ]
    );
    // Linear 1.0 / 0.0 are sRGB 255 / 0 (alpha is ignored).
    let c = m.colors.unwrap();
    assert_eq!(
        &c[..4],
        &[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255]]
    );
    assert_eq!(
        m.triangles,
        vec![[0, 1, 2], [0, 2, 3], [4, 6, 5], [4, 7, 6]]
    );
}

#[test]
fn gltf_data_uri_and_external_bin() {
    let node = r#"[{"mesh":0}]"#;
    let uri = format!(
        r#"{{"byteLength":76,"uri":"data:application/octet-stream;base64,{}"}}"#,
        base64(&quad_bin())
    );
    let json = quad_json(&uri, node, "[0]");
    let m = import_bytes(json.as_bytes(), MeshFormat::Gltf, &opts()).unwrap();
    assert_eq!(m.positions.len(), 4);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);

    // External buffer beside the .gltf, with a space in its name.
    let json = quad_json(r#"{"byteLength":76,"uri":"quad%20data.bin"}"#, node, "[0]");
    let path = tmp("quad.gltf");
    std::fs::write(&path, &json).unwrap();
    std::fs::write(tmp("quad data.bin"), quad_bin()).unwrap();
    let m2 = import_path(&path, &opts()).unwrap();
    assert_eq!(m2, m);
    // From bytes the external buffer cannot be resolved.
    assert_err(
        json.as_bytes(),
        MeshFormat::Gltf,
        &["external file", "quad%20data.bin"],
    );
    // Paths leaving the folder are refused.
    let json = quad_json(
        r#"{"byteLength":76,"uri":"../quad%20data.bin"}"#,
        node,
        "[0]",
    );
    std::fs::write(&path, &json).unwrap();
    let e = import_path(&path, &opts()).unwrap_err().to_string();
    assert!(e.contains("inside the glTF file's folder"), "{e}");
}

#[test]
fn gltf_strip_fan_no_indices_and_no_scene() {
    let mut bin = Vec::new();
    for p in [
        [0f32, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 2.0, 0.0],
    ] {
        for v in p {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    let json = r#"{"asset":{"version":"2.0"},
        "meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":5},{"attributes":{"POSITION":0},"mode":6},
                                 {"attributes":{"POSITION":0},"mode":1}]}],
        "buffers":[{"byteLength":60}],"bufferViews":[{"buffer":0,"byteLength":60}],
        "accessors":[{"bufferView":0,"componentType":5126,"count":5,"type":"VEC3","min":[0,0,0],"max":[1,2,0]}]}"#;
    let m = import_bytes(&glb(json, &bin), MeshFormat::Glb, &opts()).unwrap();
    assert_eq!(m.positions.len(), 10);
    assert_eq!(
        m.triangles,
        vec![
            [0, 1, 2],
            [2, 1, 3],
            [2, 3, 4],
            [5, 6, 7],
            [5, 7, 8],
            [5, 8, 9]
        ]
    );
}

// ---------------------------------------------------------------- export round trips

fn bits(m: &IndexedMesh) -> Vec<[u32; 3]> {
    m.positions.iter().map(|p| p.map(f32::to_bits)).collect()
}

#[test]
fn export_then_import_is_exact() {
    let m = IndexedMesh {
        positions: (0..50)
            .map(|i| {
                let x = i as f32;
                [x.sin() * 1e3, (x * 0.37).cos() / 7.0, 1.0 / (x + 3.0)]
            })
            .collect(),
        colors: Some(
            (0..50u32)
                .map(|i| [(i * 5) as u8, (255 - i) as u8, (i * 97 % 256) as u8])
                .collect(),
        ),
        triangles: (0..48u32).map(|i| [i, i + 1, i + 2]).collect(),
    };
    for colour in [true, false] {
        let mut m = m.clone();
        if !colour {
            m.colors = None;
        }
        for (name, write) in [
            (
                "rt.ply",
                write_ply as fn(&IndexedMesh, &mut Vec<u8>) -> vitrine_codec::Result<()>,
            ),
            ("rt.obj", write_obj),
            ("rt.glb", write_glb),
        ] {
            let mut out = Vec::new();
            write(&m, &mut out).unwrap();
            let path = tmp(name);
            std::fs::write(&path, &out).unwrap();
            let back = import_path(&path, &opts()).unwrap();
            assert_eq!(bits(&back), bits(&m), "{name}");
            assert_eq!(back.colors, m.colors, "{name}");
            assert_eq!(back.triangles, m.triangles, "{name}");
        }
    }
}

// ---------------------------------------------------------------- bad inputs

#[test]
fn bad_inputs_are_clear_errors() {
    use MeshFormat::*;
    let hdr = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
               property float y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
    let mut good = hdr.as_bytes().to_vec();
    for v in [0f32, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0] {
        good.extend_from_slice(&v.to_le_bytes());
    }
    good.push(3);
    for i in [0i32, 1, 2] {
        good.extend_from_slice(&i.to_le_bytes());
    }
    import_bytes(&good, Ply, &opts()).unwrap();

    // Truncated binary PLY, at every length.
    for cut in hdr.len()..good.len() {
        let e = err_of(&good[..cut], Ply);
        assert!(
            e.contains("truncated") || e.contains("bytes remain"),
            "cut {cut}: {e}"
        );
    }
    assert_err(&good[..good.len() - 3], Ply, &["truncated", "face 0"]);
    // Huge declared counts: an error at once, without allocating.
    let t = Instant::now();
    let huge =
        "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\nproperty float x\n\
                property float y\nproperty float z\nend_header\n\0\0\0\0";
    assert_err(
        huge.as_bytes(),
        Ply,
        &["declares 4000000000 vertices", "bytes remain"],
    );
    let huge = "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
                property float z\nelement face 4000000000\nproperty list uchar int vertex_indices\n\
                end_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
    assert_err(huge.as_bytes(), Ply, &["declares 4000000000 faces"]);
    let huge = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\n\
                property float y\nproperty float z\nelement face 1\nproperty list uint int vertex_indices\nend_header\n";
    let mut b = huge.as_bytes().to_vec();
    b.extend_from_slice(&[0u8; 36]);
    b.extend_from_slice(&u32::MAX.to_le_bytes());
    b.extend_from_slice(&[0u8; 8]);
    assert_err(&b, Ply, &["truncated", "face 0"]);
    assert_err(
        b"OFF\n4000000000 4000000000 0\n",
        Off,
        &["declares 4000000000 vertices"],
    );
    assert!(t.elapsed().as_millis() < 1000);
    // Limits from the options.
    let small = ImportOptions {
        max_vertices: 2,
        max_faces: 100,
        ..ImportOptions::default()
    };
    match import_bytes(&good, Ply, &small) {
        Err(Error::Limit(m)) => assert!(m.contains("limit of 2"), "{m}"),
        other => panic!("{other:?}"),
    }
    // NaN / Inf coordinates.
    let mut nan = good.clone();
    let at = hdr.len() + 16;
    nan[at..at + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_err(&nan, Ply, &["vertex 1", "non-finite"]);
    assert_err(
        b"ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n\
          element face 0\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 inf 0\n0 1 0\n",
        Ply,
        &["vertex 1", "line 11", "non-finite"],
    );
    assert_err(
        b"v 0 0 0\nv 1 NaN 0\nv 0 1 0\nf 1 2 3\n",
        Obj,
        &["line 2", "vertex 2", "non-finite"],
    );
    assert_err(
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 1e999\n3 0 1 2\n",
        Off,
        &["line 5", "non-finite"],
    );
    // Index out of range.
    let mut oob = good.clone();
    let n = oob.len();
    oob[n - 4..].copy_from_slice(&3i32.to_le_bytes());
    assert_err(&oob, Ply, &["face 0", "vertex index 3", "out of range"]);
    let mut neg = good.clone();
    neg[n - 4..].copy_from_slice(&(-1i32).to_le_bytes());
    assert_err(&neg, Ply, &["face 0", "vertex index -1"]);
    assert_err(
        b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n",
        Obj,
        &["line 4", "face 1", "vertex index 4"],
    );
    assert_err(
        b"v 0 0 0\nv 1 0 0\n\nf 1 2 -3\n",
        Obj,
        &["line 4", "relative index -3", "before the first vertex"],
    );
    assert_err(
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 5\n",
        Off,
        &["line 6", "vertex index 5"],
    );
    // Empty inputs and garbage.
    for f in [Ply, Obj, Off, Gltf, Glb] {
        let e = err_of(b"", f);
        assert!(!e.is_empty());
        let garbage: Vec<u8> = (0..2000u32)
            .map(|i| (i.wrapping_mul(2654435761) >> 13) as u8)
            .collect();
        let e = err_of(&garbage, f);
        assert!(!e.is_empty());
    }
    assert_err(b"", Ply, &["not a PLY file"]);
    assert_err(b"", Obj, &["no vertices"]);
    assert_err(b"", Off, &["empty"]);
    assert_err(b"v 0 0 0\nv 1 0 0\nv 0 1 0\n", Obj, &["no faces"]);
    assert_err(b"OFF\n0 0 0\n", Off, &["no vertices"]);
    // glTF that lies about its buffers.
    let json = quad_json(r#"{"byteLength":76}"#, r#"[{"mesh":0}]"#, "[0]");
    let short = glb(&json, &quad_bin()[..40]);
    assert_err(&short, Glb, &["truncated", "buffer 0"]);
    let bad_acc = json.replace(r#""count":6"#, r#""count":60"#);
    assert_err(
        &glb(&bad_acc, &quad_bin()),
        Glb,
        &["accessor 2", "past the end"],
    );
    let bad_idx = {
        let mut b = quad_bin();
        b[64..66].copy_from_slice(&9u16.to_le_bytes());
        b
    };
    assert_err(
        &glb(&json, &bad_idx),
        Glb,
        &["mesh 0 primitive 0", "index 9", "out of range"],
    );
    assert_err(b"{\"asset\":", Gltf, &["glTF"]);
    let cyclic = quad_json(
        r#"{"byteLength":76}"#,
        r#"[{"children":[1]},{"children":[0],"mesh":0}]"#,
        "[0]",
    );
    let e = err_of(&glb(&cyclic, &quad_bin()), Glb);
    assert!(!e.is_empty());
}

#[test]
fn import_path_sniffs_unknown_extensions() {
    let p = tmp("mesh.data");
    std::fs::write(&p, sample_ply(Enc::Le)).unwrap();
    assert_eq!(
        import_path(&p, &opts()).unwrap().triangles,
        sample_triangles()
    );
    std::fs::write(&p, b"\x01\x02\x03").unwrap();
    let e = import_path(&p, &opts()).unwrap_err().to_string();
    assert!(e.contains("unknown mesh format"), "{e}");
    let e = import_path(&tmp("missing.ply"), &opts())
        .unwrap_err()
        .to_string();
    assert!(e.contains("missing.ply"), "{e}");
}

// ---------------------------------------------------------------- repair

fn mesh(positions: Vec<[f32; 3]>, triangles: Vec<[u32; 3]>) -> IndexedMesh {
    IndexedMesh {
        positions,
        colors: None,
        triangles,
    }
}

fn repaired(m: IndexedMesh) -> (IndexedMesh, RepairReport) {
    let (out, report) = prepare(m, &RepairOptions::default()).unwrap();
    check_manifold(&out).unwrap();
    (out, report)
}

fn strict() -> RepairOptions {
    RepairOptions {
        weld: true,
        split_non_manifold: false,
    }
}

#[test]
fn repair_bow_tie_vertex_is_split() {
    // Two triangles touching at vertex 0 only.
    let m = mesh(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-1.0, 0.0, 0.0],
            [-1.0, -1.0, 0.0],
        ],
        vec![[0, 1, 2], [0, 3, 4]],
    );
    assert!(check_manifold(&m)
        .unwrap_err()
        .to_string()
        .contains("vertex 0"));
    let e = prepare(m.clone(), &strict()).unwrap_err().to_string();
    assert!(e.contains("non-manifold vertex 0"), "{e}");
    let (out, r) = repaired(m);
    assert_eq!(r.non_manifold_vertices, 1);
    assert_eq!(r.split_vertices, 1);
    assert_eq!(out.positions.len(), 6);
    assert_eq!(out.positions[5], [0.0, 0.0, 0.0]);
    assert_eq!(out.triangles, vec![[0, 1, 2], [5, 3, 4]]);
}

#[test]
fn repair_three_faces_on_an_edge() {
    // A "book" of three pages on edge 0–1.
    let m = mesh(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.5, 1.0, 0.0],
            [0.5, -1.0, 0.0],
            [0.5, 0.0, 1.0],
        ],
        vec![[0, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    let e = prepare(m.clone(), &strict()).unwrap_err().to_string();
    assert!(
        e.contains("non-manifold edge between vertices 0 and 1"),
        "{e}"
    );
    assert!(e.contains("3 faces"), "{e}");
    let (out, r) = repaired(m);
    assert_eq!(r.non_manifold_edges, 1);
    assert_eq!(r.split_vertices, 2);
    // The first pair keeps the edge; the third page gets its own copy.
    assert_eq!(&out.triangles[..2], &[[0, 1, 2], [1, 0, 3]]);
    assert_eq!(out.triangles[2], [5, 6, 4]);
}

#[test]
fn repair_edge_fan_in_one_vertex_fan() {
    // Four faces on edge 0–1 that are also connected around both ends,
    // so splitting fans alone cannot separate them.
    let p = vec![
        [0.0, 0.0, 0.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 0.5],
        [0.0, 1.0, 0.5],
        [-1.0, 0.0, 0.5],
        [0.0, -1.0, 0.5],
    ];
    let t = vec![
        [0, 1, 2],
        [1, 0, 3],
        [0, 1, 4],
        [1, 0, 5],
        [0, 2, 3],
        [0, 4, 5],
        [1, 3, 2],
        [1, 5, 4],
    ];
    let (_, r) = repaired(mesh(p, t));
    assert!(r.non_manifold_edges >= 1, "{r:?}");
}

#[test]
fn repair_drops_duplicate_and_degenerate_faces() {
    let m = mesh(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [2.0, 2.0, 2.0],
            [1.0, 0.0, 0.0],
            [5.0; 3],
        ],
        vec![
            [0, 1, 2],
            [0, 2, 1], // duplicate, other orientation
            [1, 2, 0], // duplicate, rotated
            [0, 1, 4], // degenerate after welding 4 into 1
            [3, 3, 2], // degenerate
        ],
    );
    let (out, r) = repaired(m);
    assert_eq!(r.duplicate_faces, 2);
    assert_eq!(r.degenerate_faces, 2);
    assert_eq!(r.welded_vertices, 1);
    assert_eq!(r.unreferenced_vertices, 2); // vertices 3 and 5
    assert_eq!(
        out.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    );
    assert_eq!(out.triangles, vec![[0, 1, 2]]);
}

#[test]
fn repair_keeps_zero_area_faces() {
    let m = mesh(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]],
        vec![[0, 1, 2]],
    );
    let (out, r) = repaired(m.clone());
    assert_eq!(out, m);
    assert_eq!(r, RepairReport::default());
}

/// A closed octahedron.
fn octahedron() -> IndexedMesh {
    mesh(
        vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        vec![
            [0, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
    )
}

#[test]
fn repair_fixes_inconsistent_orientation() {
    check_manifold(&octahedron()).unwrap();
    let mut m = octahedron();
    m.triangles[1].swap(0, 1);
    m.triangles[6].swap(1, 2);
    assert!(check_manifold(&m).is_err());
    // Orientation alone is fixed even when splitting is refused.
    let (out, r) = prepare(m, &strict()).unwrap();
    check_manifold(&out).unwrap();
    assert_eq!(r.flipped_faces, 2);
    assert_eq!(r.non_manifold_edges, 0);
    assert_eq!(out.triangles[0], [0, 2, 4]);
    // Majority wins: flipping 6 of 8 faces keeps the 6.
    let mut m = octahedron();
    for t in &mut m.triangles[..6] {
        t.swap(1, 2);
    }
    let (out, r) = repaired(m);
    assert_eq!(r.flipped_faces, 2);
    assert_eq!(out.triangles[0], [0, 4, 2]);
}

#[test]
fn repair_welds_seams_and_keeps_first_colour() {
    // A quad split along its diagonal, with the diagonal's vertices doubled
    // (as a UV seam), and -0.0 vs 0.0.
    let m = IndexedMesh {
        positions: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [-0.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        colors: Some(vec![
            [1, 1, 1],
            [2, 2, 2],
            [3, 3, 3],
            [4, 4, 4],
            [5, 5, 5],
            [6, 6, 6],
        ]),
        triangles: vec![[0, 1, 2], [3, 4, 5]],
    };
    let (out, r) = repaired(m.clone());
    assert_eq!(r.welded_vertices, 2);
    assert_eq!(out.positions.len(), 4);
    assert_eq!(
        out.colors.unwrap(),
        vec![[1, 1, 1], [2, 2, 2], [3, 3, 3], [6, 6, 6]]
    );
    assert_eq!(out.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    // Without welding, nothing changes.
    let (out, r) = prepare(
        m.clone(),
        &RepairOptions {
            weld: false,
            split_non_manifold: true,
        },
    )
    .unwrap();
    assert_eq!(out, m);
    assert_eq!(r, RepairReport::default());
}

#[test]
fn repair_refuses_bad_input() {
    let m = mesh(
        vec![[0.0, f32::NAN, 0.0], [1.0; 3], [2.0; 3]],
        vec![[0, 1, 2]],
    );
    let e = prepare(m, &RepairOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("vertex 0") && e.contains("non-finite"), "{e}");
    let m = mesh(vec![[0.0; 3], [1.0; 3], [2.0; 3]], vec![[0, 1, 3]]);
    assert!(prepare(m, &RepairOptions::default()).is_err());
    let m = mesh(vec![[0.0; 3], [0.0; 3], [0.0; 3]], vec![[0, 1, 2]]);
    let e = prepare(m, &RepairOptions::default())
        .unwrap_err()
        .to_string();
    assert!(e.contains("no triangles left"), "{e}");
}

#[test]
fn repair_is_fast_on_large_meshes() {
    // A 1000×1000 grid (1 M vertices, 2 M triangles) with every vertex
    // doubled for seams: welding, orientation and fan checks at scale.
    let n = 1000u32;
    let mut positions = Vec::with_capacity(2 * ((n + 1) * (n + 1)) as usize);
    for y in 0..=n {
        for x in 0..=n {
            positions.push([x as f32, y as f32, ((x * y) % 7) as f32]);
        }
    }
    let copies = positions.len() as u32;
    positions.extend_from_within(..);
    let id = |x: u32, y: u32| y * (n + 1) + x;
    let mut triangles = Vec::with_capacity(2 * (n * n) as usize);
    for y in 0..n {
        for x in 0..n {
            let o = if (x + y) % 2 == 0 { 0 } else { copies };
            triangles.push([id(x, y) + o, id(x + 1, y) + o, id(x + 1, y + 1) + o]);
            triangles.push([id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
        }
    }
    let t = Instant::now();
    let (out, r) = prepare(mesh(positions, triangles), &RepairOptions::default()).unwrap();
    let took = t.elapsed();
    eprintln!("prepare on 2 M triangles: {took:?} ({r})");
    assert_eq!(r.welded_vertices, copies as usize);
    assert_eq!(out.positions.len(), copies as usize);
    check_manifold(&out).unwrap();
}

fn soup() -> impl Strategy<Value = IndexedMesh> {
    (3usize..24).prop_flat_map(|nv| {
        (
            proptest::collection::vec((0u8..4, 0u8..4, 0u8..3), nv),
            proptest::collection::vec((0..nv as u32, 0..nv as u32, 0..nv as u32), 1..60),
            any::<bool>(),
        )
            .prop_map(|(p, t, colour)| IndexedMesh {
                colors: colour.then(|| (0..p.len()).map(|i| [i as u8; 3]).collect()),
                positions: p
                    .into_iter()
                    .map(|(x, y, z)| [x as f32, y as f32, z as f32])
                    .collect(),
                triangles: t.into_iter().map(|(a, b, c)| [a, b, c]).collect(),
            })
    })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(600))]
    #[test]
    fn prop_prepare_yields_manifold(m in soup(), weld in any::<bool>()) {
        let opts = RepairOptions { weld, split_non_manifold: true };
        match prepare(m.clone(), &opts) {
            Ok((out, r)) => {
                prop_assert!(check_manifold(&out).is_ok(), "{:?}\n{:?}\n{:?}", check_manifold(&out), m, out);
                prop_assert_eq!(out.colors.is_some(), m.colors.is_some());
                prop_assert_eq!(
                    out.triangles.len() + r.degenerate_faces + r.duplicate_faces,
                    m.triangles.len()
                );
            }
            Err(e) => prop_assert!(e.to_string().contains("no triangles left"), "{}", e),
        }
        // Strict mode either accepts the same mesh or names the problem.
        if let Err(e) = prepare(m, &RepairOptions { weld, split_non_manifold: false }) {
            let s = e.to_string();
            prop_assert!(s.contains("non-manifold") || s.contains("no triangles left"), "{}", s);
        }
    }

    #[test]
    fn prop_importers_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400), f in 0usize..5) {
        let format = [MeshFormat::Ply, MeshFormat::Obj, MeshFormat::Off, MeshFormat::Gltf, MeshFormat::Glb][f];
        let _ = import_bytes(&bytes, format, &opts());
    }

    #[test]
    fn prop_mutated_ply_never_panics(cuts in proptest::collection::vec((0usize..600, any::<u8>()), 1..4), enc in 0usize..3) {
        let mut b = sample_ply([Enc::Ascii, Enc::Le, Enc::Be][enc]);
        for (at, v) in cuts {
            let n = b.len();
            b[at % n] = v;
        }
        let _ = import_bytes(&b, MeshFormat::Ply, &opts());
    }
}

// ---------------------------------------------------------------- real scans

#[test]
fn shared_meshes_import_and_repair() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes");
    if !dir.is_dir() {
        eprintln!(
            "note: {} is absent; skipping the real-scan test",
            dir.display()
        );
        return;
    }
    let expected: &[(&str, usize, Option<usize>)] = &[
        ("bunny.ply", 35_947, Some(69_451)),
        ("lucy-100k.ply", 49_987, Some(99_970)),
        ("horse.ply", 48_485, Some(96_966)),
        ("armadillo-80k.obj", 40_002, Some(80_000)),
        ("igea.ply", 134_345, Some(268_686)),
        ("nefertiti-100k.obj", 49_971, Some(99_938)),
        ("nefertiti-rgb-10k.off", 10_013, Some(20_022)),
        ("gargoyle.ply", 25_002, Some(50_000)),
        ("laurana.ply", 25_160, Some(50_000)),
        ("demosthenes.obj", 8_394, Some(16_719)),
        ("suzanne.obj", 507, Some(968)),
        (
            "mask/mask-gltf-2.0_separated-valid.gltf",
            62_383,
            Some(100_000),
        ),
        ("banana/textured_simple_reoriented.obj", 7_866, Some(15_728)),
    ];
    for &(name, vertices, triangles) in expected {
        let path = dir.join(name);
        if !path.exists() {
            eprintln!("note: {name} is absent; skipped");
            continue;
        }
        let t = Instant::now();
        let m = import_path(&path, &opts()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let t_import = t.elapsed();
        assert_eq!(m.positions.len(), vertices, "{name}");
        if let Some(tris) = triangles {
            assert_eq!(m.triangles.len(), tris, "{name}");
        }
        let coloured = matches!(
            name,
            "nefertiti-rgb-10k.off" | "gargoyle.ply" | "laurana.ply" | "horse.ply"
        );
        assert_eq!(m.colors.is_some(), coloured, "{name}");
        let t = Instant::now();
        let (out, report) =
            prepare(m, &RepairOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let t_repair = t.elapsed();
        check_manifold(&out).unwrap_or_else(|e| panic!("{name}: {e}"));
        eprintln!(
            "{name}: {vertices} -> {} vertices, {} triangles; import {t_import:.0?}, repair {t_repair:.0?}; {report:?}",
            out.positions.len(),
            out.triangles.len()
        );
    }
}

// ---------------------------------------------------------------- textures

mod textured {
    use super::*;
    use image::{ImageBuffer, Luma, Rgb, Rgba};
    use vitrine_mesh::import::{
        import_path_textured, import_path_textured_with, Imported, TextureOptions,
    };

    /// A fresh folder for one test's files.
    fn folder(name: &str) -> PathBuf {
        let dir = tmp("textured").join(name);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    /// 4 × 2 RGBA image: pixel (x, y) = (60x, 100y, 7, 200).
    fn rgba_png() -> Vec<u8> {
        let img = ImageBuffer::from_fn(4, 2, |x, y| Rgba([60 * x as u8, 100 * y as u8, 7, 200]));
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    }

    /// 3 × 5 16-bit grey image: pixel (x, y) = 257 · (10x + 40y).
    fn grey16_png() -> Vec<u8> {
        let img = ImageBuffer::from_fn(3, 5, |x, y| Luma([257 * (10 * x + 40 * y) as u16]));
        let mut out = std::io::Cursor::new(Vec::new());
        img.write_to(&mut out, image::ImageFormat::Png).unwrap();
        out.into_inner()
    }

    fn crc32(data: &[u8]) -> u32 {
        let mut c = !0u32;
        for &b in data {
            c ^= b as u32;
            for _ in 0..8 {
                c = if c & 1 != 0 {
                    0xEDB8_8320 ^ (c >> 1)
                } else {
                    c >> 1
                };
            }
        }
        !c
    }

    fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
        out.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let start = out.len();
        out.extend_from_slice(kind);
        out.extend_from_slice(data);
        let crc = crc32(&out[start..]);
        out.extend_from_slice(&crc.to_be_bytes());
    }

    /// A valid-looking PNG that claims `w` × `h` RGB pixels, with a tiny IDAT.
    fn bomb_png(w: u32, h: u32) -> Vec<u8> {
        let mut out = b"\x89PNG\r\n\x1a\n".to_vec();
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&w.to_be_bytes());
        ihdr.extend_from_slice(&h.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]);
        chunk(&mut out, b"IHDR", &ihdr);
        chunk(
            &mut out,
            b"IDAT",
            &[0x78, 0x9c, 0x03, 0x00, 0x00, 0x00, 0x00, 0x01],
        );
        chunk(&mut out, b"IEND", &[]);
        out
    }

    /// Two triangles over a unit quad whose second triangle has its own
    /// `vt` on the shared vertex 3 (a UV seam).
    const QUAD_OBJ: &str = "mtllib  my materials.mtl\n\
        v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
        vt 0 0\nvt 1 0\nvt 1 1\nvt 0.25 0.75\nvt 0.5 0.5\n\
        vn 0 0 1\nusemtl skin\n\
        f 1/1/1 2/2/1 3/3/1\nf 1/1/1 3/5/1 4/4/1\n";

    fn write(dir: &Path, name: &str, data: impl AsRef<[u8]>) {
        if let Some(parent) = dir.join(name).parent() {
            std::fs::create_dir_all(parent).unwrap();
        }
        std::fs::write(dir.join(name), data).unwrap();
    }

    fn textured(path: &Path) -> Imported {
        import_path_textured(path, &opts()).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
    }

    #[test]
    fn obj_mtl_png() {
        let dir = folder("obj");
        write(&dir, "quad.obj", QUAD_OBJ);
        write(
            &dir,
            "my materials.mtl",
            "newmtl other\nmap_Kd nothere.png\n\nnewmtl skin\nKd 1 1 1\n\
             map_Kd -s 1 1 1 -clamp on \"tex dir/skin tex.png\"\n",
        );
        write(&dir, "tex dir/skin tex.png", rgba_png());
        let path = dir.join("quad.obj");
        let got = textured(&path);
        assert!(got.warnings.is_empty(), "{:?}", got.warnings);
        // The mesh is exactly what import_path gives.
        let plain = import_path(&path, &opts()).unwrap();
        assert_eq!(got.mesh.positions, plain.positions);
        assert_eq!(got.mesh.triangles, plain.triangles);
        let t = got.texture.expect("texture");
        assert_eq!(t.triangles.len(), 2);
        // Vertex 1 and 3 are shared with the same vt; vertex 3 also has a second vt.
        assert_eq!(t.positions.len(), 5);
        assert_eq!(t.uvs.len(), 5);
        let uv_of =
            |p: [f32; 3], uv: [f32; 2]| (0..5).any(|i| t.positions[i] == p && t.uvs[i] == uv);
        assert!(uv_of([0.0, 0.0, 0.0], [0.0, 1.0]), "{:?}", t.uvs); // v flipped
        assert!(uv_of([0.0, 1.0, 0.0], [0.25, 0.25]), "{:?}", t.uvs);
        assert!(uv_of([1.0, 1.0, 0.0], [1.0, 0.0]));
        assert!(uv_of([1.0, 1.0, 0.0], [0.5, 0.5]));
        for tri in &t.triangles {
            assert!(tri.iter().all(|&i| (i as usize) < 5));
        }
        assert_eq!(t.image.dimensions(), (4, 2));
        assert_eq!(*t.image.get_pixel(3, 1), Rgb([180, 100, 7])); // alpha dropped
    }

    #[test]
    fn obj_without_material_or_uvs_has_no_texture() {
        let dir = folder("obj-plain");
        write(&dir, "a.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
        let got = textured(&dir.join("a.obj"));
        assert!(got.texture.is_none() && got.warnings.is_empty());
        // A map_Kd but faces without vt: a warning.
        write(&dir, "b.mtl", "newmtl m\nmap_Kd t.png\n");
        write(&dir, "t.png", rgba_png());
        write(
            &dir,
            "b.obj",
            "mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n",
        );
        let got = textured(&dir.join("b.obj"));
        assert!(got.texture.is_none());
        assert!(
            got.warnings[0].contains("no texture coordinates"),
            "{:?}",
            got.warnings
        );
        // Bad vt data costs the texture, not the geometry: a warning with its line.
        for (obj, needles) in [
            (
                "vt 0 0\nusemtl m\nf 1/1 2/1 3/4\n",
                ["line 7", "texture coordinate index 4 is out of range"],
            ),
            (
                "vt 0 zero\nusemtl m\nf 1/1 2/1 3/1\n",
                ["line 5", "bad number \"zero\""],
            ),
            (
                "vt 0 0\nusemtl m\nf 1/1 2/-2 3/1\n",
                ["line 7", "reaches before the first"],
            ),
        ] {
            let obj = format!("mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\n{obj}");
            write(&dir, "c.obj", &obj);
            let got = textured(&dir.join("c.obj"));
            assert!(got.texture.is_none(), "{obj}");
            assert_eq!(got.mesh.triangles, vec![[0, 1, 2]]);
            assert_eq!(got.warnings.len(), 1, "{:?}", got.warnings);
            for n in needles {
                assert!(got.warnings[0].contains(n), "{n}: {:?}", got.warnings);
            }
        }
    }

    #[test]
    fn obj_missing_texture_or_library_is_a_warning() {
        let dir = folder("obj-missing");
        write(&dir, "quad.obj", QUAD_OBJ);
        let path = dir.join("quad.obj");
        let got = textured(&path);
        assert!(got.texture.is_none());
        assert!(got.warnings[0].contains("not found"), "{:?}", got.warnings);
        write(&dir, "my materials.mtl", "newmtl skin\nmap_Kd skin.jpg\n");
        let got = textured(&path);
        assert!(got.texture.is_none());
        assert!(got.warnings[0].contains("not found"), "{:?}", got.warnings);
        assert!(got.warnings[0].contains("skin.jpg"), "{:?}", got.warnings);
        assert_eq!(got.mesh.triangles.len(), 2);
    }

    #[test]
    fn obj_reference_outside_the_folder_is_not_followed() {
        let dir = folder("obj-escape");
        // A texture outside the model's folder that must not be read…
        write(&dir, "secret.png", rgba_png());
        let model = dir.join("model");
        write(&model, "quad.obj", QUAD_OBJ);
        write(
            &model,
            "my materials.mtl",
            "newmtl skin\nmap_Kd ../secret.png\n",
        );
        let got = textured(&model.join("quad.obj"));
        assert!(got.texture.is_none());
        assert!(
            got.warnings.iter().any(|w| w.contains("outside")),
            "{:?}",
            got.warnings
        );
        // …but an exporter's absolute path finds the file of that name beside the OBJ.
        write(
            &model,
            "my materials.mtl",
            "newmtl skin\nmap_Kd C:\\Users\\me\\scans\\skin.png\n",
        );
        write(&model, "skin.png", rgba_png());
        let got = textured(&model.join("quad.obj"));
        assert_eq!(got.texture.expect("texture").image.dimensions(), (4, 2));
        assert!(
            got.warnings[0].contains("beside the model"),
            "{:?}",
            got.warnings
        );
    }

    /// A textured quad with TEXCOORD_1 (used by the material) as normalized
    /// ushort, after 4 float positions and 6 ushort indices.
    fn textured_quad(image: &str, extra_images: &str) -> (String, Vec<u8>) {
        let mut bin = Vec::new();
        for p in [
            [0f32, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ] {
            for v in p {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend_from_slice(&i.to_le_bytes());
        }
        // TEXCOORD_0: garbage floats; TEXCOORD_1: the real one.
        for _ in 0..8 {
            bin.extend_from_slice(&9f32.to_le_bytes());
        }
        for uv in [[0u16, 65535], [65535, 65535], [65535, 0], [0, 0]] {
            for v in uv {
                bin.extend_from_slice(&v.to_le_bytes());
            }
        }
        let json = format!(
            r#"{{"asset":{{"version":"2.0"}},"scene":0,"scenes":[{{"nodes":[0]}}],
            "nodes":[{{"mesh":0,"translation":[0,0,5]}}],
            "meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"TEXCOORD_0":2,"TEXCOORD_1":3}},
                "indices":1,"material":0}}]}}],
            "materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0,"texCoord":1}}}}}}],
            "textures":[{{"source":0}}],
            "images":[{image}{extra_images}],
            "buffers":[BUFFER],
            "bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":48}},{{"buffer":0,"byteOffset":48,"byteLength":12}},
                           {{"buffer":0,"byteOffset":60,"byteLength":32}},{{"buffer":0,"byteOffset":92,"byteLength":16}}
                           IMAGEVIEW],
            "accessors":[{{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0]}},
                         {{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}},
                         {{"bufferView":2,"componentType":5126,"count":4,"type":"VEC2"}},
                         {{"bufferView":3,"componentType":5123,"normalized":true,"count":4,"type":"VEC2"}}]}}"#
        );
        (json, bin)
    }

    fn check_quad(got: &Imported, size: (u32, u32)) -> image::RgbImage {
        assert!(got.warnings.is_empty(), "{:?}", got.warnings);
        let t = got.texture.clone().expect("texture");
        assert_eq!(t.positions, got.mesh.positions);
        assert_eq!(t.positions[2], [1.0, 1.0, 5.0]);
        assert_eq!(t.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        assert_eq!(t.uvs, vec![[0.0, 1.0], [1.0, 1.0], [1.0, 0.0], [0.0, 0.0]]);
        assert_eq!(t.image.dimensions(), size);
        t.image
    }

    #[test]
    fn glb_image_in_buffer_view() {
        let dir = folder("glb");
        let png = grey16_png();
        let (json, mut bin) = textured_quad(r#"{"bufferView":4,"mimeType":"image/png"}"#, "");
        let json = json
            .replace(
                "BUFFER",
                &format!(r#"{{"byteLength":{}}}"#, 108 + png.len()),
            )
            .replace(
                "IMAGEVIEW",
                &format!(
                    r#",{{"buffer":0,"byteOffset":108,"byteLength":{}}}"#,
                    png.len()
                ),
            );
        bin.extend_from_slice(&png);
        write(&dir, "quad.glb", glb(&json, &bin));
        let got = textured(&dir.join("quad.glb"));
        let image = check_quad(&got, (3, 5));
        // 16-bit grey → 8-bit RGB.
        assert_eq!(*image.get_pixel(2, 4), Rgb([180, 180, 180]));
        assert_eq!(
            got.mesh.positions,
            import_path(&dir.join("quad.glb"), &opts())
                .unwrap()
                .positions
        );
    }

    fn gltf_with(dir: &Path, image: &str) -> PathBuf {
        let (json, bin) = textured_quad(image, "");
        let json = json
            .replace(
                "BUFFER",
                &format!(
                    r#"{{"byteLength":108,"uri":"data:application/octet-stream;base64,{}"}}"#,
                    base64(&bin)
                ),
            )
            .replace("IMAGEVIEW", "");
        write(dir, "quad.gltf", json);
        dir.join("quad.gltf")
    }

    #[test]
    fn gltf_image_file_and_data_uri() {
        let dir = folder("gltf");
        write(&dir, "maps/skin tex.png", rgba_png());
        let got = textured(&gltf_with(&dir, r#"{"uri":"maps/skin%20tex.png"}"#));
        let image = check_quad(&got, (4, 2));
        assert_eq!(*image.get_pixel(1, 1), Rgb([60, 100, 7]));
        let uri = format!(
            r#"{{"uri":"data:image/png;base64,{}"}}"#,
            base64(&rgba_png())
        );
        let got = textured(&gltf_with(&dir, &uri));
        check_quad(&got, (4, 2));
        // Without a texture: None, no warning.
        let (json, bin) = textured_quad(r#"{"uri":"x.png"}"#, "");
        let json = json
            .replace(r#","material":0"#, "")
            .replace(
                "BUFFER",
                &format!(
                    r#"{{"byteLength":108,"uri":"data:;base64,{}"}}"#,
                    base64(&bin)
                ),
            )
            .replace("IMAGEVIEW", "");
        write(&dir, "plain.gltf", json);
        let got = textured(&dir.join("plain.gltf"));
        assert!(
            got.texture.is_none() && got.warnings.is_empty(),
            "{:?}",
            got.warnings
        );
    }

    #[test]
    fn gltf_missing_image_is_a_warning() {
        let dir = folder("gltf-missing");
        let got = textured(&gltf_with(&dir, r#"{"uri":"gone.jpg"}"#));
        assert!(got.texture.is_none());
        assert!(got.warnings[0].contains("not found"), "{:?}", got.warnings);
        assert_eq!(got.mesh.triangles.len(), 2);
    }

    #[test]
    fn gltf_bad_texture_coordinates_are_warnings() {
        let dir = folder("gltf-bad-uv");
        write(&dir, "t.png", rgba_png());
        let path = gltf_with(&dir, r#"{"uri":"t.png"}"#);
        let good = std::fs::read_to_string(&path).unwrap();
        for (from, to, needle) in [
            (
                r#""normalized":true,"count":4"#,
                r#""normalized":true,"count":3"#,
                "TEXCOORD_1 must be VEC2 with one value per vertex",
            ),
            (r#""texCoord":1"#, r#""texCoord":2"#, "not its TEXCOORD"),
        ] {
            assert!(good.contains(from));
            std::fs::write(&path, good.replace(from, to)).unwrap();
            let got = textured(&path);
            assert!(got.texture.is_none());
            assert_eq!(got.mesh.triangles.len(), 2);
            assert!(got.warnings[0].contains(needle), "{:?}", got.warnings);
        }
    }

    #[test]
    fn gltf_traversal_uri_is_refused() {
        let dir = folder("gltf-escape");
        write(&dir, "secret.png", rgba_png());
        let model = dir.join("model");
        std::fs::create_dir_all(&model).unwrap();
        for uri in [
            "../secret.png",
            "sub/%2e%2e/%2e%2e/secret.png",
            "/etc/passwd",
            "file:///etc/passwd",
        ] {
            let path = gltf_with(&model, &format!(r#"{{"uri":"{uri}"}}"#));
            match import_path_textured(&path, &opts()) {
                Err(e @ Error::Input { .. }) => {
                    let e = e.to_string();
                    assert!(e.contains("image 0") && e.contains(uri), "{e}");
                }
                other => panic!("{uri}: {other:?}"),
            }
        }
    }

    #[test]
    fn bomb_and_corrupt_images_are_refused() {
        let dir = folder("bomb");
        write(&dir, "quad.obj", QUAD_OBJ);
        write(&dir, "my materials.mtl", "newmtl skin\nmap_Kd skin.png\n");
        let path = dir.join("quad.obj");
        // A header claiming 10^10 pixels: refused from the header, at once.
        write(&dir, "skin.png", bomb_png(100_000, 100_000));
        let t = Instant::now();
        match import_path_textured(&path, &opts()) {
            Err(Error::Limit(m)) => assert!(m.contains("100000 × 100000"), "{m}"),
            other => panic!("{other:?}"),
        }
        assert!(t.elapsed().as_millis() < 500, "{:?}", t.elapsed());
        // Within the pixel budget but a lie about its data: a decoding error.
        write(&dir, "skin.png", bomb_png(300, 200));
        match import_path_textured(&path, &opts()) {
            Err(e @ Error::Input { .. }) => assert!(e.to_string().contains("skin.png"), "{e}"),
            other => panic!("{other:?}"),
        }
        // A smaller budget refuses a real image.
        write(&dir, "skin.png", rgba_png());
        let small = TextureOptions {
            max_texture_pixels: 7,
        };
        match import_path_textured_with(&path, &opts(), &small) {
            Err(Error::Limit(m)) => assert!(m.contains("4 × 2 = 8 pixels"), "{m}"),
            other => panic!("{other:?}"),
        }
        // Truncated and garbage images.
        let png = rgba_png();
        write(&dir, "skin.png", &png[..png.len() / 2]);
        assert!(matches!(
            import_path_textured(&path, &opts()),
            Err(Error::Input { .. })
        ));
        write(&dir, "skin.png", b"GIF89a this is not a png");
        let got = textured(&path);
        assert!(got.texture.is_none());
        assert!(
            got.warnings[0].contains("only PNG, JPEG, TGA and PCX"),
            "{:?}",
            got.warnings
        );
        write(&dir, "skin.png", b"\xff\xd8\xff\xe0 not really a jpeg");
        assert!(import_path_textured(&path, &opts()).is_err());
        // The same bomb inside a GLB.
        let png = bomb_png(65_536, 65_536);
        let (json, mut bin) = textured_quad(r#"{"bufferView":4,"mimeType":"image/png"}"#, "");
        let json = json
            .replace(
                "BUFFER",
                &format!(r#"{{"byteLength":{}}}"#, 108 + png.len()),
            )
            .replace(
                "IMAGEVIEW",
                &format!(
                    r#",{{"buffer":0,"byteOffset":108,"byteLength":{}}}"#,
                    png.len()
                ),
            );
        bin.extend_from_slice(&png);
        write(&dir, "bomb.glb", glb(&json, &bin));
        assert!(matches!(
            import_path_textured(&dir.join("bomb.glb"), &opts()),
            Err(Error::Limit(_))
        ));
    }

    #[test]
    fn other_formats_have_no_texture() {
        let dir = folder("ply");
        write(&dir, "a.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
        let got = textured(&dir.join("a.off"));
        assert!(got.texture.is_none() && got.warnings.is_empty());
        assert_eq!(got.mesh.triangles.len(), 1);
    }

    #[test]
    fn shared_textured_scans() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../../shared/data/meshes");
        let scans = [
            ("mask/mask-gltf-2.0_separated-valid.gltf", (4096, 4096)),
            ("banana/textured_simple_reoriented.obj", (0, 0)),
        ];
        for (name, size) in scans {
            let path = dir.join(name);
            if !path.exists() {
                eprintln!("note: {} is absent; skipped", path.display());
                continue;
            }
            let t = Instant::now();
            let plain = import_path(&path, &opts()).unwrap();
            let geometry = t.elapsed();
            let t = Instant::now();
            let got = textured(&path);
            let elapsed = t.elapsed();
            assert_eq!(got.mesh.positions, plain.positions, "{name}");
            assert_eq!(got.mesh.triangles, plain.triangles, "{name}");
            assert!(got.warnings.is_empty(), "{name}: {:?}", got.warnings);
            let tex = got
                .texture
                .as_ref()
                .unwrap_or_else(|| panic!("{name}: no texture"));
            if size != (0, 0) {
                assert_eq!(tex.image.dimensions(), size, "{name}");
            }
            assert_eq!(tex.uvs.len(), tex.positions.len());
            assert!(tex.uvs.iter().flatten().all(|v| v.is_finite()));
            let n = tex.positions.len() as u32;
            assert!(tex.triangles.iter().flatten().all(|&i| i < n));
            assert_eq!(tex.triangles.len(), got.mesh.triangles.len(), "{name}");
            let inside = tex
                .uvs
                .iter()
                .filter(|uv| uv.iter().all(|&v| (-1e-3..=1.001).contains(&v)))
                .count();
            let (w, h) = tex.image.dimensions();
            let mean = tex.image.pixels().fold([0u64; 3], |m, p| {
                [m[0] + p[0] as u64, m[1] + p[1] as u64, m[2] + p[2] as u64]
            });
            let px = (w as u64 * h as u64).max(1);
            // Colour at the vertices' UVs (nearest texel): a wrong v
            // convention samples the atlas's empty background instead.
            let at_uvs = |flip: bool| {
                let sum = tex.uvs.iter().fold([0u64; 3], |m, &[u, v]| {
                    let v = if flip { 1.0 - v } else { v };
                    let x = ((u * w as f32) as u32).min(w - 1);
                    let y = ((v * h as f32) as u32).min(h - 1);
                    let p = tex.image.get_pixel(x, y);
                    [m[0] + p[0] as u64, m[1] + p[1] as u64, m[2] + p[2] as u64]
                });
                sum.map(|c| c / tex.uvs.len().max(1) as u64)
            };
            let (sampled, flipped) = (at_uvs(false), at_uvs(true));
            let luma = |c: [u64; 3]| c[0] + c[1] + c[2];
            // The banana's atlas is mostly black around the fruit; the mask's
            // photograph fills its image, so the test tells nothing there.
            assert!(
                !name.starts_with("banana") || luma(sampled) > 2 * luma(flipped),
                "{name}: UVs sample {sampled:?}, flipped {flipped:?}"
            );
            eprintln!(
                "{name}: mesh {} vertices / {} triangles; textured surface {} vertices \
                 ({} UVs in [0,1]), {} triangles; image {w}×{h}, mean RGB {:?}, at the UVs {sampled:?} \
                 (v flipped: {flipped:?}); textured import {elapsed:.2?} (geometry alone {geometry:.2?})",
                got.mesh.positions.len(),
                got.mesh.triangles.len(),
                tex.positions.len(),
                inside,
                tex.triangles.len(),
                mean.map(|c| c / px),
            );
        }
    }
}
