//! The feature guard inside the progressive encoder: streams stay lossless,
//! features survive the coarse levels, and the guard composes with others.

use vitrine_codec::{
    decode, encode, EncodeOptions, Encoder, IndexedMesh, Limits, Quantization, StreamIndex,
};
use vitrine_samples::{add_noise, torus};
use vitrine_simplify::{FeatureGuard, FeatureThreshold};

/// A torus with a sharp groove cut around it: a feature line on a smooth body.
fn grooved_torus() -> IndexedMesh {
    let mut mesh = torus(96, 32, 1.0, 0.35);
    for p in &mut mesh.positions {
        let (x, y) = (p[0], p[1]);
        let angle = y.atan2(x);
        // A V-groove 0.06 deep along the band |angle| < 0.06.
        let depth = (0.06 - angle.abs()).max(0.0);
        let r = (x * x + y * y).sqrt();
        let scale = (r - depth) / r;
        p[0] *= scale;
        p[1] *= scale;
    }
    add_noise(&mut mesh, 0.0005, 3);
    mesh
}

fn guard(mesh: &IndexedMesh, options: &EncodeOptions) -> FeatureGuard {
    let q = Quantization::for_positions(&mesh.positions, options.quantization_bits).unwrap();
    FeatureGuard::new(mesh, &q, FeatureThreshold::MeanPlusTwoSigma)
}

#[test]
fn a_guarded_stream_decodes_losslessly() {
    let mesh = grooved_torus();
    let options = EncodeOptions::default();
    let g = guard(&mesh, &options);
    assert!(g.feature_vertices() > 0);
    let encoded = Encoder::new(options.clone())
        .guard(&g)
        .encode(&mesh)
        .unwrap();
    let d = decode(&encoded.bytes, None, Limits::default()).unwrap();
    assert_eq!(
        vitrine_samples::final_level_mismatch(
            &mesh,
            options.quantization_bits,
            &d,
            &encoded.vertex_order
        ),
        None
    );
    assert_ne!(
        encoded.bytes,
        encode(&mesh, &options).unwrap().bytes,
        "the guard refused patches"
    );
}

/// The guard holds feature vertices back: after the first batch the
/// guarded stream has more than twice as many of them as the plain one.
#[test]
fn feature_vertices_stay_in_the_coarse_levels() {
    let mesh = grooved_torus();
    let options = EncodeOptions::default();
    let q = Quantization::for_positions(&mesh.positions, options.quantization_bits).unwrap();
    let g = guard(&mesh, &options);
    let features: std::collections::HashSet<[i32; 3]> = {
        let theta = vitrine_simplify::normal_deviation(&mesh);
        let ring = vitrine_simplify::one_ring_max(&mesh, &theta);
        let t = g.threshold_radians();
        mesh.positions
            .iter()
            .zip(&ring)
            .filter(|(_, &r)| r > t)
            .map(|(&p, _)| q.quantize(p))
            .collect()
    };
    let kept_at = |bytes: &[u8], level: usize| {
        let index = StreamIndex::parse(bytes).unwrap();
        let mut d =
            vitrine_codec::Decoder::new(&bytes[index.base.clone()], Limits::default()).unwrap();
        for range in &index.batches[..level] {
            d.apply_batch(&bytes[range.clone()]).unwrap();
        }
        d.quantized_positions()
            .iter()
            .filter(|p| features.contains(*p))
            .count()
    };
    let guarded = Encoder::new(options.clone())
        .guard(&g)
        .encode(&mesh)
        .unwrap()
        .bytes;
    let plain = encode(&mesh, &options).unwrap().bytes;
    let (kept_guarded, kept_plain) = (kept_at(&guarded, 1), kept_at(&plain, 1));
    assert!(
        kept_guarded > 2 * kept_plain,
        "feature vertices after one batch: guarded {kept_guarded}, plain {kept_plain}"
    );
}
