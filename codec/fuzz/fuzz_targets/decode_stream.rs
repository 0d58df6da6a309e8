//! Whole stream bytes → `decode`, and the same bytes through the incremental API.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_codec::{decode, Decoder, StreamIndex};
use vitrine_codec_fuzz::{check_decoder, LIMITS};

fuzz_target!(|data: &[u8]| {
    if let Ok(d) = decode(data, None, LIMITS) {
        check_decoder(&d);
        assert!(d.is_complete());
        // A charted stream's charts on two threads: the same level.
        let index = StreamIndex::parse(data).expect("decoded");
        let mut t = Decoder::new(&data[index.base.clone()], LIMITS).expect("decoded");
        t.set_threads(2);
        for range in &index.batches {
            t.apply_batch(&data[range.clone()]).expect("decoded on one thread");
        }
        assert_eq!(t.indices(), d.indices());
        assert_eq!(t.quantized_positions(), d.quantized_positions());
    }
    // Batch by batch, checking every level reached.
    let Ok(index) = StreamIndex::parse(data) else {
        return;
    };
    let Ok(mut d) = Decoder::new(&data[index.base.clone()], LIMITS) else {
        return;
    };
    check_decoder(&d);
    for range in &index.batches {
        if d.apply_batch(&data[range.clone()]).is_err() {
            return;
        }
        check_decoder(&d);
    }
});
