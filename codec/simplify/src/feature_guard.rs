//! Average normal deviation as a decimation guard (seed 004, integrated
//! into Alliez–Desbrun): a patch whose removed vertex lies on a feature of
//! the full-resolution scan becomes a null patch, as the cell complex's
//! guard does. Encoder-side only: the stream format does not change.

use std::collections::HashSet;

use vitrine_codec::{CandidatePatch, Error, IndexedMesh, PatchGuard, Quantization, Result};

use crate::deviation::{normal_deviation, one_ring_max};

/// Where a feature starts, in θ of the full-resolution mesh.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FeatureThreshold {
    /// Mean plus two standard deviations of θ (the seed's rule, fixed once
    /// from the full resolution instead of re-derived every pass).
    #[default]
    MeanPlusTwoSigma,
    /// An angle in degrees.
    Degrees(f64),
    /// The given percentile (0–100) of θ: 95 keeps the top 5 % of vertices.
    Percentile(f64),
}

impl std::str::FromStr for FeatureThreshold {
    type Err = Error;

    /// `mean+2sigma`, `12deg` / `12` (degrees) or `p95` (a percentile).
    fn from_str(s: &str) -> Result<Self> {
        let bad = || {
            Error::Parameter(format!(
                "feature threshold must be mean+2sigma, degrees (12 or 12deg) or a percentile (p95), got {s:?}"
            ))
        };
        let s = s.trim();
        if s == "mean+2sigma" {
            return Ok(FeatureThreshold::MeanPlusTwoSigma);
        }
        if let Some(p) = s.strip_prefix('p') {
            let p: f64 = p.parse().map_err(|_| bad())?;
            return if (0.0..=100.0).contains(&p) {
                Ok(FeatureThreshold::Percentile(p))
            } else {
                Err(bad())
            };
        }
        let d: f64 = s
            .strip_suffix("deg")
            .unwrap_or(s)
            .parse()
            .map_err(|_| bad())?;
        if (0.0..=180.0).contains(&d) {
            Ok(FeatureThreshold::Degrees(d))
        } else {
            Err(bad())
        }
    }
}

impl FeatureThreshold {
    /// The threshold in radians for these θ values.
    pub fn radians(self, theta: &[f64]) -> f64 {
        match self {
            FeatureThreshold::Degrees(d) => d.to_radians(),
            FeatureThreshold::MeanPlusTwoSigma => {
                let n = theta.len().max(1) as f64;
                let mean = theta.iter().sum::<f64>() / n;
                let var = theta.iter().map(|t| (t - mean).powi(2)).sum::<f64>() / n;
                mean + 2.0 * var.sqrt()
            }
            FeatureThreshold::Percentile(p) => {
                let mut sorted = theta.to_vec();
                sorted.sort_by(f64::total_cmp);
                let Some(last) = sorted.len().checked_sub(1) else {
                    return 0.0;
                };
                sorted[((p / 100.0) * last as f64).round() as usize]
            }
        }
    }
}

/// Refuses to decimate a vertex whose one-ring maximum θ on the full
/// resolution exceeds the threshold. The encoder names a patch by its
/// quantized centre, so the guard keeps the quantized positions of the
/// feature vertices (with the stream's own quantization).
#[derive(Clone, Debug)]
pub struct FeatureGuard {
    features: HashSet<[i32; 3]>,
    threshold: f64,
}

impl FeatureGuard {
    /// `quantization` must be the stream's: `Quantization::for_positions`
    /// of the mesh with the encoder's `quantization_bits`.
    pub fn new(
        mesh: &IndexedMesh,
        quantization: &Quantization,
        threshold: FeatureThreshold,
    ) -> Self {
        let theta = normal_deviation(mesh);
        let threshold = threshold.radians(&theta);
        let ring = one_ring_max(mesh, &theta);
        let features = mesh
            .positions
            .iter()
            .zip(&ring)
            .filter(|(_, &t)| t > threshold)
            .map(|(&p, _)| quantization.quantize(p))
            .collect();
        FeatureGuard {
            features,
            threshold,
        }
    }

    /// How many distinct quantized positions the guard keeps.
    pub fn feature_vertices(&self) -> usize {
        self.features.len()
    }

    /// The threshold it was built with, in radians.
    pub fn threshold_radians(&self) -> f64 {
        self.threshold
    }
}

impl PatchGuard for FeatureGuard {
    fn allows(&self, patch: &CandidatePatch<'_>) -> bool {
        !self.features.contains(&patch.centre)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds_parse_and_refuse_nonsense() {
        assert_eq!(
            "mean+2sigma".parse::<FeatureThreshold>().unwrap(),
            FeatureThreshold::MeanPlusTwoSigma
        );
        assert_eq!(
            "12".parse::<FeatureThreshold>().unwrap(),
            FeatureThreshold::Degrees(12.0)
        );
        assert_eq!(
            "30deg".parse::<FeatureThreshold>().unwrap(),
            FeatureThreshold::Degrees(30.0)
        );
        assert_eq!(
            "p95".parse::<FeatureThreshold>().unwrap(),
            FeatureThreshold::Percentile(95.0)
        );
        for bad in ["", "p101", "-3", "200deg", "sharp", "pNaN"] {
            assert!(bad.parse::<FeatureThreshold>().is_err(), "{bad}");
        }
    }

    #[test]
    fn percentiles_and_the_default_rule() {
        let theta: Vec<f64> = (0..101).map(f64::from).collect();
        assert_eq!(FeatureThreshold::Percentile(95.0).radians(&theta), 95.0);
        let flat_with_one_spike: Vec<f64> =
            (0..100).map(|i| if i == 7 { 1.0 } else { 0.0 }).collect();
        let t = FeatureThreshold::MeanPlusTwoSigma.radians(&flat_with_one_spike);
        assert!(t > 0.0 && t < 1.0, "{t}");
    }
}
