//! Decimation guards asked for beside the colour mode's own (which
//! `vitrine_colour::encode_coloured` adds itself): today the feature guard
//! of `vitrine_simplify`. With none, the encoder is left as it was and the
//! stream is byte for byte the unguarded one.

use serde::Serialize;
use vitrine_codec::{EncodeOptions, Encoder, IndexedMesh, Quantization};
use vitrine_simplify::{
    search_feature_guard, FeatureGuard, FeatureThreshold, GuardSetting, DEFAULT_CONNECTIVITY_BUDGET,
};

/// Which extra guards an encode runs under.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct GuardOptions {
    /// Keep the vertices near sharp features of the full resolution until
    /// the finer levels (`vitrine_simplify::FeatureGuard`), features being
    /// where the one-ring maximum of θ exceeds this threshold. `None`: off.
    pub features: Option<FeatureThreshold>,
    /// How the feature guard's share and relief gate are set.
    pub feature_setting: FeatureSetting,
}

/// The feature guard's setting: searched per scan, or given.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum FeatureSetting {
    /// `vitrine_simplify::search_feature_guard`: the setting that keeps
    /// features best within +5 % connectivity and no higher image error,
    /// or none (the plain stream) when no setting does.
    #[default]
    Auto,
    Fixed(GuardSetting),
}

impl std::str::FromStr for FeatureSetting {
    type Err = String;

    /// `auto`, `SHARE` (no relief gate) or `SHARE:GATE`, e.g. `0.3:0.3`.
    fn from_str(s: &str) -> Result<Self, String> {
        let s = s.trim();
        if s == "auto" {
            return Ok(FeatureSetting::Auto);
        }
        let bad =
            || format!("feature setting must be auto, SHARE or SHARE:GATE (0.3:0.3), got {s:?}");
        let number = |t: &str| {
            t.parse::<f64>()
                .ok()
                .filter(|v| (0.0..=1.0).contains(v))
                .ok_or_else(bad)
        };
        let (share, relief_gate) = match s.split_once(':') {
            Some((a, b)) => (number(a)?, Some(number(b)?)),
            None => (number(s)?, None),
        };
        Ok(FeatureSetting::Fixed(GuardSetting { share, relief_gate }))
    }
}

impl FeatureSetting {
    /// As `--feature-setting` spells it.
    pub fn name(self) -> String {
        match self {
            FeatureSetting::Auto => "auto".into(),
            FeatureSetting::Fixed(GuardSetting {
                share,
                relief_gate: Some(g),
            }) => format!("{share}:{g}"),
            FeatureSetting::Fixed(GuardSetting { share, .. }) => format!("{share}"),
        }
    }
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
    /// The setting encoded with; `None` when the search declined (the
    /// stream is then the plain one).
    pub share: Option<f64>,
    pub relief_gate: Option<f64>,
    /// Whether the setting was searched for this scan.
    pub searched: bool,
    /// From the search, at the first level with ≥ 5 % of the vertices:
    /// the change of the features' RMS distance and of the whole stream's
    /// connectivity against the plain stream (the chosen setting's).
    pub feature_rms_change: Option<f64>,
    pub connectivity_change: Option<f64>,
}

impl FeatureSummary {
    /// One line for a log.
    pub fn describe(&self) -> String {
        let head = format!(
            "feature guard: threshold {:.2}°, {} feature vertices",
            self.threshold_degrees, self.vertices
        );
        let searched = match (self.feature_rms_change, self.connectivity_change) {
            (Some(f), Some(c)) => format!(
                " (searched: features' distance {:+.1} %, connectivity {:+.2} %)",
                100.0 * f,
                100.0 * c
            ),
            _ => String::new(),
        };
        match self.share {
            Some(share) => format!(
                "{head}; share {share}, relief gate {}{searched}",
                self.relief_gate.map_or("none".into(), |g| g.to_string())
            ),
            None => format!(
                "{head}; declined: no setting keeps features closer within +{:.0} % connectivity \
                 without raising the image error, so the stream is the plain one",
                100.0 * DEFAULT_CONNECTIVITY_BUDGET
            ),
        }
    }
}

/// The guards of [`GuardOptions`], built for one mesh and quantization.
pub struct Guards {
    features: Option<FeatureGuard>,
    summary: Option<FeatureSummary>,
}

impl Guards {
    /// Builds the guards for `mesh` (repaired, as the encoder gets it) with
    /// the stream's options (the feature guard keys its vertices by the
    /// stream's quantization, and its search encodes with them).
    pub fn new(
        mesh: &IndexedMesh,
        options: &GuardOptions,
        encode: &EncodeOptions,
    ) -> vitrine_codec::Result<Guards> {
        let Some(threshold) = options.features else {
            return Ok(Guards {
                features: None,
                summary: None,
            });
        };
        let q = Quantization::for_positions(&mesh.positions, encode.quantization_bits)?;
        let base = FeatureGuard::new(mesh, &q, threshold);
        let mut summary = FeatureSummary {
            threshold_degrees: base.threshold_radians().to_degrees(),
            vertices: base.feature_vertices(),
            share: None,
            relief_gate: None,
            searched: false,
            feature_rms_change: None,
            connectivity_change: None,
        };
        let features = match options.feature_setting {
            FeatureSetting::Fixed(s) => {
                summary.share = Some(s.share);
                summary.relief_gate = s.relief_gate;
                Some(base.with_share(s.share).with_relief_gate(s.relief_gate))
            }
            FeatureSetting::Auto => {
                let (guard, search) =
                    search_feature_guard(mesh, encode, &base, DEFAULT_CONNECTIVITY_BUDGET)?;
                summary.searched = true;
                if let Some((s, m)) = search.choice() {
                    let plain = &search.plain;
                    summary.share = Some(s.share);
                    summary.relief_gate = s.relief_gate;
                    summary.feature_rms_change = Some(m.feature_rms / plain.feature_rms - 1.0);
                    summary.connectivity_change = Some(
                        m.connectivity_bits as f64 / plain.connectivity_bits.max(1) as f64 - 1.0,
                    );
                }
                guard
            }
        };
        Ok(Guards {
            features,
            summary: Some(summary),
        })
    }

    pub fn features(&self) -> Option<FeatureSummary> {
        self.summary
    }

    /// `encoder` with these guards added to the ones it has.
    pub fn apply<'a>(&'a self, encoder: Encoder<'a>) -> Encoder<'a> {
        match &self.features {
            Some(g) => encoder.guard(g),
            None => encoder,
        }
    }
}
