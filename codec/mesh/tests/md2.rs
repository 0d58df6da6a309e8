//! MD2 (seed 003) on generated models: read → write byte-identical,
//! positions exactly `scale · v + translate`, frames, skins, seams, and
//! hostile headers refused within bounded memory.

use std::path::{Path, PathBuf};

use vitrine_codec::Error;
use vitrine_mesh::export::md2::quantize_frame;
use vitrine_mesh::export::{sample_md2, write_md2, write_mesh_md2};
use vitrine_mesh::import::md2::{quake_to_y_up, Md2, MD2_HEADER_BYTES};
use vitrine_mesh::import::{
    import_bytes, import_path, import_path_textured, ImportOptions, MeshFormat,
};
use vitrine_mesh::repair::{check_manifold, prepare, RepairOptions};

fn bytes_of(model: &Md2) -> Vec<u8> {
    let mut out = Vec::new();
    write_md2(model, &mut out).unwrap();
    out
}

fn sample_bytes() -> Vec<u8> {
    bytes_of(&sample_md2(12, 8, 5))
}

fn opts(frame: usize) -> ImportOptions {
    ImportOptions {
        frame,
        ..ImportOptions::default()
    }
}

fn tmp(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("md2-tests")
        .join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn put_i32(bytes: &mut [u8], at: usize, v: i32) {
    bytes[at..at + 4].copy_from_slice(&v.to_le_bytes());
}

#[test]
fn read_then_write_is_byte_identical() {
    let bytes = sample_bytes();
    let model = Md2::parse(&bytes, &ImportOptions::default()).unwrap();
    assert_eq!(model, sample_md2(12, 8, 5));
    assert_eq!(bytes_of(&model), bytes);
    // And a model with foreign GL commands is rewritten with regenerated ones,
    // which then re-write identically.
    let mut odd = model.clone();
    odd.gl_commands = vec![0];
    let once = bytes_of(&odd);
    assert_eq!(once, bytes);
    // The header's sizes are the layout's.
    let h = |k: usize| i32::from_le_bytes(bytes[4 * k..4 * k + 4].try_into().unwrap());
    assert_eq!(&bytes[..4], b"IDP2");
    assert_eq!(h(1), 8);
    assert_eq!(h(4), 40 + 4 * 96, "framesize");
    assert_eq!(h(16) as usize, bytes.len(), "ofs_end");
    assert_eq!(h(11) as usize, MD2_HEADER_BYTES, "ofs_skins");
    // One 3-vertex strip per triangle and the final 0.
    assert_eq!(h(9) as usize, 1 + 10 * model.triangles.len());
}

#[test]
fn positions_are_scale_times_v_plus_translate_exactly() {
    let bytes = sample_bytes();
    let model = Md2::parse(&bytes, &ImportOptions::default()).unwrap();
    for k in [0, 3, 4] {
        let mesh = import_bytes(&bytes, MeshFormat::Md2, &opts(k)).unwrap();
        let f = &model.frames[k];
        assert_eq!(mesh.positions.len(), 96);
        for (i, p) in mesh.positions.iter().enumerate() {
            let v = f.vertices[i];
            let quake: [f32; 3] =
                std::array::from_fn(|c| f32::from(v[c]) * f.scale[c] + f.translate[c]);
            // Z-up to Y-up: (x, y, z) → (x, z, −y).
            let want = [quake[0], quake[2], -quake[1]];
            assert_eq!(
                p.map(f32::to_bits),
                want.map(f32::to_bits),
                "frame {k} vertex {i}"
            );
        }
    }
    let a = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap();
    let b = import_bytes(&bytes, MeshFormat::Md2, &opts(2)).unwrap();
    assert_ne!(a.positions, b.positions, "frames differ");
    assert_eq!(a.triangles, b.triangles);
    match import_bytes(&bytes, MeshFormat::Md2, &opts(5)) {
        Err(Error::Parameter(m)) => assert!(m.contains("has 5 frames"), "{m}"),
        other => panic!("{other:?}"),
    }
}

#[test]
fn the_model_is_a_closed_outward_manifold_with_its_seams_welded() {
    let bytes = sample_bytes();
    let mesh = import_bytes(&bytes, MeshFormat::Md2, &opts(1)).unwrap();
    let (repaired, report) = prepare(mesh.clone(), &RepairOptions::default()).unwrap();
    check_manifold(&repaired).unwrap();
    // The UV seam does not split the positions: nothing to weld or cut.
    assert_eq!(repaired.positions.len(), 96);
    assert_eq!(report.flipped_faces, 0);
    // Counter-clockwise from outside: positive signed volume.
    let p = |v: u32| glam::Vec3::from(mesh.positions[v as usize]);
    let volume: f32 = mesh
        .triangles
        .iter()
        .map(|&[a, b, c]| p(a).dot(p(b).cross(p(c))) / 6.0)
        .sum();
    assert!(volume > 0.0, "{volume}");
}

#[test]
fn the_skin_beside_the_file_becomes_the_texture() {
    let dir = tmp("skin");
    let path = dir.join("torus.md2");
    std::fs::write(&path, sample_bytes()).unwrap();
    let skin = image::RgbImage::from_fn(64, 32, |x, y| image::Rgb([x as u8 * 4, y as u8 * 8, 9]));
    skin.save(dir.join("skin.png")).unwrap();
    let got = import_path_textured(&path, &ImportOptions::default()).unwrap();
    assert!(got.warnings.is_empty(), "{:?}", got.warnings);
    let tex = got.texture.expect("texture");
    assert_eq!(tex.image.dimensions(), (64, 32));
    // The seam opens in the textured surface: (12 + 1) × (8 + 1) corners.
    assert_eq!(tex.positions.len(), 13 * 9);
    assert_eq!(tex.triangles.len(), got.mesh.triangles.len());
    assert!(tex
        .uvs
        .iter()
        .all(|uv| (0.0..=1.0).contains(&uv[0]) && (0.0..=1.0).contains(&uv[1])));
    assert_eq!(
        import_path(&path, &ImportOptions::default()).unwrap(),
        got.mesh
    );
    // A PCX skin is read too.
    std::fs::remove_file(dir.join("skin.png")).unwrap();
    let mut pcx_bytes = Vec::new();
    let mut w = pcx::WriterRgb::new(&mut pcx_bytes, (64, 32), (72, 72)).unwrap();
    for y in 0..32u8 {
        let row: Vec<u8> = (0..64u8).flat_map(|x| [x, y, 1]).collect();
        w.write_row(&row).unwrap();
    }
    w.finish().unwrap();
    // Named .png by the model: the content decides.
    std::fs::write(dir.join("skin.png"), &pcx_bytes).unwrap();
    let got = import_path_textured(&path, &ImportOptions::default()).unwrap();
    assert_eq!(got.texture.expect("pcx").image.get_pixel(5, 7).0, [5, 7, 1]);
    // No skin: geometry still comes, with a warning.
    std::fs::remove_file(dir.join("skin.png")).unwrap();
    let got = import_path_textured(&path, &ImportOptions::default()).unwrap();
    assert!(got.texture.is_none());
    assert!(got.warnings[0].contains("not found"), "{:?}", got.warnings);
}

#[test]
fn a_wrong_magic_is_refused_even_with_version_8() {
    let mut bytes = sample_bytes();
    bytes[..4].copy_from_slice(b"IDP3");
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("wrong magic"), "{e}");
    let mut bytes = sample_bytes();
    put_i32(&mut bytes, 4, 7);
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("version 7"), "{e}");
}

