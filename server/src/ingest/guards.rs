//! Decimation guards asked for beside the colour mode's own (which
//! `vitrine_colour::encode_coloured` adds itself): today the feature guard
//! of `vitrine_simplify`. With none, the encoder is left as it was and the
//! stream is byte for byte the unguarded one.

use serde::Serialize;
use vitrine_codec::{Encoder, IndexedMesh, Quantization};
use vitrine_simplify::{FeatureGuard, FeatureThreshold};

/// Which extra guards an encode runs under.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GuardOptions {
    /// Keep the vertices near sharp features of the full resolution until
    /// the finer levels (`vitrine_simplify::FeatureGuard`), features being
    /// where the one-ring maximum of θ exceeds this threshold. `None`: off.
    pub features: Option<FeatureThreshold>,
}

impl GuardOptions {
    /// The guards' names, as `--guard` spells them.
    pub fn names(&self) -> Vec<&'static str> {
        self.features.iter().map(|_| "features").collect()
    }
}

/// The threshold as `--feature-threshold` spells it.
pub fn threshold_name(t: FeatureThreshold) -> String {
    match t {
        FeatureThreshold::MeanPlusTwoSigma => "mean+2sigma".into(),
        FeatureThreshold::Degrees(d) => format!("{d}deg"),
        FeatureThreshold::Percentile(p) => format!("p{p}"),
    }
}

/// What the feature guard resolved to on this mesh.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct FeatureSummary {
    pub threshold_degrees: f64,
    /// Distinct quantized positions the guard may keep.
    pub vertices: usize,
}

/// The guards of [`GuardOptions`], built for one mesh and quantization.
pub struct Guards {
    features: Option<FeatureGuard>,
}

impl Guards {
    /// Builds the guards for `mesh` (repaired, as the encoder gets it) with
    /// the stream's quantization, which the feature guard keys its vertices by.
    pub fn new(
        mesh: &IndexedMesh,
        options: &GuardOptions,
        quantization_bits: u8,
    ) -> vitrine_codec::Result<Guards> {
        let features = match options.features {
            Some(threshold) => {
                let q = Quantization::for_positions(&mesh.positions, quantization_bits)?;
                Some(FeatureGuard::new(mesh, &q, threshold))
            }
            None => None,
        };
        Ok(Guards { features })
    }

    pub fn features(&self) -> Option<FeatureSummary> {
        self.features.as_ref().map(|g| FeatureSummary {
            threshold_degrees: g.threshold_radians().to_degrees(),
            vertices: g.feature_vertices(),
        })
    }

    /// `encoder` with these guards added to the ones it has.
    pub fn apply<'a>(&'a self, encoder: Encoder<'a>) -> Encoder<'a> {
        match &self.features {
            Some(g) => encoder.guard(g),
            None => encoder,
        }
    }
}
