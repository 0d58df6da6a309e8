//! A glTF document's buffers: the GLB binary chunk, base64 `data:` URIs and
//! files beside the glTF (never outside its folder), loaded on first use
//! and checked against their declared `byteLength`.

use std::borrow::Cow;
use std::path::{Component, Path};

use gltf::buffer::Source;

use crate::{Error, Result};

/// The buffers of a document, loaded on first use.
pub(super) struct Buffers<'a> {
    pub(super) what: &'static str,
    pub(super) base: Option<&'a Path>,
    pub(super) bin: Option<&'a [u8]>,
    pub(super) loaded: Vec<Option<Cow<'a, [u8]>>>,
}

impl<'a> Buffers<'a> {
    pub(super) fn load(&mut self, buffer: &gltf::Buffer<'_>) -> Result<()> {
        let uri = match buffer.source() {
            Source::Bin => None,
            Source::Uri(uri) => Some(uri),
        };
        self.load_uri(buffer.index(), uri, buffer.length())
    }

    /// [`Self::load`] for a buffer of the JSON document, before it is
    /// validated (the decompression of `EXT_meshopt_compression` and
    /// `KHR_draco_mesh_compression` reads buffers then).
    pub(super) fn load_json(&mut self, i: usize, buffer: &gltf::json::Buffer) -> Result<()> {
        let length = usize::try_from(buffer.byte_length.0).unwrap_or(usize::MAX);
        self.load_uri(i, buffer.uri.as_deref(), length)
    }

    /// Buffer `i` is `data`, decoded from a compressed view or primitive.
    pub(super) fn preload(&mut self, i: usize, data: Vec<u8>) {
        if self.loaded.len() <= i {
            self.loaded.resize(i + 1, None);
        }
        self.loaded[i] = Some(Cow::Owned(data));
    }

    fn load_uri(&mut self, i: usize, uri: Option<&str>, length: usize) -> Result<()> {
        if self.loaded.get(i).is_some_and(|b| b.is_some()) {
            return Ok(());
        }
        let what = self.what;
        let data: Cow<'a, [u8]> = match uri {
            None => Cow::Borrowed(self.bin.ok_or_else(|| {
                Error::input(
                    what,
                    format!("buffer {i} refers to a GLB binary chunk that is absent"),
                )
            })?),
            Some(uri) if uri.starts_with("data:") => Cow::Owned(
                decode_data_uri(uri)
                    .map_err(|e| Error::input(what, format!("buffer {i}: bad data URI: {e}")))?,
            ),
            Some(uri) => {
                let Some(base) = self.base else {
                    return Err(Error::input(
                        what,
                        format!("buffer {i} is in the external file {uri:?}: import from a path to read it"),
                    ));
                };
                let rel = relative_uri_path(uri)
                    .map_err(|e| Error::input(what, format!("buffer {i}: uri {uri:?}: {e}")))?;
                let path = base.join(rel);
                Cow::Owned(std::fs::read(&path).map_err(|e| {
                    Error::Io(std::io::Error::new(
                        e.kind(),
                        format!("buffer {i} of the glTF file, {}: {e}", path.display()),
                    ))
                })?)
            }
        };
        if data.len() < length {
            return Err(Error::input(
                what,
                format!(
                    "truncated: buffer {i} holds {} bytes but declares byteLength {}",
                    data.len(),
                    length
                ),
            ));
        }
        if self.loaded.len() <= i {
            self.loaded.resize(i + 1, None);
        }
        self.loaded[i] = Some(data);
        Ok(())
    }

    pub(super) fn get(&self, i: usize) -> &[u8] {
        self.loaded.get(i).and_then(|b| b.as_deref()).unwrap_or(&[])
    }
}

pub(super) fn decode_data_uri(uri: &str) -> std::result::Result<Vec<u8>, String> {
    use base64::Engine as _;
    let (header, payload) = uri
        .split_once(',')
        .ok_or_else(|| "no ',' separator".to_string())?;
    if !header.ends_with(";base64") {
        return Err("only base64 data URIs are supported".to_string());
    }
    base64::engine::general_purpose::STANDARD
        .decode(payload.trim())
        .map_err(|e| e.to_string())
}

/// A relative URI reference to a file beside the glTF, percent-decoded.
/// Absolute paths, other schemes and `..` are refused: a glTF must not make
/// the importer read files outside its folder.
pub(super) fn relative_uri_path(uri: &str) -> std::result::Result<std::path::PathBuf, String> {
    let bytes = uri.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes
                .get(i + 1..i + 3)
                .and_then(|h| std::str::from_utf8(h).ok())
                .and_then(|h| u8::from_str_radix(h, 16).ok())
                .ok_or_else(|| "bad percent-escape".to_string())?;
            out.push(hex);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    let s = String::from_utf8(out).map_err(|_| "not UTF-8 after percent-decoding".to_string())?;
    if s.contains(':') || s.contains('\\') || s.contains('\0') {
        return Err("only relative file names are read".to_string());
    }
    let p = std::path::PathBuf::from(s);
    if p.components()
        .any(|c| !matches!(c, Component::Normal(_) | Component::CurDir))
    {
        return Err("must stay inside the glTF file's folder".to_string());
    }
    Ok(p)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uri_paths_stay_inside() {
        assert!(relative_uri_path("a%20b.bin").is_ok());
        assert_eq!(
            relative_uri_path("a%20b.bin").unwrap(),
            std::path::PathBuf::from("a b.bin")
        );
        assert!(relative_uri_path("../x.bin").is_err());
        assert!(relative_uri_path("/etc/passwd").is_err());
        assert!(relative_uri_path("http://x/y.bin").is_err());
        assert!(relative_uri_path("sub/%2e%2e/%2e%2e/x").is_err());
    }
}
