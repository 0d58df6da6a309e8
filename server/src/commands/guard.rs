//! `--guard` and `--feature-threshold`, shared by `encode` and `ingest`:
//! decimation guards beside the colour mode's own.

use crate::ingest::GuardOptions;
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
}

impl GuardArgs {
    pub fn options(&self) -> anyhow::Result<GuardOptions> {
        let features = self.guards.contains(&GuardKind::Features);
        if self.feature_threshold.is_some() && !features {
            bail!("--feature-threshold needs --guard features");
        }
        Ok(GuardOptions {
            features: features.then(|| self.feature_threshold.unwrap_or_default()),
        })
    }
}
