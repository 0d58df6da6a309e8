//! JSON answers built once and kept compressed, one copy per coding. The
//! compression layer compresses every answer again on every request; for
//! the part index of a 20 M-vertex scan (553 KB of JSON, 43 KB in gzip)
//! that is milliseconds of CPU a visitor, so the index is compressed once
//! per coding and sent with its `Content-Encoding` (which the layer then
//! leaves alone).

use axum::http::{header, HeaderMap, HeaderValue};
use bytes::Bytes;
use std::io::Write;
use std::sync::OnceLock;

/// A content coding the service sends precompressed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Coding {
    Brotli,
    Gzip,
    Identity,
}

impl Coding {
    fn token(self) -> Option<&'static str> {
        match self {
            Coding::Brotli => Some("br"),
            Coding::Gzip => Some("gzip"),
            Coding::Identity => None,
        }
    }
}

/// The coding to answer `Accept-Encoding` with: the one of brotli and
/// gzip with the higher weight (brotli on a tie, `*` standing for either),
/// none where both weigh 0 or the header is absent.
pub fn preferred(headers: &HeaderMap) -> Coding {
    let mut weights = [None::<f32>; 3]; // br, gzip, *
    for value in headers.get_all(header::ACCEPT_ENCODING) {
        let Ok(value) = value.to_str() else { continue };
        for item in value.split(',') {
            let mut fields = item.split(';');
            let name = fields.next().unwrap_or("").trim().to_ascii_lowercase();
            let q = fields
                .filter_map(|f| f.trim().strip_prefix("q="))
                .find_map(|q| q.trim().parse::<f32>().ok())
                .unwrap_or(1.0);
            let slot = match name.as_str() {
                "br" => 0,
                "gzip" | "x-gzip" => 1,
                "*" => 2,
                _ => continue,
            };
            weights[slot] = Some(q);
        }
    }
    let br = weights[0].or(weights[2]).unwrap_or(0.0);
    let gzip = weights[1].or(weights[2]).unwrap_or(0.0);
    if br > 0.0 && br >= gzip {
        Coding::Brotli
    } else if gzip > 0.0 {
        Coding::Gzip
    } else {
        Coding::Identity
    }
}

/// One answer's body, serialized on first use, and its compressed copies
/// once asked for.
#[derive(Debug, Default)]
pub struct Precompressed {
    body: OnceLock<Bytes>,
    brotli: OnceLock<Bytes>,
    gzip: OnceLock<Bytes>,
}

impl Precompressed {
    /// The body in `coding`, if it was already made: what a request task
    /// may take without blocking.
    pub fn ready(&self, coding: Coding) -> Option<Bytes> {
        match coding {
            Coding::Identity => &self.body,
            Coding::Gzip => &self.gzip,
            Coding::Brotli => &self.brotli,
        }
        .get()
        .cloned()
    }

    /// The body in `coding`: made by `make` and compressed on the first
    /// call for that coding. Brotli of a large index takes some 0.1 s, so
    /// call this where blocking is allowed (`spawn_blocking`).
    pub fn encoded<E>(
        &self,
        coding: Coding,
        make: impl FnOnce() -> Result<Bytes, E>,
    ) -> Result<Bytes, E> {
        let body = match self.body.get() {
            Some(body) => body.clone(),
            None => {
                let made = make()?;
                self.body.get_or_init(|| made).clone()
            }
        };
        Ok(match coding {
            Coding::Identity => body,
            Coding::Gzip => self.gzip.get_or_init(|| gzip(&body)).clone(),
            Coding::Brotli => self.brotli.get_or_init(|| brotli(&body)).clone(),
        })
    }
}

/// The headers of a body sent in `coding`: its `Content-Encoding`, and
/// `Vary: Accept-Encoding` either way (a cache keeps one copy per coding).
pub fn coding_headers(coding: Coding, headers: &mut HeaderMap) {
    if let Some(token) = coding.token() {
        headers.insert(header::CONTENT_ENCODING, HeaderValue::from_static(token));
    }
    headers.append(header::VARY, HeaderValue::from_static("accept-encoding"));
}

fn gzip(body: &[u8]) -> Bytes {
    let mut out = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::best());
    out.write_all(body).expect("writing to memory");
    Bytes::from(out.finish().expect("writing to memory"))
}

/// Brotli at quality 9, a 4 MiB window: within a few percent of quality 11
/// on JSON, at a fraction of its time.
fn brotli(body: &[u8]) -> Bytes {
    let mut out = Vec::new();
    {
        let mut w = brotli::CompressorWriter::new(&mut out, 64 * 1024, 9, 22);
        w.write_all(body).expect("writing to memory");
    }
    Bytes::from(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn accepting(value: &str) -> HeaderMap {
        let mut h = HeaderMap::new();
        h.insert(
            header::ACCEPT_ENCODING,
            HeaderValue::from_str(value).unwrap(),
        );
        h
    }

    #[test]
    fn the_coding_follows_the_weights() {
        assert_eq!(preferred(&HeaderMap::new()), Coding::Identity);
        assert_eq!(
            preferred(&accepting("gzip, deflate, br, zstd")),
            Coding::Brotli
        );
        assert_eq!(preferred(&accepting("gzip, deflate")), Coding::Gzip);
        assert_eq!(preferred(&accepting("br;q=0, gzip")), Coding::Gzip);
        assert_eq!(preferred(&accepting("br;q=0.5, GZIP;q=0.8")), Coding::Gzip);
        assert_eq!(preferred(&accepting("*")), Coding::Brotli);
        assert_eq!(preferred(&accepting("*;q=0")), Coding::Identity);
        assert_eq!(preferred(&accepting("identity, deflate")), Coding::Identity);
    }

    #[test]
    fn copies_decode_to_the_body_and_are_made_once() {
        let body = Bytes::from(br#"{"parts":[1,2,3,1,2,3,1,2,3,1,2,3]}"#.repeat(200));
        let kept = Precompressed::default();
        assert_eq!(kept.ready(Coding::Identity), None);
        let made = || Ok::<_, ()>(body.clone());
        let gz = kept.encoded(Coding::Gzip, made).unwrap();
        assert_eq!(kept.ready(Coding::Brotli), None);
        let br = kept.encoded(Coding::Brotli, made).unwrap();
        assert!(gz.len() < body.len() / 10 && br.len() < body.len() / 10);
        let mut plain = Vec::new();
        std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(&gz[..]), &mut plain).unwrap();
        assert_eq!(plain, body);
        plain.clear();
        std::io::Read::read_to_end(&mut brotli::Decompressor::new(&br[..], 4096), &mut plain)
            .unwrap();
        assert_eq!(plain, body);
        // The same bytes, not made or compressed again.
        let never = || Err::<Bytes, _>("made twice");
        assert_eq!(
            kept.encoded(Coding::Gzip, never).unwrap().as_ptr(),
            gz.as_ptr()
        );
        assert_eq!(kept.ready(Coding::Brotli).unwrap().as_ptr(), br.as_ptr());
        assert_eq!(kept.encoded(Coding::Identity, never).unwrap(), body);
    }
}