/// Header field `k` (0 = ident) lies at byte 4k.
#[test]
fn hostile_headers_are_clear_errors_in_bounded_memory() {
    let good = sample_bytes();
    let cases: &[(usize, i32, &str)] = &[
        (2, 0, "skinwidth"),
        (4, 77, "framesize"),
        (5, 33, "limit of 32"),          // num_skins
        (6, 1_000_000, "limit of 2048"), // num_xyz
        (6, -1, "negative"),
        (7, 1 << 30, "limit of 12288"), // num_st
        (7, 5000, "past the end"),
        (8, 100_000, "limit of 4096"), // num_tris
        (8, 4000, "past the end"),
        (9, 1 << 28, "limit"),     // num_glcmds
        (10, 513, "limit of 512"), // num_frames
        (10, 0, "no frames"),
        (12, 1 << 30, "past the end"),  // ofs_st
        (13, 0, "overlaps the header"), // ofs_tris
        (14, -8, "negative"),           // ofs_frames
        (15, i32::MAX, "past the end"), // ofs_glcmds
        (16, 1 << 30, "past the end"),  // ofs_end
    ];
    for &(field, value, needle) in cases {
        let mut bytes = good.clone();
        put_i32(&mut bytes, 4 * field, value);
        let info = allocation_counter::measure(|| {
            let r = import_bytes(&bytes, MeshFormat::Md2, &opts(0));
            let e = r.expect_err("hostile header accepted").to_string();
            assert!(
                e.contains(needle),
                "field {field} = {value}: {e:?} lacks {needle:?}"
            );
        });
        assert!(
            info.bytes_max < 64 << 10,
            "field {field}: peak {} bytes",
            info.bytes_max
        );
    }
    // Indices past the vertices and texture coordinates.
    let model = Md2::parse(&good, &ImportOptions::default()).unwrap();
    let mut bytes = good.clone();
    let ofs_tris = i32::from_le_bytes(bytes[52..56].try_into().unwrap()) as usize;
    bytes[ofs_tris..ofs_tris + 2].copy_from_slice(&96u16.to_le_bytes());
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("vertex 96 of 96"), "{e}");
    let mut bytes = good.clone();
    bytes[ofs_tris + 6..ofs_tris + 8].copy_from_slice(&(model.st.len() as u16).to_le_bytes());
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("texture coordinate"), "{e}");
    // A NaN scale.
    let mut bytes = good.clone();
    let ofs_frames = i32::from_le_bytes(bytes[56..60].try_into().unwrap()) as usize;
    bytes[ofs_frames..ofs_frames + 4].copy_from_slice(&f32::NAN.to_le_bytes());
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
    // Finite fields whose product overflows (found by fuzzing).
    let mut bytes = good.clone();
    bytes[ofs_frames..ofs_frames + 4].copy_from_slice(&3e37f32.to_le_bytes());
    let e = import_bytes(&bytes, MeshFormat::Md2, &opts(0)).unwrap_err();
    assert!(e.to_string().contains("non-finite"), "{e}");
}

