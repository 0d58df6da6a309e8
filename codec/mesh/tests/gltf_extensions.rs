//! glTF as tools write it: `KHR_mesh_quantization`, sparse accessors,
//! `KHR_texture_transform`, material-only and custom extensions, and the
//! extensions that stay unsupported, each on a file built here.

use std::path::{Path, PathBuf};

use vitrine_codec::Error;
use vitrine_mesh::import::{import_bytes, import_path_textured, ImportOptions, MeshFormat};

mod common;
use common::{le, Glb};

/// A unit quad's float positions, counter-clockwise indices.
const QUAD: [[f32; 3]; 4] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 1.0, 0.0],
    [0.0, 1.0, 0.0],
];

fn float_positions(g: &mut Glb, p: &[[f32; 3]]) -> usize {
    let v = g.view(&le(p.as_flattened(), f32::to_le_bytes));
    g.accessor(format!(
        r#""bufferView":{v},"componentType":5126,"count":{},"type":"VEC3","min":[0,0,0],"max":[1,1,1]"#,
        p.len()
    ))
}

fn quad_indices(g: &mut Glb) -> usize {
    let v = g.view(&le(&[0u16, 1, 2, 0, 2, 3], u16::to_le_bytes));
    g.accessor(format!(
        r#""bufferView":{v},"componentType":5123,"count":6,"type":"SCALAR""#
    ))
}

/// One primitive with `attributes` under node `node` (JSON members), and
/// `extra` document members (a leading comma each).
fn document(attributes: &str, indices: usize, node: &str, extra: &str) -> String {
    format!(
        r#""scene":0,"scenes":[{{"nodes":[0]}}],"nodes":[{{"mesh":0{node}}}],
        "meshes":[{{"primitives":[{{"attributes":{{{attributes}}},"indices":{indices}MATERIAL}}]}}]{extra}"#
    )
}

fn import(bytes: &[u8]) -> vitrine_codec::Result<vitrine_codec::IndexedMesh> {
    import_bytes(bytes, MeshFormat::Glb, &ImportOptions::default())
}

fn unsupported(bytes: &[u8]) -> String {
    match import(bytes) {
        Err(e @ Error::Unsupported(_)) => e.to_string(),
        other => panic!("expected Error::Unsupported, got {other:?}"),
    }
}

// ------------------------------------------------------- KHR_mesh_quantization

#[test]
fn quantized_positions_under_the_node_transform() {
    // Short positions, unnormalized, with byte normals: the dequantization
    // is the node's scale and translation, as exporters (gltfpack) write it.
    let raw: [[i16; 3]; 4] = [[0, 0, 0], [300, 0, -2], [300, 300, 7], [-4, 300, 0]];
    let mut g = Glb::default();
    let pv = g.view(&le(raw.as_flattened(), i16::to_le_bytes));
    let pos = g.accessor(format!(
        r#""bufferView":{pv},"componentType":5122,"count":4,"type":"VEC3","min":[-4,0,-2],"max":[300,300,7]"#
    ));
    // VEC3 bytes padded to 4 per element, as the spec's alignment asks.
    let nv = g.view(&[0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0, 0, 0, 127, 0]);
    g.views[nv] = g.views[nv].replace('}', r#","byteStride":4}"#);
    let nor = g.accessor(format!(
        r#""bufferView":{nv},"componentType":5120,"normalized":true,"count":4,"type":"VEC3""#
    ));
    let idx = quad_indices(&mut g);
    let doc = document(
        &format!(r#""POSITION":{pos},"NORMAL":{nor}"#),
        idx,
        r#","scale":[0.5,0.25,2],"translation":[10,-3,0.5]"#,
        r#","extensionsUsed":["KHR_mesh_quantization"],"extensionsRequired":["KHR_mesh_quantization"]"#,
    )
    .replace("MATERIAL", "");
    let m = import(&g.bytes(&doc)).unwrap();
    let want: Vec<[f32; 3]> = raw
        .iter()
        .map(|p| {
            [
                p[0] as f32 * 0.5 + 10.0,
                p[1] as f32 * 0.25 - 3.0,
                p[2] as f32 * 2.0 + 0.5,
            ]
        })
        .collect();
    assert_eq!(m.positions, want);
    assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3]]);
}

