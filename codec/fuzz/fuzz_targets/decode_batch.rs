//! A valid header and base (from `encode` of a generated mesh), then
//! fuzzed bytes as batch 1; when that decodes, the real batch 2 must still
//! give an error or a consistent decoder.
//!
//! Input: one selector byte, then the bytes. Selector bit 0 picks the mesh
//! (bit 1 clear: the bytes are batch 1's payload, wrapped by the stream's own
//! chunk writer in batch 1's header with the payload length replaced, so the
//! fuzzer works on the passes; bit 1 set: the bytes are the whole chunk,
//! header included). `wrapped_batches_decode` checks once, before any
//! input, that an unmodified wrapped payload decodes.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_codec::{BatchChunk, Decoder, StreamIndex};
use vitrine_codec_fuzz::{check_decoder, sample_streams, wrapped_batches_decode, LIMITS};

fuzz_target!(|data: &[u8]| {
    let Some((&selector, bytes)) = data.split_first() else {
        return;
    };
    wrapped_batches_decode();
    let streams = sample_streams();
    let stream = &streams[selector as usize % streams.len()];
    let index = StreamIndex::parse(stream).expect("sample stream");
    let mut d = Decoder::new(&stream[index.base.clone()], LIMITS).expect("sample base");
    let chunk = if selector & 2 == 0 {
        let real = BatchChunk::parse(&stream[index.batches[0].clone()]).expect("sample batch");
        real.with_payload(bytes).expect("a fuzz input under 4 GiB")
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