#[test]
fn every_truncation_is_an_error() {
    let good = sample_bytes();
    for len in (0..good.len()).step_by(7) {
        assert!(
            import_bytes(&good[..len], MeshFormat::Md2, &opts(0)).is_err(),
            "prefix {len}"
        );
    }
}

#[test]
fn the_format_is_known_by_extension_and_magic() {
    assert_eq!(
        MeshFormat::from_path(Path::new("models/Tank.MD2")),
        Some(MeshFormat::Md2)
    );
    assert_eq!(MeshFormat::sniff(&sample_bytes()), Some(MeshFormat::Md2));
}

#[test]
fn a_mesh_written_as_md2_reads_back_within_half_a_step() {
    let mesh = import_bytes(&sample_bytes(), MeshFormat::Md2, &opts(2)).unwrap();
    let mut out = Vec::new();
    write_mesh_md2(&mesh, &mut out).unwrap();
    let back = import_bytes(&out, MeshFormat::Md2, &opts(0)).unwrap();
    assert_eq!(back.triangles, mesh.triangles);
    let model = Md2::parse(&out, &ImportOptions::default()).unwrap();
    let step = model.frames[0].scale;
    let step = [step[0], step[2], step[1]];
    for (a, b) in back.positions.iter().zip(&mesh.positions) {
        for k in 0..3 {
            assert!((a[k] - b[k]).abs() <= step[k] * 0.5 + 1e-4, "{a:?} {b:?}");
        }
    }
    // And that MD2 re-writes byte-identical.
    assert_eq!(bytes_of(&model), out);
    // Too large for the format: a clear error.
    let big = vitrine_codec::IndexedMesh {
        positions: vec![[0.0; 3]; 3000],
        colors: None,
        triangles: vec![[0, 1, 2]],
    };
    let e = write_mesh_md2(&big, &mut Vec::new()).unwrap_err();
    assert!(e.to_string().contains("at most 2048 vertices"), "{e}");
}

#[test]
fn quantizing_keeps_the_minimum_exactly() {
    let p = [[0.0, 1.0, 2.0], [10.0, -1.0, 4.0], [5.0, 0.0, 3.0]];
    let f = quantize_frame(&p, &[[0, 1, 2]], "x").unwrap();
    assert_eq!(quake_to_y_up(f.translate), [0.0, -1.0, 4.0]);
    assert_eq!(f.vertices[0][0], 0);
    assert_eq!(f.vertices[1][0], 255);
    assert_eq!(f.name(), "x");
}
