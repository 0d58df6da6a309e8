//! PLY files as old exporters write them: header lines ending in CR alone
//! (classic Mac OS) or CRLF (Windows).

use vitrine_mesh::import::{import_bytes, ImportOptions, MeshFormat};

fn opts() -> ImportOptions {
    ImportOptions::default()
}

/// PLY headers as old Mac (CR) and Windows (CRLF) exporters end their
/// lines: the same mesh as with LF, in ascii and binary (whose first body
/// byte here is 0x0A, a LF, right after a CR-terminated end_header).
#[test]
fn ply_headers_ending_in_cr_or_crlf_read_like_lf() {
    let header = |eol: &str, format: &str, faces: usize| {
        [
            "ply",
            &format!("format {format} 1.0"),
            "comment from an old exporter",
            "element vertex 3",
            "property float x",
            "property float y",
            "property float z",
            &format!("element face {faces}"),
            "property list uchar int vertex_indices",
            "end_header",
            "",
        ]
        .join(eol)
    };
    let want = vitrine_codec::IndexedMesh {
        positions: vec![[2.5, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
        colors: None,
        triangles: vec![[0, 1, 2]],
    };
    for eol in ["\n", "\r\n", "\r"] {
        let ascii =
            header(eol, "ascii", 1) + &["2.5 0 0", "1 0 0", "0 1 0", "3 0 1 2", ""].join(eol);
        let got = import_bytes(ascii.as_bytes(), MeshFormat::Ply, &opts())
            .unwrap_or_else(|e| panic!("{eol:?} ascii: {e}"));
        assert_eq!(got, want, "{eol:?} ascii");
        assert_eq!(MeshFormat::sniff(ascii.as_bytes()), Some(MeshFormat::Ply));
        let mut binary = header(eol, "binary_little_endian", 1).into_bytes();
        // The body's first byte is 0x0A (a LF) right after end_header.
        let x = f32::from_le_bytes([0x0A, 0, 0x20, 0x40]);
        for p in [[x, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
            for c in p {
                binary.extend_from_slice(&c.to_le_bytes());
            }
        }
        binary.push(3);
        for v in [0i32, 1, 2] {
            binary.extend_from_slice(&v.to_le_bytes());
        }
        let got = import_bytes(&binary, MeshFormat::Ply, &opts())
            .unwrap_or_else(|e| panic!("{eol:?} binary: {e}"));
        assert_eq!(got.positions[0][0].to_bits(), x.to_bits(), "{eol:?} binary");
        assert_eq!(got.triangles, want.triangles);
    }
}
