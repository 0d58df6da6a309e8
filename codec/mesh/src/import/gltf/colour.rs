//! glTF's linear vertex colours and the sRGB bytes [`crate::IndexedMesh`]
//! holds.

/// glTF vertex colours are linear; IndexedMesh holds sRGB bytes.
pub(crate) fn linear_to_srgb_u8(l: f64) -> u8 {
    let l = if l.is_nan() { 0.0 } else { l.clamp(0.0, 1.0) };
    let s = if l <= 0.003_130_8 {
        12.92 * l
    } else {
        1.055 * l.powf(1.0 / 2.4) - 0.055
    };
    (s * 255.0).round().clamp(0.0, 255.0) as u8
}

/// The inverse of [`linear_to_srgb_u8`], for the exporter.
pub(crate) fn srgb_u8_to_linear(c: u8) -> f32 {
    let s = c as f64 / 255.0;
    let l = if s <= 0.040_45 {
        s / 12.92
    } else {
        ((s + 0.055) / 1.055).powf(2.4)
    };
    l as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_round_trip_is_exact() {
        for c in 0..=255u8 {
            assert_eq!(linear_to_srgb_u8(srgb_u8_to_linear(c) as f64), c);
        }
    }
}
