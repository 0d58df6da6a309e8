//! Uniform quantization of positions on the bounding cube.

use crate::{Error, Result};

/// Maps positions to integers in `[0, 2^bits)` with one step for all axes,
/// so residual lengths mean the same in every direction (the Frenet
/// rotation relies on that).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantization {
    pub bits: u8,
    pub min: [f32; 3],
    /// Size of one quantization step in model units.
    pub step: f32,
}

impl Quantization {
    pub const MIN_BITS: u8 = 8;
    pub const MAX_BITS: u8 = 16;

    pub fn for_positions(positions: &[[f32; 3]], bits: u8) -> Result<Self> {
        if !(Self::MIN_BITS..=Self::MAX_BITS).contains(&bits) {
            return Err(Error::Parameter(format!(
                "quantization must be {}–{} bits, got {bits}",
                Self::MIN_BITS,
                Self::MAX_BITS
            )));
        }
        let mut min = [f32::INFINITY; 3];
        let mut max = [f32::NEG_INFINITY; 3];
        for (i, p) in positions.iter().enumerate() {
            for k in 0..3 {
                if !p[k].is_finite() {
                    return Err(Error::input(
                        "mesh",
                        format!("vertex {i} has a non-finite coordinate"),
                    ));
                }
                min[k] = min[k].min(p[k]);
                max[k] = max[k].max(p[k]);
            }
        }
        if positions.is_empty() {
            return Err(Error::input("mesh", "no vertices"));
        }
        let extent = (0..3)
            .map(|k| max[k] as f64 - min[k] as f64)
            .fold(0.0, f64::max);
        let levels = ((1u32 << bits) - 1) as f64;
        let step = if extent > 0.0 {
            (extent / levels) as f32
        } else {
            1.0
        };
        // f32 rounding of the step may leave the top value past 2^bits − 1; nudge up.
        let mut step = step;
        while (extent / step as f64).round() > levels {
            step = f32::from_bits(step.to_bits() + 1);
        }
        Ok(Quantization { bits, min, step })
    }

    pub fn max_value(&self) -> i32 {
        (1i32 << self.bits) - 1
    }

    pub fn quantize(&self, p: [f32; 3]) -> [i32; 3] {
        let max = self.max_value();
        std::array::from_fn(|k| {
            let q = ((p[k] as f64 - self.min[k] as f64) / self.step as f64).round() as i64;
            q.clamp(0, max as i64) as i32
        })
    }

    /// Exact same arithmetic on every platform: one f32 multiply and add.
    #[inline]
    pub fn dequantize(&self, q: [i32; 3]) -> [f32; 3] {
        std::array::from_fn(|k| self.min[k] + q[k] as f32 * self.step)
    }
}
