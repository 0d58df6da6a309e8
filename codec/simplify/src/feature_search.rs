//! Choosing the feature guard's setting per scan.
//!
//! No one setting of the guard (the share of a level features may hold,
//! and the relief gate) keeps features best on every scan within the
//! issue's budget: on the 13 shared scans the best fixed setting cuts the
//! features' RMS distance by 30.6 % on average but costs one scan (an 8 k
//! vertex bust) +8.2 % connectivity, and raises the image error on three
//! (docs/bench-log/2026-12-02-session-13-guard.md). The encoder has the
//! original, so it can measure what the setting buys on this very scan and
//! pick: [`search_feature_guard`] encodes the scan unguarded and under each
//! of [`SEARCHED_SETTINGS`], and keeps the setting whose first level with
//! at least 5 % of the vertices lies nearest the original's sharpest
//! vertices, among those that cost at most the budget in connectivity over
//! the whole stream and do not raise that level's 24-view image error.
//! When none qualifies the guard declines, and the stream is byte for byte
//! the unguarded one.
//!
//! Cost: one encode and one level's measurement per setting, plus the
//! plain stream's (nine encodes in all): on the 2-core VM 0.3–2 s for the
//! shared scans up to 50 k vertices, 3.6–4.4 s for igea (134 k).

use glam::DVec3;

use vitrine_codec::{
    breakdown, Decoder, EncodeOptions, Encoder, IndexedMesh, Limits, Result, StreamIndex,
};
use vitrine_quality::metrics::{
    distances_to_surface, ConstantColour, ImageReference, RenderOptions,
};

use crate::{normal_deviation, FeatureGuard, FeatureThreshold};

/// One setting of [`FeatureGuard`]: [`FeatureGuard::with_share`] and
/// [`FeatureGuard::with_relief_gate`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GuardSetting {
    pub share: f64,
    pub relief_gate: Option<f64>,
}

impl std::fmt::Display for GuardSetting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.relief_gate {
            Some(g) => write!(f, "share {}, relief gate {g}", self.share),
            None => write!(f, "share {}, no relief gate", self.share),
        }
    }
}

const fn setting(share: f64, gate: f64) -> GuardSetting {
    GuardSetting {
        share,
        relief_gate: Some(gate),
    }
}

/// The settings tried, most protective first: the ones that were best on
/// some shared scan in session 16's sweep of twelve
/// (docs/bench-log/2026-12-03-session-16-guard.md), and the fixed default.
pub const SEARCHED_SETTINGS: [GuardSetting; 8] = [
    setting(1.0, 0.3),
    setting(0.3, 0.2),
    setting(0.2, 0.2),
    setting(0.5, 0.3),
    setting(0.3, 0.3),
    setting(0.15, 0.3),
    setting(0.3, 0.4),
    setting(0.3, 0.5),
];

/// The connectivity a guarded stream may cost over the unguarded one, by
/// default (issue 18: at most 5 % more over the whole stream).
pub const DEFAULT_CONNECTIVITY_BUDGET: f64 = 0.05;

/// What one stream gives at its first level with at least 5 % of the
/// vertices, and what its connectivity costs over every level.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LevelMeasure {
    /// That level's index (0: the base mesh).
    pub level: usize,
    pub vertices: usize,
    /// RMS distance from the original's top-5 %-θ vertices to the level's
    /// surface, in the mesh's units.
    pub feature_rms: f64,
    /// Luma RMSE over the 24 views, clay-shaded, 256² pixels.
    pub image_rmse: f64,
    /// Connectivity bits of the whole stream (codes, seeds, framing).
    pub connectivity_bits: u64,
}

/// The yardsticks of one scan, built once: its sharpest vertices and its
/// 24 pictures.
pub struct FeatureProbe {
    features: Vec<DVec3>,
    images: ImageReference,
    vertices: usize,
}

