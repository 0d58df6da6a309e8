//! `--guard`, `--feature-threshold` and `--feature-setting`, shared by
//! `encode` and `ingest`:
//! decimation guards beside the colour mode's own.

use crate::ingest::{FeatureSetting, GuardOptions};
use anyhow::bail;
use clap::ValueEnum;
use vitrine_simplify::FeatureThreshold;

/// A decimation guard the encoder can run under.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GuardKind {
    /// Keep vertices near sharp features (average normal deviation θ of the
    /// full resolution) until the finer levels.
    Features,
}

#[derive(clap::Args, Clone, Debug, Default)]
pub struct GuardArgs {
    /// Extra decimation guards, beside the colour mode's own: `features`.
    /// Repeatable or comma-separated; default none (the plain stream).
    #[arg(long = "guard", value_enum, value_delimiter = ',')]
    pub guards: Vec<GuardKind>,
    /// Where a feature starts, with `--guard features`: `mean+2sigma` of θ
    /// (the default), an angle in degrees (`12` or `12deg`) or a percentile
    /// (`p95`).
    #[arg(long, value_name = "mean+2sigma|DEG|pP")]
    pub feature_threshold: Option<FeatureThreshold>,
    /// The feature guard's share and relief gate: `auto` (the default)
    /// encodes the scan under 8 settings and keeps the one whose coarse
    /// levels stay nearest its sharpest vertices within +5 % connectivity
    /// and no higher image error, or none; `SHARE:GATE` (e.g. `0.3:0.3`)
    /// or `SHARE` (no relief gate) sets it.
    #[arg(long, value_name = "auto|SHARE[:GATE]")]
    pub feature_setting: Option<FeatureSetting>,
}

impl GuardArgs {
    pub fn options(&self) -> anyhow::Result<GuardOptions> {
        let features = self.guards.contains(&GuardKind::Features);
        if self.feature_threshold.is_some() && !features {
            bail!("--feature-threshold needs --guard features");
        }
        if self.feature_setting.is_some() && !features {
            bail!("--feature-setting needs --guard features");
        }
        Ok(GuardOptions {
            features: features.then(|| self.feature_threshold.unwrap_or_default()),
            feature_setting: self.feature_setting.unwrap_or_default(),
        })
    }
}
