//! A valid header and base (from `encode` of a generated mesh), then
//! fuzzed bytes as batch 1; when that decodes, the real batch 2 must still
//! give an error or a consistent decoder.
//!
//! Input: one selector byte, then the bytes. Selector bit 0 picks the mesh
//! (bit 1 clear: the bytes are batch 1's payload, wrapped in a chunk header
//! with the right counts, so the fuzzer works on the passes; bit 1 set: the
//! bytes are the whole chunk, header included).
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_codec::{Decoder, StreamIndex};
use vitrine_codec_fuzz::{check_decoder, sample_streams, LIMITS};

fuzz_target!(|data: &[u8]| {
    let Some((&selector, bytes)) = data.split_first() else {
        return;
    };
    let streams = sample_streams();
    let stream = &streams[selector as usize % streams.len()];
    let index = StreamIndex::parse(stream).expect("sample stream");
    let mut d = Decoder::new(&stream[index.base.clone()], LIMITS).expect("sample base");
    let chunk = if selector & 2 == 0 {
        // Chunk header of the real batch 1 with the payload length replaced.
        let real = &stream[index.batches[0].clone()];
        let mut chunk = real[..20].to_vec();
        chunk[16..20].copy_from_slice(&(bytes.len() as u32).to_le_bytes());
        chunk.extend_from_slice(bytes);
        chunk
    } else {
        bytes.to_vec()
    };
    if d.apply_batch(&chunk).is_err() {
        return;
    }
    check_decoder(&d);
    if let Some(next) = index.batches.get(1) {
        if d.apply_batch(&stream[next.clone()]).is_ok() {
            check_decoder(&d);
        }
    }
});
