//! The bit budget (`vitrine_codec::bit_budget`): what its shadow models
//! count is what the stream's range coders spent.

use vitrine_codec::{bit_budget, encode, Charts, EncodeOptions, StreamIndex};
use vitrine_samples::{add_noise, torus};

#[test]
fn metered_geometry_is_what_the_range_coder_spent() {
    let mut mesh = torus(80, 30, 1.0, 0.3);
    add_noise(&mut mesh, 0.003, 5);
    let encoded = encode(&mesh, &EncodeOptions::default()).unwrap();
    let passes = bit_budget(&encoded.bytes).unwrap();
    let index = StreamIndex::parse(&encoded.bytes).unwrap();
    let levels = &index.header.levels;
    let inserted: u32 = passes.iter().map(|p| p.inserted).sum();
    assert_eq!(
        inserted,
        levels.last().unwrap().vertices - levels[0].vertices
    );
    assert!(passes.iter().any(|p| p.inserted > 300));
    for p in passes.iter().filter(|p| p.inserted > 0) {
        let metered = p.geometry_bits.iter().sum::<f64>() / 8.0;
        // The coder's flush adds up to 4 bytes; it never spends less than
        // the information (to rounding of its 32-bit range).
        let stored = p.geometry_bytes as f64;
        assert!(
            stored >= metered * 0.995 - 1.0 && stored <= metered * 1.005 + 5.0,
            "batch {} ({} vertices): {stored} bytes stored, {metered:.1} metered",
            p.batch,
            p.inserted
        );
        // Every component carries information, the normal least on a
        // smooth torus.
        assert!(p.geometry_bits.iter().all(|&b| b > 0.0), "{p:?}");
        // The trials price the same residuals: the baseline's own
        // correction (3/8) is among them and agrees to the bit.
        let own = p.trials.iter().find(|t| t.0 == "curvature 3/8").unwrap();
        assert!((own.1 - p.geometry_bits.iter().sum::<f64>()).abs() < 1e-6);
    }
}

#[test]
fn a_charted_stream_is_refused_with_a_reason() {
    let mesh = torus(120, 60, 1.0, 0.3);
    let options = EncodeOptions {
        charts: Charts::Count(2),
        ..EncodeOptions::default()
    };
    let encoded = encode(&mesh, &options).unwrap();
    let error = bit_budget(&encoded.bytes).unwrap_err().to_string();
    assert!(error.contains("charted"), "{error}");
}

#[test]
fn a_truncated_stream_is_an_error_not_a_panic() {
    let mesh = torus(40, 20, 1.0, 0.3);
    let encoded = encode(&mesh, &EncodeOptions::default()).unwrap();
    for cut in [10, encoded.bytes.len() / 2, encoded.bytes.len() - 3] {
        assert!(bit_budget(&encoded.bytes[..cut]).is_err());
    }
}