impl FeatureProbe {
    /// `mesh` as the encoder gets it (repaired).
    pub fn new(mesh: &IndexedMesh) -> Self {
        let theta = normal_deviation(mesh);
        let cut = FeatureThreshold::Percentile(95.0).radians(&theta);
        let features = mesh
            .positions
            .iter()
            .zip(&theta)
            .filter(|(_, &t)| t >= cut)
            .map(|(p, _)| DVec3::from(p.map(f64::from)))
            .collect();
        let geometry = IndexedMesh {
            colors: None,
            ..mesh.clone()
        };
        FeatureProbe {
            features,
            images: ImageReference::new(
                &geometry,
                &ConstantColour::CLAY,
                &RenderOptions::square(256),
            ),
            vertices: mesh.positions.len(),
        }
    }

    /// The original's top-5 %-θ vertices.
    pub fn features(&self) -> &[DVec3] {
        &self.features
    }

    /// RMS distance from the features to `level`'s surface.
    pub fn feature_rms(&self, level: &IndexedMesh) -> f64 {
        let d = distances_to_surface(&self.features, level);
        (d.iter().map(|x| x * x).sum::<f64>() / d.len().max(1) as f64).sqrt()
    }

    /// `level`'s 24-view image error against the original.
    pub fn image_rmse(&self, level: &IndexedMesh) -> f64 {
        self.images.rmse(level, &ConstantColour::CLAY)
    }

    /// `stream` (of this scan) measured at its first level with at least
    /// 5 % of the scan's vertices.
    pub fn measure(&self, stream: &[u8]) -> Result<LevelMeasure> {
        let (level, mesh) = first_level_with(stream, self.vertices.div_ceil(20))?;
        let connectivity_bits = breakdown(stream)?
            .iter()
            .map(|l| 8 * u64::from(l.connectivity))
            .sum();
        Ok(LevelMeasure {
            level,
            vertices: mesh.positions.len(),
            feature_rms: self.feature_rms(&mesh),
            image_rmse: self.image_rmse(&mesh),
            connectivity_bits,
        })
    }
}

/// The first level of `stream` with at least `vertices` vertices (the
/// finest when none has), decoded, with its index.
pub fn first_level_with(stream: &[u8], vertices: usize) -> Result<(usize, IndexedMesh)> {
    let index = StreamIndex::parse(stream)?;
    let levels = &index.header.levels;
    let level = levels
        .iter()
        .position(|l| l.vertices as usize >= vertices)
        .unwrap_or(levels.len().saturating_sub(1));
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    for range in index.batches.iter().take(level) {
        decoder.apply_batch(&stream[range.clone()])?;
    }
    Ok((level, decoded_mesh(&decoder)))
}

/// The decoder's current level as a mesh (no colour).
pub fn decoded_mesh(decoder: &Decoder) -> IndexedMesh {
    IndexedMesh {
        positions: decoder
            .positions()
            .chunks_exact(3)
            .map(|p| [p[0], p[1], p[2]])
            .collect(),
        colors: None,
        triangles: decoder
            .indices()
            .chunks_exact(3)
            .map(|t| [t[0], t[1], t[2]])
            .collect(),
    }
}

/// `f` of every level of `stream` with 2–20 % of `full` vertices, as
/// (vertices, value): to compare streams whose levels do not line up.
pub fn level_curve(
    stream: &[u8],
    full: usize,
    mut f: impl FnMut(&IndexedMesh) -> f64,
) -> Result<Vec<(f64, f64)>> {
    let index = StreamIndex::parse(stream)?;
    let mut decoder = Decoder::new(&stream[index.base.clone()], Limits::default())?;
    let mut points = Vec::new();
    for (level, info) in index.header.levels.iter().enumerate() {
        if level > 0 {
            decoder.apply_batch(&stream[index.batches[level - 1].clone()])?;
        }
        let n = info.vertices as usize;
        if n * 50 >= full && n * 5 <= full {
            points.push((n as f64, f(&decoded_mesh(&decoder))));
        }
    }
    Ok(points)
}

