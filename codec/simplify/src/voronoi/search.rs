//! The radius for a vertex count (`--target-vertices`): the seed has no
//! such mode, and the count is not a smooth function of r (refinement adds
//! sites in steps), so it bisects r on a log scale from an estimate and
//! keeps the nearest count seen (below the target on a tie).

use vitrine_codec::Result;
use vitrine_geodesic::Surface;

use super::{area, VoronoiSimplified};

/// Radii tried at most.
const ATTEMPTS: usize = 14;

/// Sites of an r-net sit 1–2 r apart: about 1.5 r² of surface each.
const AREA_PER_SITE: f64 = 1.5;

pub(super) fn nearest(
    target: usize,
    start: f64,
    step: f64,
    run: impl Fn(f64) -> Result<VoronoiSimplified>,
) -> Result<VoronoiSimplified> {
    let mut fraction = start;
    let (mut small, mut large) = (None::<f64>, None::<f64>); // r giving too many / too few
    let mut best: Option<VoronoiSimplified> = None;
    for attempt in 1..=ATTEMPTS {
        let out = run(fraction)?;
        let count = out.mesh.positions.len();
        let better = best.as_ref().is_none_or(|b| {
            let (d, e) = (
                count.abs_diff(target),
                b.mesh.positions.len().abs_diff(target),
            );
            d < e || (d == e && count < b.mesh.positions.len())
        });
        if count > target {
            small = Some(small.map_or(fraction, |s| s.max(fraction)));
        } else {
            large = Some(large.map_or(fraction, |l| l.min(fraction)));
        }
        if better {
            best = Some(VoronoiSimplified {
                attempts: attempt,
                ..out
            });
        } else if let Some(b) = &mut best {
            b.attempts = attempt;
        }
        if count == target {
            break;
        }
        fraction = match (small, large) {
            (Some(s), Some(l)) => (s * l).sqrt(),
            (Some(s), None) => s * step,
            (None, Some(l)) => l / step,
            (None, None) => fraction, // not reached: one side was just set
        };
    }
    best.ok_or_else(|| vitrine_codec::Error::Parameter("no radius was tried".into()))
}

/// The first radius tried for `target` vertices, over the diagonal.
pub(super) fn first_fraction(surface: &Surface, target: usize) -> f64 {
    (area(surface) / (AREA_PER_SITE * target as f64)).sqrt() / surface.diagonal()
}
