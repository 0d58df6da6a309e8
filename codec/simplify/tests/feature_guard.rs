//! The feature guard inside the progressive encoder: streams stay lossless,
//! features survive the coarse levels, and the guard composes with others.

use vitrine_codec::{
    decode, encode, EncodeOptions, Encoder, IndexedMesh, Limits, Quantization, StreamIndex,
};
use vitrine_samples::{add_noise, torus};
use vitrine_simplify::{FeatureGuard, FeatureThreshold};

/// A torus with a sharp groove cut around it: a feature line on a smooth body.
fn grooved_torus() -> IndexedMesh {
    grooved(96, 32, 0.06)
}

/// A torus of `rings × sides` with a V-groove `depth` deep along the band
/// |angle| < `depth`.
fn grooved(rings: u32, sides: u32, groove: f32) -> IndexedMesh {
    let mut mesh = torus(rings, sides, 1.0, 0.35);
    for p in &mut mesh.positions {
        let (x, y) = (p[0], p[1]);
        let angle = y.atan2(x);
        let depth = (groove - angle.abs()).max(0.0);
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

/// The search keeps the setting it says, and only one that fits: within
/// the budget, no higher image error (at its level and at equal vertices),
/// closer features, and the closest of those; its guard reproduces the
/// measured stream.
#[test]
fn the_search_keeps_the_closest_setting_within_the_budget() {
    use vitrine_simplify::{
        at_vertices, search_feature_guard, FeatureProbe, DEFAULT_CONNECTIVITY_BUDGET,
        SEARCHED_SETTINGS,
    };
    // 12 k vertices, a deep groove: on the 3 k torus above the first level
    // with 5 % of the vertices has 189, and no setting keeps its picture.
    let mesh = grooved(192, 64, 0.12);
    let options = EncodeOptions::default();
    let base = guard(&mesh, &options);
    let (chosen_guard, search) =
        search_feature_guard(&mesh, &options, &base, DEFAULT_CONNECTIVITY_BUDGET).unwrap();
    assert_eq!(search.tried.len(), SEARCHED_SETTINGS.len());
    let plain = search.plain;
    assert_eq!(
        plain,
        FeatureProbe::new(&mesh)
            .measure(&encode(&mesh, &options).unwrap().bytes)
            .unwrap()
    );
    let fits: Vec<usize> = (0..search.tried.len())
        .filter(|&k| {
            let m = &search.tried[k].1;
            let equal = at_vertices(&search.plain_images, m.vertices as f64);
            m.connectivity_bits as f64 <= 1.05 * plain.connectivity_bits as f64
                && m.image_rmse <= plain.image_rmse
                && (equal.is_nan() || m.image_rmse <= equal)
                && m.feature_rms < plain.feature_rms
        })
        .collect();
    // The groove is what the guard is for: some setting must fit.
    assert!(!fits.is_empty(), "{search:#?}");
    let best = fits
        .iter()
        .copied()
        .min_by(|&a, &b| {
            search.tried[a]
                .1
                .feature_rms
                .total_cmp(&search.tried[b].1.feature_rms)
        })
        .unwrap();
    assert_eq!(search.chosen, Some(best));
    let (_, chosen) = search.tried[best];
    let stream = Encoder::new(options.clone())
        .guard(chosen_guard.as_ref().unwrap())
        .encode(&mesh)
        .unwrap()
        .bytes;
    assert_eq!(FeatureProbe::new(&mesh).measure(&stream).unwrap(), chosen);
    assert!(
        chosen.feature_rms < 0.9 * plain.feature_rms,
        "{chosen:?} {plain:?}"
    );

    // With no room at all in the budget, nothing that costs bits fits.
    let (none, strict) = search_feature_guard(&mesh, &options, &base, 0.0).unwrap();
    match strict.choice() {
        Some((_, m)) => assert!(m.connectivity_bits <= plain.connectivity_bits),
        None => assert!(none.is_none()),
    }
}
