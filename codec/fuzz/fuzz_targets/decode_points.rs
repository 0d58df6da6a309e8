//! Point-stream bytes → `vitrine_points::stream::decode`, whole and level
//! by level: errors are fine, panics and inconsistent decoders are not.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vitrine_points::stream::{decode, split, Limits, PointDecoder};

const LIMITS: Limits = Limits {
    max_points: 1 << 20,
};

fn check(d: &PointDecoder) {
    let n = d.point_count();
    assert!(n <= d.header().points as usize);
    assert_eq!(d.quantized().len(), n);
    if let Some(normals) = d.normals() {
        assert_eq!(normals.len(), n);
    }
    if let Some(colours) = d.colours() {
        assert_eq!(colours.len(), n);
    }
    let max = 1u32 << d.header().bits;
    assert!(d.quantized().iter().flatten().all(|&v| v < max));
}

fuzz_target!(|data: &[u8]| {
    if let Ok(d) = decode(data, None, LIMITS) {
        check(&d);
        assert!(d.is_complete());
        assert_eq!(d.point_count(), d.header().points as usize);
    }
    let Ok((header, chunks)) = split(data) else {
        return;
    };
    let Ok(mut d) = PointDecoder::new(&data[..header.len()], LIMITS) else {
        return;
    };
    for range in &chunks {
        if d.apply_level(&data[range.clone()]).is_err() {
            return;
        }
        check(&d);
    }
});
