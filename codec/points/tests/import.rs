//! Point-cloud import: PLY without faces (ascii and binary, normals,
//! integer and float colour), LAS and LAZ, and clear errors on bad files.

use std::io::Cursor;

use vitrine_points::import::import_bytes;
use vitrine_points::Error;

const LIMIT: usize = 1_000_000;

#[test]
fn import_ply_ascii_with_normals_and_uchar_colour() {
    let ply = b"ply\nformat ascii 1.0\ncomment points only\nelement vertex 3\n\
property float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float ny\nproperty float nz\n\
property uchar red\nproperty uchar green\nproperty uchar blue\nend_header\n\
0 0 0 0 0 2 255 0 10\n1 2 3 0 1 0 1 2 3\n-1.5 0.25 8 1 0 0 200 100 50\n";
    let c = import_bytes(ply, LIMIT).unwrap();
    assert_eq!(
        c.positions,
        vec![[0.0, 0.0, 0.0], [1.0, 2.0, 3.0], [-1.5, 0.25, 8.0]]
    );
    // Normals are made unit length.
    assert_eq!(
        c.normals.unwrap(),
        vec![[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]
    );
    assert_eq!(
        c.colours.unwrap(),
        vec![[255, 0, 10], [1, 2, 3], [200, 100, 50]]
    );
}

fn binary_ply(n: u32, float_colour: bool, faces: bool) -> Vec<u8> {
    let mut h = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {n}\n\
property float x\nproperty float y\nproperty float z\nproperty double intensity\n"
    );
    let ty = if float_colour { "float" } else { "uchar" };
    for c in ["red", "green", "blue"] {
        h += &format!("property {ty} {c}\n");
    }
    if faces {
        h += "element face 1\nproperty list uchar int vertex_indices\n";
    }
    h += "end_header\n";
    let mut b = h.into_bytes();
    for i in 0..n {
        for v in [i as f32, 0.5 * i as f32, -(i as f32)] {
            b.extend_from_slice(&v.to_le_bytes());
        }
        b.extend_from_slice(&7.5f64.to_le_bytes());
        for k in 0..3u32 {
            if float_colour {
                b.extend_from_slice(&(((i + k) % 5) as f32 / 4.0).to_le_bytes());
            } else {
                b.push(((i * 3 + k) % 256) as u8);
            }
        }
    }
    if faces {
        b.push(3);
        for v in [0i32, 1, 2] {
            b.extend_from_slice(&v.to_le_bytes());
        }
    }
    b
}

#[test]
fn import_ply_binary_float_and_uchar_colour_faces_ignored() {
    let c = import_bytes(&binary_ply(100, true, true), LIMIT).unwrap();
    assert_eq!(c.len(), 100);
    assert_eq!(c.positions[7], [7.0, 3.5, -7.0]);
    assert!(c.normals.is_none());
    // 0, 0.25, 0.5, 0.75, 1.0 of 255, rounded.
    assert_eq!(c.colours.as_ref().unwrap()[1], [64, 128, 191]);
    let c = import_bytes(&binary_ply(300, false, false), LIMIT).unwrap();
    assert_eq!(
        c.colours.as_ref().unwrap()[299],
        [(897 % 256) as u8, (898 % 256) as u8, (899 % 256) as u8]
    );
}

#[test]
fn import_ply_bad_files_give_clear_errors() {
    // A count the file cannot hold: refused before anything is reserved.
    let mut huge = binary_ply(10, false, false);
    let at = huge.windows(9).position(|w| w == b"vertex 10").unwrap();
    huge.splice(at..at + 9, b"vertex 4000000000".iter().copied());
    let e = import_bytes(&huge, usize::MAX).unwrap_err().to_string();
    assert!(e.contains("declares 4000000000 vertices"), "{e}");
    // Over the caller's limit.
    let e = import_bytes(&binary_ply(10, false, false), 5).unwrap_err();
    assert!(matches!(e, Error::Limit(_)), "{e}");
    // Truncated payload.
    let full = binary_ply(10, false, false);
    let e = import_bytes(&full[..full.len() - 3], LIMIT)
        .unwrap_err()
        .to_string();
    assert!(e.contains("truncated") || e.contains("remain"), "{e}");
    // No z.
    let no_z = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nend_header\n1 2\n";
    let e = import_bytes(no_z, LIMIT).unwrap_err().to_string();
    assert!(e.contains("\"z\""), "{e}");
    // Not a number, and not finite.
    let bad = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 two 3\n";
    let e = import_bytes(bad, LIMIT).unwrap_err().to_string();
    assert!(e.contains("two"), "{e}");
    let nan = b"ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 nan 3\n";
    assert!(import_bytes(nan, LIMIT).is_err());
    // Neither PLY nor LAS.
    let e = import_bytes(b"hello", LIMIT).unwrap_err().to_string();
    assert!(e.contains("neither PLY"), "{e}");
}

fn las_bytes(compressed: bool, n: usize) -> Vec<u8> {
    let mut b = las::Builder::from((1, 2));
    b.point_format = las::point::Format::new(2).unwrap();
    b.point_format.is_compressed = compressed;
    let t = |offset| las::Transform {
        scale: 0.001,
        offset,
    };
    b.transforms = las::Vector {
        x: t(500_000.0),
        y: t(4_000_000.0),
        z: t(0.0),
    };
    let header = b.into_header().unwrap();
    let mut w = las::Writer::new(Cursor::new(Vec::new()), header).unwrap();
    for i in 0..n {
        w.write_point(las::Point {
            x: 500_000.0 + i as f64 * 0.01,
            y: 4_000_000.0 - i as f64 * 0.02,
            z: 12.5 + (i % 7) as f64,
            color: Some(las::Color::new((i * 257) as u16, 65535, 0)),
            ..Default::default()
        })
        .unwrap();
    }
    w.close().unwrap();
    w.into_inner().unwrap().into_inner()
}

#[test]
fn import_las_and_laz_keep_millimetres_far_from_the_origin() {
    for compressed in [false, true] {
        let bytes = las_bytes(compressed, 1000);
        let c = import_bytes(&bytes, LIMIT).unwrap();
        assert_eq!(c.len(), 1000, "compressed {compressed}");
        assert_eq!(c.origin, [500_000.0, 4_000_000.0 - 999.0 * 0.02, 12.5]);
        for (i, p) in c.positions.iter().enumerate() {
            let abs = [0, 1, 2].map(|a| c.origin[a] + f64::from(p[a]));
            assert!((abs[0] - (500_000.0 + i as f64 * 0.01)).abs() < 1e-4);
            assert!((abs[1] - (4_000_000.0 - i as f64 * 0.02)).abs() < 1e-4);
        }
        assert_eq!(c.colours.as_ref().unwrap()[3], [3, 255, 0]);
        // Over the limit.
        assert!(matches!(import_bytes(&bytes, 10), Err(Error::Limit(_))));
        // Truncated.
        assert!(import_bytes(&bytes[..bytes.len() / 2], LIMIT).is_err());
    }
}