/// `points` (vertices, value) read at `vertices`, linear in log–log
/// between its neighbours, clamped to its ends (NaN when empty).
pub fn at_vertices(points: &[(f64, f64)], vertices: f64) -> f64 {
    let Some(&first) = points.first() else {
        return f64::NAN;
    };
    if vertices <= first.0 {
        return first.1;
    }
    for w in points.windows(2) {
        let ((n0, r0), (n1, r1)) = (w[0], w[1]);
        if vertices == n1 {
            return r1;
        }
        if vertices < n1 {
            let t = (vertices.ln() - n0.ln()) / (n1.ln() - n0.ln());
            return (r0.ln() + t * (r1.ln() - r0.ln())).exp();
        }
    }
    points.last().map_or(f64::NAN, |l| l.1)
}

/// What [`search_feature_guard`] tried and chose.
#[derive(Clone, Debug)]
pub struct GuardSearch {
    pub plain: LevelMeasure,
    /// The plain stream's image error at its levels with 2–20 % of the
    /// vertices, as (vertices, image RMSE).
    pub plain_images: Vec<(f64, f64)>,
    /// Every setting tried, in [`SEARCHED_SETTINGS`]' order.
    pub tried: Vec<(GuardSetting, LevelMeasure)>,
    /// Index into `tried` of the setting kept; `None`: the guard declines.
    pub chosen: Option<usize>,
    pub budget: f64,
}

impl GuardSearch {
    /// The setting kept and its measure.
    pub fn choice(&self) -> Option<&(GuardSetting, LevelMeasure)> {
        self.chosen.map(|k| &self.tried[k])
    }

    /// Whether `m` fits the budget and keeps the picture: its image error
    /// is no higher than the plain stream's at its own first level with
    /// 5 % of the vertices, nor than the plain stream's at `m`'s vertex
    /// count (where the plain stream has levels there to compare).
    fn qualifies(&self, m: &LevelMeasure) -> bool {
        let plain = &self.plain;
        m.connectivity_bits as f64 <= plain.connectivity_bits as f64 * (1.0 + self.budget)
            && m.image_rmse <= plain.image_rmse
            && {
                // NaN where the plain stream has no level there to compare.
                let equal = at_vertices(&self.plain_images, m.vertices as f64);
                equal.is_nan() || m.image_rmse <= equal
            }
            && m.feature_rms < plain.feature_rms
    }
}

/// Measures the guard at each of [`SEARCHED_SETTINGS`] on `mesh` (repaired,
/// as the encoder gets it) and returns the guard to encode with, if one
/// qualifies (see the module's notes). Only geometry is encoded here: the
/// guard keeps or removes vertices, whatever their colour.
///
/// `base` is the guard built for `mesh` with the stream's quantization
/// (`FeatureGuard::new`); each setting is a copy of it, so θ is not
/// computed again.
pub fn search_feature_guard(
    mesh: &IndexedMesh,
    options: &EncodeOptions,
    base: &FeatureGuard,
    budget: f64,
) -> Result<(Option<FeatureGuard>, GuardSearch)> {
    let geometry = IndexedMesh {
        colors: None,
        ..mesh.clone()
    };
    let probe = FeatureProbe::new(&geometry);
    let plain_stream = Encoder::new(options.clone()).encode(&geometry)?.bytes;
    let plain = probe.measure(&plain_stream)?;
    let plain_images = level_curve(&plain_stream, probe.vertices, |m| probe.image_rmse(m))?;
    let mut search = GuardSearch {
        plain,
        plain_images,
        tried: Vec::with_capacity(SEARCHED_SETTINGS.len()),
        chosen: None,
        budget: budget.max(0.0),
    };
    for s in SEARCHED_SETTINGS {
        let guard = base
            .clone()
            .with_share(s.share)
            .with_relief_gate(s.relief_gate);
        let stream = Encoder::new(options.clone())
            .guard(&guard)
            .encode(&geometry)?
            .bytes;
        search.tried.push((s, probe.measure(&stream)?));
    }
    search.chosen = (0..search.tried.len())
        .filter(|&k| search.qualifies(&search.tried[k].1))
        .min_by(|&a, &b| {
            search.tried[a]
                .1
                .feature_rms
                .total_cmp(&search.tried[b].1.feature_rms)
        });
    let guard = search.choice().map(|(s, _)| {
        base.clone()
            .with_share(s.share)
            .with_relief_gate(s.relief_gate)
    });
    Ok((guard, search))
}
