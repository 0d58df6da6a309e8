//! Writes seed inputs for the fuzz targets: `make_seeds DIR` creates
//! `DIR/<target>/seed-*` (existing files are overwritten). Streams come from
//! the current encoder, so the seeds follow format changes.

use std::path::Path;

use vitrine_mesh::export::{sample_md2, write_glb, write_md2, write_obj, write_ply};
use vitrine_samples::{icosphere, paint, plate_with_tunnels, torus};
use vitrine_codec::{encode, Charts, EncodeOptions, StreamIndex};
use vitrine_codec_fuzz::{sample_meshes, sample_streams};

fn base64(data: &[u8]) -> String {
    const T: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut s = String::new();
    for c in data.chunks(3) {
        let b = [c[0], *c.get(1).unwrap_or(&0), *c.get(2).unwrap_or(&0)];
        let n = (b[0] as u32) << 16 | (b[1] as u32) << 8 | b[2] as u32;
        for k in 0..4 {
            s.push(if k <= c.len() {
                T[(n >> (18 - 6 * k) & 63) as usize] as char
            } else {
                '='
            });
        }
    }
    s
}

fn main() {
    let dir = std::env::args().nth(1).expect("usage: make_seeds DIR");
    let write = |target: &str, name: &str, bytes: &[u8]| {
        let d = Path::new(&dir).join(target);
        std::fs::create_dir_all(&d).unwrap();
        std::fs::write(d.join(format!("seed-{name}")), bytes).unwrap();
    };

    // import_md2: generated animated models (no game assets).
    for (i, (rings, sides, frames)) in [(3, 3, 1), (8, 5, 3), (12, 8, 5)].into_iter().enumerate() {
        let mut bytes = Vec::new();
        write_md2(&sample_md2(rings, sides, frames), &mut bytes).unwrap();
        write("import_md2", &format!("torus-{i}"), &bytes);
    }

    // decode_stream: whole streams.
    for (i, s) in sample_streams().iter().enumerate() {
        write("decode_stream", &format!("sample-{i}"), s);
    }
    let plate = encode(
        &plate_with_tunnels(1, 2),
        &EncodeOptions {
            min_base_vertices: 8,
            ..Default::default()
        },
    )
    .unwrap();
    write("decode_stream", "plate", &plate.bytes);
    let coarse = encode(
        &icosphere(1),
        &EncodeOptions {
            quantization_bits: 8,
            min_base_vertices: 4,
            ..Default::default()
        },
    );
    write("decode_stream", "coarse", &coarse.unwrap().bytes);
    // A charted stream (format 5): labels and parted batches.
    let mut painted = torus(40, 24, 1.0, 0.3);
    paint(&mut painted);
    let charted = encode(
        &painted,
        &EncodeOptions {
            min_base_vertices: 8,
            charts: Charts::Count(3),
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(charted.header.version, vitrine_codec::CHARTED_VERSION);
    write("decode_stream", "charted", &charted.bytes);
    // A nested stream (format 6): phases, splits, deferred-precision bytes.
    let mut painted = torus(60, 30, 1.0, 0.3);
    paint(&mut painted);
    let nested = encode(
        &painted,
        &EncodeOptions {
            min_base_vertices: 8,
            charts: Charts::NestedShape {
                top: 2,
                fanout: 2,
                phases: 2,
            },
            ..Default::default()
        },
    )
    .unwrap();
    assert_eq!(nested.header.version, vitrine_codec::NESTED_VERSION);
    write("decode_stream", "nested", &nested.bytes);

    // decode_points: small point streams, with and without attributes.
    for (i, (n, attrs)) in [(40usize, false), (300, true)].into_iter().enumerate() {
        let (pos, nrm) = vitrine_points::testing::sphere(n, [0.0; 3], 1.0, i as u64);
        let cloud = vitrine_points::PointCloud {
            colours: attrs.then(|| pos.iter().map(|p| p.map(|v| (v * 90.0 + 128.0) as u8)).collect()),
            normals: attrs.then_some(nrm),
            ..vitrine_points::PointCloud::from_positions(pos)
        };
        // Every stream version (2 and 3: neighbour-dependent mask contexts),
        // and with attributes, also predicted from the neighbourhood (flag bit 2).
        for version in vitrine_points::stream::VERSIONS {
            for predict in [false, true].into_iter().filter(|&p| attrs || !p) {
                let opts = vitrine_points::stream::EncodeOptions {
                    bits: 10,
                    base_points: 16,
                    version,
                    predict_attributes: predict,
                    ..Default::default()
                };
                let s = vitrine_points::stream::encode(&cloud, &opts).unwrap();
                let tail = if predict { "-predicted" } else { "" };
                write("decode_points", &format!("sphere-{i}-v{version}{tail}"), &s.bytes);
            }
        }
    }

    // decode_batch: selector byte, then batch 1's payload or whole chunk.
    for (i, s) in sample_streams().iter().enumerate() {
        let index = StreamIndex::parse(s).unwrap();
        let chunk = &s[index.batches[0].clone()];
        let mut payload = vec![i as u8];
        payload.extend_from_slice(&chunk[20..]);
        write("decode_batch", &format!("payload-{i}"), &payload);
        let mut whole = vec![i as u8 | 2];
        whole.extend_from_slice(chunk);
        write("decode_batch", &format!("chunk-{i}"), &whole);
    }

    // Importers: the sample meshes as each format writes them.
    let small = [icosphere(0), sample_meshes()[1].clone()];
    for (i, m) in small.iter().enumerate() {
        let mut b = Vec::new();
        write_ply(m, &mut b).unwrap();
        write("import_ply", &format!("binary-{i}"), &b);
        let mut b = Vec::new();
        write_obj(m, &mut b).unwrap();
        write("import_obj", &format!("mesh-{i}"), &b);
        let mut b = Vec::new();
        write_glb(m, &mut b).unwrap();
        write("import_gltf", &format!("glb-{i}"), &b);
        // The same GLB as glTF JSON with its binary chunk in a data URI.
        let json_len = u32::from_le_bytes(b[12..16].try_into().unwrap()) as usize;
        let json = std::str::from_utf8(&b[20..20 + json_len])
            .unwrap()
            .trim_end();
        let bin = &b[20 + json_len + 8..];
        let uri = format!(
            "\"uri\":\"data:application/octet-stream;base64,{}\",",
            base64(bin)
        );
        let gltf = json.replacen("\"byteLength\"", &format!("{uri}\"byteLength\""), 1);
        write("import_gltf", &format!("json-{i}"), gltf.as_bytes());
        // OFF / COFF by hand.
        let mut off = String::from(if m.colors.is_some() {
            "COFF\n"
        } else {
            "OFF\n"
        });
        off += &format!("{} {} 0\n", m.positions.len(), m.triangles.len());
        for (v, p) in m.positions.iter().enumerate() {
            off += &format!("{} {} {}", p[0], p[1], p[2]);
            if let Some(c) = &m.colors {
                off += &format!(" {} {} {} 255", c[v][0], c[v][1], c[v][2]);
            }
            off += "\n";
        }
        for t in &m.triangles {
            off += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
        }
        write("import_off", &format!("mesh-{i}"), off.as_bytes());
    }
    write(
        "import_ply",
        "ascii",
        b"ply\nformat ascii 1.0\ncomment x\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n\
          property uchar red\nproperty uchar green\nproperty uchar blue\nelement face 2\n\
          property list uchar int vertex_indices\nend_header\n0 0 0 255 0 0\n1 0 0 0 255 0\n1 1 0 0 0 255\n0 1 0 9 9 9\n\
          3 0 1 2\n4 0 1 2 3\n",
    );
    write(
        "import_ply",
        "strips-be",
        b"ply\nformat binary_big_endian 1.0\nelement vertex 0\nproperty double x\nproperty double y\nproperty double z\n\
          element tristrips 0\nproperty list int int vertex_indices\nend_header\n",
    );
    write(
        "import_obj",
        "polygons",
        b"v 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nf 1/1 2/1 3/1 4/1\nf -1 -2 -3\n",
    );
    write("import_gltf", "extensions", extension_seed().as_bytes());
}

/// glTF as tools write it: quantized short positions (`KHR_mesh_quantization`
/// required, with a material-only extension), a sparse accessor without a
/// base view, a custom attribute and a texture transform, in one file.
fn extension_seed() -> String {
    let mut bin = Vec::new();
    for v in [0i16, 0, 0, 300, 0, 0, 300, 300, 0, 0, 300, 0] {
        bin.extend_from_slice(&v.to_le_bytes()); // 24 bytes of positions
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend_from_slice(&i.to_le_bytes()); // 12 bytes of indices
    }
    bin.extend_from_slice(&[1, 2, 3, 0]); // 4 bytes of sparse indices
    for v in [1f32, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 0.0] {
        bin.extend_from_slice(&v.to_le_bytes()); // 36 bytes of sparse values
    }
    format!(
        r#"{{"asset":{{"version":"2.0"}},"extensionsUsed":["KHR_mesh_quantization","KHR_materials_unlit","KHR_texture_transform"],
"extensionsRequired":["KHR_mesh_quantization","KHR_materials_unlit"],"scene":0,"scenes":[{{"nodes":[0]}}],
"nodes":[{{"mesh":0,"scale":[0.01,0.01,0.01]}}],
"materials":[{{"extensions":{{"KHR_materials_unlit":{{}}}},"pbrMetallicRoughness":{{"baseColorTexture":{{"index":0,"extensions":{{"KHR_texture_transform":{{"scale":[2,2]}}}}}}}}}}],
"textures":[{{"source":0}}],"images":[{{"uri":"missing.png"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"_BATCHID":0}},"indices":1,"material":0}},{{"attributes":{{"POSITION":2}},"indices":1}}]}}],
"buffers":[{{"byteLength":76,"uri":"data:application/octet-stream;base64,{}"}}],
"bufferViews":[{{"buffer":0,"byteOffset":0,"byteLength":24}},{{"buffer":0,"byteOffset":24,"byteLength":12}},
{{"buffer":0,"byteOffset":36,"byteLength":4}},{{"buffer":0,"byteOffset":40,"byteLength":36}}],
"accessors":[{{"bufferView":0,"componentType":5122,"count":4,"type":"VEC3","min":[0,0,0],"max":[300,300,0]}},
{{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"}},
{{"componentType":5126,"count":4,"type":"VEC3","min":[0,0,0],"max":[1,1,0],
"sparse":{{"count":3,"indices":{{"bufferView":2,"componentType":5121}},"values":{{"bufferView":3}}}}}}]}}"#,
        base64(&bin)
    )
}