#[test]
fn quantized_normalized_byte_positions() {
    let raw: [[u8; 4]; 4] = [
        [0, 0, 0, 0],
        [255, 0, 0, 0],
        [255, 255, 51, 0],
        [0, 255, 0, 0],
    ];
    let mut g = Glb::default();
    let pv = g.view(raw.as_flattened());
    g.views[pv] = g.views[pv].replace('}', r#","byteStride":4}"#);
    let pos = g.accessor(format!(
        r#""bufferView":{pv},"componentType":5121,"normalized":true,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0.2]"#
    ));
    let idx = quad_indices(&mut g);
    let doc = document(
        &format!(r#""POSITION":{pos}"#),
        idx,
        "",
        r#","extensionsRequired":["KHR_mesh_quantization"]"#,
    )
    .replace("MATERIAL", "");
    let m = import(&g.bytes(&doc)).unwrap();
    let want: Vec<[f32; 3]> = raw
        .iter()
        .map(|p| [0, 1, 2].map(|k| (p[k] as f64 / 255.0) as f32))
        .collect();
    assert_eq!(m.positions, want);
    assert_eq!(m.positions[2], [1.0, 1.0, 0.2]);
}

// ------------------------------------------------------------ sparse accessors

#[test]
fn sparse_positions_over_a_base_view() {
    let mut base = QUAD;
    base[2] = [9.0, 9.0, 9.0]; // replaced by the sparse value
    let mut g = Glb::default();
    let bv = g.view(&le(base.as_flattened(), f32::to_le_bytes));
    let iv = g.view(&le(&[2u16], u16::to_le_bytes));
    let vv = g.view(&le(&[1f32, 1.0, 0.0], f32::to_le_bytes));
    let pos = g.accessor(format!(
        r#""bufferView":{bv},"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
        "sparse":{{"count":1,"indices":{{"bufferView":{iv},"componentType":5123}},"values":{{"bufferView":{vv}}}}}"#
    ));
    let idx = quad_indices(&mut g);
    let doc = document(&format!(r#""POSITION":{pos}"#), idx, "", "").replace("MATERIAL", "");
    let m = import(&g.bytes(&doc)).unwrap();
    assert_eq!(m.positions, QUAD.to_vec());
}

/// A quad whose positions are a sparse accessor without a buffer view
/// (zeros but for `indices`), as `(bytes, document)` with `indices` and
/// their values given raw.
fn zero_based_sparse(indices: &[u8], values: &[[f32; 3]], count: usize) -> Vec<u8> {
    let mut g = Glb::default();
    let iv = g.view(indices);
    let vv = g.view(&le(values.as_flattened(), f32::to_le_bytes));
    let pos = g.accessor(format!(
        r#""componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
        "sparse":{{"count":{count},"indices":{{"bufferView":{iv},"componentType":5121}},"values":{{"bufferView":{vv}}}}}"#
    ));
    let idx = quad_indices(&mut g);
    let doc = document(&format!(r#""POSITION":{pos}"#), idx, "", "").replace("MATERIAL", "");
    g.bytes(&doc)
}

#[test]
fn sparse_positions_without_a_base_view_start_from_zero() {
    let m = import(&zero_based_sparse(&[1, 2, 3], &QUAD[1..], 3)).unwrap();
    assert_eq!(m.positions, QUAD.to_vec());
}

#[test]
fn hostile_sparse_accessors_are_clear_errors() {
    let check = |bytes: Vec<u8>, needle: &str| {
        let e = import(&bytes).unwrap_err().to_string();
        assert!(e.contains(needle) && e.contains("sparse"), "{e}");
    };
    check(
        zero_based_sparse(&[1, 3, 2], &QUAD[1..], 3),
        "increase strictly",
    );
    check(
        zero_based_sparse(&[1, 2, 4], &QUAD[1..], 3),
        "past the accessor's 4",
    );
    // A count the index and value bytes do not back: nothing is allocated for it.
    check(
        zero_based_sparse(&[1, 2, 3], &QUAD[1..], 4_000_000),
        "runs past the end of buffer view",
    );
}

// ------------------------------------------------------- KHR_texture_transform

fn folder(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("gltf-extensions")
        .join(name);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn png(w: u32, h: u32) -> Vec<u8> {
    let img = image::RgbImage::from_fn(w, h, |x, y| image::Rgb([x as u8 * 40, y as u8 * 40, 9]));
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png).unwrap();
    out.into_inner()
}

/// A textured quad with two UV sets, the base colour texture's reference
/// `texture_info` (JSON members after `"index":0`).
fn textured_quad(texture_info: &str, required: &str) -> Vec<[f32; 2]> {
    let mut g = Glb::default();
    let pos = float_positions(&mut g, &QUAD);
    let uv0: [[f32; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
    let uv1: [[f32; 2]; 4] = [[0.25, 0.5], [0.5, 0.5], [0.5, 0.75], [0.25, 0.75]];
    let mut sets = Vec::new();
    for uv in [uv0, uv1] {
        let v = g.view(&le(uv.as_flattened(), f32::to_le_bytes));
        sets.push(g.accessor(format!(
            r#""bufferView":{v},"componentType":5126,"count":4,"type":"VEC2""#
        )));
    }
    let idx = quad_indices(&mut g);
    let image = g.view(&png(4, 4));
    let doc = document(
        &format!(
            r#""POSITION":{pos},"TEXCOORD_0":{},"TEXCOORD_1":{}"#,
            sets[0], sets[1]
        ),
        idx,
        "",
        &format!(
            r#","materials":[{{"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0{texture_info}}}}}}}],
            "textures":[{{"source":0}}],"images":[{{"bufferView":{image},"mimeType":"image/png"}}]{required}"#
        ),
    )
    .replace("MATERIAL", r#","material":0"#);
    // One file per call: the tests run in parallel, and a shared name let
    // one test read another's half-written file.
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let path = folder("transform").join(format!("quad-{n}.glb"));
    let bytes = g.bytes(&doc);
    std::fs::write(&path, bytes).unwrap();
    let got = import_path_textured(&path, &ImportOptions::default()).unwrap();
    assert!(got.warnings.is_empty(), "{:?}", got.warnings);
    got.texture.expect("a texture").uvs
}

#[test]
fn texture_transform_offset_and_scale() {
    let uvs = textured_quad(
        r#","extensions":{"KHR_texture_transform":{"offset":[0.25,0.5],"scale":[2,0.5]}}"#,
        r#","extensionsUsed":["KHR_texture_transform"],"extensionsRequired":["KHR_texture_transform"]"#,
    );
    assert_eq!(
        uvs,
        vec![[0.25, 0.5], [2.25, 0.5], [2.25, 1.0], [0.25, 1.0]]
    );
}

#[test]
fn texture_transform_rotation_is_the_specification_example() {
    // The extension's example: offset [0, 1], rotation π/2, scale 0.5 uses
    // "the lower left quadrant of the image, rotated clockwise 90°":
    // (u, v) → (v / 2, 1 − u / 2).
    let uvs = textured_quad(
        r#","extensions":{"KHR_texture_transform":{"offset":[0,1],"rotation":1.57079632679,"scale":[0.5,0.5]}}"#,
        "",
    );
    let want = [[0.0, 1.0], [0.0, 0.5], [0.5, 0.5], [0.5, 1.0]];
    for (got, want) in uvs.iter().zip(want) {
        for k in 0..2 {
            assert!((got[k] - want[k]).abs() < 1e-6, "{uvs:?}");
        }
    }
}

#[test]
fn texture_transform_tex_coord_overrides_the_reference() {
    let plain = textured_quad(r#","texCoord":0"#, "");
    assert_eq!(plain[1], [1.0, 0.0]);
    let uvs = textured_quad(
        r#","texCoord":0,"extensions":{"KHR_texture_transform":{"texCoord":1}}"#,
        "",
    );
    assert_eq!(
        uvs,
        vec![[0.25, 0.5], [0.5, 0.5], [0.5, 0.75], [0.25, 0.75]]
    );
}

// ------------------------------------------ accepted and refused extensions

fn plain_quad(attributes: &str, extra: &str) -> Vec<u8> {
    let mut g = Glb::default();
    let pos = float_positions(&mut g, &QUAD);
    let idx = quad_indices(&mut g);
    let mut attrs = format!(r#""POSITION":{pos}"#);
    if !attributes.is_empty() {
        let v = g.view(&[7u8; 16]);
        let a = g.accessor(format!(
            r#""bufferView":{v},"componentType":5121,"count":4,"type":"VEC4""#
        ));
        attrs += &attributes.replace("ACC", &a.to_string());
    }
    let doc = document(&attrs, idx, "", extra).replace("MATERIAL", r#","material":0"#);
    g.bytes(&doc)
}

#[test]
fn material_only_extensions_are_accepted_when_required() {
    let plain = import(&plain_quad("", r#","materials":[{}]"#)).unwrap();
    for name in [
        "KHR_materials_unlit",
        "KHR_materials_emissive_strength",
        "KHR_materials_ior",
        "KHR_materials_specular",
        "KHR_materials_transmission",
        "KHR_materials_volume",
        "KHR_materials_clearcoat",
        "KHR_materials_sheen",
        "KHR_materials_iridescence",
        "KHR_materials_anisotropy",
        "KHR_materials_dispersion",
        "KHR_materials_variants",
    ] {
        let extra = format!(
            r#","materials":[{{"extensions":{{"{name}":{{}}}}}}],"extensionsUsed":["{name}"],"extensionsRequired":["{name}"]"#
        );
        let m = import(&plain_quad("", &extra)).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(m, plain, "{name}");
    }
}

#[test]
fn custom_attributes_are_ignored() {
    let plain = import(&plain_quad("", r#","materials":[{}]"#)).unwrap();
    let m = import(&plain_quad(
        r#","_FOO":ACC,"_BATCHID":ACC"#,
        r#","materials":[{}]"#,
    ))
    .unwrap();
    assert_eq!(m, plain);
}

#[test]
fn other_required_extensions_are_refused_by_name() {
    for (name, why) in [
        ("EXT_mesh_gpu_instancing", "instanced"),
        ("KHR_materials_pbrSpecularGlossiness", "diffuse texture"),
        ("EXT_texture_webp", "format"),
        ("VENDOR_made_up", "does not know it"),
    ] {
        let extra = format!(
            r#","materials":[{{}}],"extensionsUsed":["{name}"],"extensionsRequired":["KHR_materials_unlit","{name}"]"#
        );
        let e = unsupported(&plain_quad("", &extra));
        assert!(
            e.contains(&format!("glTF extension {name} is not supported")) && e.contains(why),
            "{e}"
        );
    }
}

#[test]
fn extensions_used_but_not_required_fall_back() {
    // An exporter's fallback: the compressed data is optional, the plain
    // accessors are read.
    let plain = import(&plain_quad("", r#","materials":[{}]"#)).unwrap();
    let extra =
        r#","materials":[{}],"extensionsUsed":["EXT_meshopt_compression","VENDOR_made_up"]"#;
    assert_eq!(import(&plain_quad("", extra)).unwrap(), plain);
}
