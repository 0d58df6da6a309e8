//! The contexts the connectivity codes are modelled in (FORMAT.md,
//! "Connectivity"): how many there are and what distinguishes them. Part of
//! the stream format, shared by the gate traversal and the trained priors.

use crate::patch::{MAX_VALENCE, MIN_VALENCE};
use crate::predict::GATE_CONTEXTS;

/// Decimation symbols: 0 = null patch, `valence − 2` otherwise (1..=4).
pub(crate) const DECIMATION_SYMBOLS: usize = MAX_VALENCE - 1;
/// Coarse valence classes by faces around a vertex: ≤ 4, 5–6, ≥ 7.
pub(crate) const VALENCE_CLASSES: usize = 3;
/// The front vertex's coarse valence itself, ≤ 2 … ≥ 9.
pub(crate) const FRONT_VALENCES: usize = 8;
/// How many patch valences fit around a gate: 1 (only 3) ..= 4 (3 to 6).
pub(crate) const FIT_CLASSES: usize = MAX_VALENCE - MIN_VALENCE + 1;

/// Decimating contexts: gate tags × front valence × valence classes of the
/// gate's origin and target × widest fit.
pub(crate) const DECIMATION_CONTEXTS: usize =
    GATE_CONTEXTS * FRONT_VALENCES * VALENCE_CLASSES * VALENCE_CLASSES * FIT_CLASSES;
/// Cleaning contexts: gate tags × valence classes of front, origin, target.
pub(crate) const CLEANING_CONTEXTS: usize = GATE_CONTEXTS * VALENCE_CLASSES.pow(3);
