//! The GLB container (JSON and BIN chunks, every length checked) and the
//! glTF JSON document, parsed and validated by the `gltf` crate.

use super::super::MeshFormat;
use crate::{Error, Result};

/// Splits a GLB container into its JSON chunk and optional BIN chunk.
fn split_glb<'a>(bytes: &'a [u8], what: &'static str) -> Result<(&'a [u8], Option<&'a [u8]>)> {
    let u32_at = |p: usize| -> Option<u32> {
        let b = bytes.get(p..p.checked_add(4)?)?;
        Some(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    };
    let (Some(version), Some(length)) = (u32_at(4), u32_at(8)) else {
        return Err(Error::input(
            what,
            "truncated: shorter than the 12-byte GLB header",
        ));
    };
    if version != 2 {
        return Err(Error::Unsupported(format!(
            "{what}: GLB version {version} (only glTF 2.0 is read)"
        )));
    }
    let length = length as usize;
    if length > bytes.len() {
        return Err(Error::input(
            what,
            format!(
                "truncated: the header says {length} bytes but the file has {}",
                bytes.len()
            ),
        ));
    }
    let mut pos = 12usize;
    let (mut json, mut bin) = (None, None);
    while pos < length {
        let (Some(len), Some(kind)) = (u32_at(pos), u32_at(pos + 4)) else {
            return Err(Error::input(
                what,
                format!("truncated chunk header at byte {pos}"),
            ));
        };
        let start = pos + 8;
        let end = start
            .checked_add(len as usize)
            .filter(|&e| e <= length)
            .ok_or_else(|| {
                Error::input(
                    what,
                    format!("truncated: chunk at byte {pos} declares {len} bytes, past the end"),
                )
            })?;
        let data = &bytes[start..end];
        match &kind.to_le_bytes() {
            b"JSON" if json.is_none() => json = Some(data),
            b"BIN\0" if bin.is_none() && json.is_some() => bin = Some(data),
            _ => {} // unknown chunks are skipped
        }
        pos = end;
    }
    let json = json.ok_or_else(|| Error::input(what, "has no JSON chunk"))?;
    Ok((json, bin))
}

fn gltf_error(e: gltf::Error, what: &'static str) -> Error {
    if let gltf::Error::Validation(list) = &e {
        let unsupported = list
            .iter()
            .any(|(_, e)| matches!(e, gltf::json::validation::Error::Unsupported));
        let detail = list
            .iter()
            .take(5)
            .map(|(path, e)| format!("{path}: {e}"))
            .collect::<Vec<_>>()
            .join("; ");
        if unsupported {
            return Error::Unsupported(format!("{what}: {detail}"));
        }
        return Error::input(what, format!("invalid glTF: {detail}"));
    }
    Error::input(what, e)
}

/// gltf-json 1.4's validation reads a primitive's `POSITION` accessor
/// before checking that it exists, and panics on an index past the end of
/// `accessors`: refuse such documents before validating them.
fn check_attribute_accessors(root: &gltf::json::Root, what: &'static str) -> Result<()> {
    for (m, mesh) in root.meshes.iter().enumerate() {
        for (p, prim) in mesh.primitives.iter().enumerate() {
            for index in prim.attributes.values() {
                if index.value() >= root.accessors.len() {
                    return Err(Error::input(
                        what,
                        format!(
                            "invalid glTF: mesh {m} primitive {p} uses accessor {} but there are {}",
                            index.value(),
                            root.accessors.len()
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// The JSON document of a `.gltf` or GLB file, not yet validated (the
/// compressed views and primitives are decoded into it first), and the
/// GLB's binary chunk.
pub(super) fn parse_root<'a>(
    bytes: &'a [u8],
    format: MeshFormat,
    what: &'static str,
) -> Result<(gltf::json::Root, Option<&'a [u8]>)> {
    let (json, bin) = if bytes.starts_with(b"glTF") {
        split_glb(bytes, what)?
    } else if format == MeshFormat::Glb {
        return Err(Error::input(what, "not a GLB file (no glTF magic)"));
    } else {
        (bytes, None)
    };
    if json.iter().all(|b| b.is_ascii_whitespace()) {
        return Err(Error::input(what, "is empty"));
    }
    let mut root = gltf::json::Root::from_slice(json)
        .map_err(|e| gltf_error(gltf::Error::Deserialize(e), what))?;
    super::extensions::accept_required(&mut root, what)?;
    Ok((root, bin))
}

/// The document, validated by the `gltf` crate.
pub(super) fn validate(root: gltf::json::Root, what: &'static str) -> Result<gltf::Document> {
    check_attribute_accessors(&root, what)?;
    gltf::Document::from_json(root).map_err(|e| gltf_error(e, what))
}

#[cfg(test)]
mod tests {
    use super::super::read;
    use crate::import::{ImportOptions, MeshFormat};

    #[test]
    fn glb_container_errors() {
        let o = ImportOptions::default();
        let e = read(b"glTF\x02\0\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("12-byte"), "{e}");
        let e = read(b"glTF\x02\0\0\0\x00\x01\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("truncated"), "{e}");
        let e = read(b"glTF\x02\0\0\0\x0b\0\0\0", MeshFormat::Glb, None, &o).unwrap_err();
        assert!(e.to_string().contains("no JSON chunk"), "{e}");
    }
}
