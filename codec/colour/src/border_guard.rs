//! The colour-preserving decimation metric of Lee, Lavoué & Dupont 2012, as
//! the thesis uses it (§4.1.2, eq. 3): a patch is decimated only if
//! `E_total = E_colour ⊗ E_geo < 0.5`.
//!
//! - `E_colour`: CIE L\*a\*b\* distance (CIE76) between the removed vertex's
//!   colour and the colour interpolated at the centre of the middle face of
//!   the retriangulation (the mean of its three corners), divided by
//!   [`COLOUR_SCALE`].
//! - `E_geo`: mean area of the patch's faces before decimation over the mean
//!   face area of the current level.
//! - `⊗` is taken as the product. The thesis leaves the normalisation of
//!   `E_colour` and the combination open; these choices are ours, set so the
//!   guard fires at visible colour borders (ΔE ≳ 12 on a patch of average area).

use glam::DVec3;

/// ΔE (CIE76) that counts as a colour error of 1.
pub const COLOUR_SCALE: f64 = 25.0;

use vitrine_codec::{CandidatePatch, PatchGuard};

/// Refuses decimations that would blur a colour border (see module docs).
#[derive(Clone, Copy, Debug)]
pub struct ColourBorderGuard {
    pub threshold: f64,
}

impl Default for ColourBorderGuard {
    fn default() -> Self {
        ColourBorderGuard { threshold: 0.5 }
    }
}

impl PatchGuard for ColourBorderGuard {
    fn uses_mean_face_area(&self) -> bool {
        true
    }

    fn allows(&self, p: &CandidatePatch<'_>) -> bool {
        let Some(centre_colour) = p.centre_colour else {
            return true;
        };
        let middle = p.triangles[(p.triangles.len() - 1) / 2];
        let mut mean = [0.0; 3];
        for &i in &middle {
            let lab = srgb_to_lab(p.polygon_colours[i as usize]);
            (0..3).for_each(|k| mean[k] += lab[k] / 3.0);
        }
        let removed = srgb_to_lab(centre_colour);
        let e_colour = (0..3)
            .map(|k| (removed[k] - mean[k]).powi(2))
            .sum::<f64>()
            .sqrt()
            / COLOUR_SCALE;
        let centre = DVec3::from(p.centre.map(f64::from));
        let mut area = 0.0;
        for i in 0..p.valence {
            let a = DVec3::from(p.polygon[i].map(f64::from));
            let b = DVec3::from(p.polygon[(i + 1) % p.valence].map(f64::from));
            area += 0.5 * (a - centre).cross(b - centre).length();
        }
        let e_geo = if p.mean_face_area > 0.0 {
            area / p.valence as f64 / p.mean_face_area
        } else {
            1.0
        };
        e_colour * e_geo < self.threshold
    }
}

/// sRGB bytes to CIE L\*a\*b\* (D65).
pub fn srgb_to_lab(c: [u8; 3]) -> [f64; 3] {
    let lin = c.map(|v| {
        let v = v as f64 / 255.0;
        if v <= 0.04045 {
            v / 12.92
        } else {
            ((v + 0.055) / 1.055).powf(2.4)
        }
    });
    // IEC 61966-2-1 primaries, D65 white normalised to (0.95047, 1, 1.08883).
    let x = (0.4124564 * lin[0] + 0.3575761 * lin[1] + 0.1804375 * lin[2]) / 0.95047;
    let y = 0.2126729 * lin[0] + 0.7151522 * lin[1] + 0.0721750 * lin[2];
    let z = (0.0193339 * lin[0] + 0.1191920 * lin[1] + 0.9503041 * lin[2]) / 1.08883;
    let f = |t: f64| {
        if t > 216.0 / 24389.0 {
            t.cbrt()
        } else {
            (24389.0 / 27.0 * t + 16.0) / 116.0
        }
    };
    let (fx, fy, fz) = (f(x), f(y), f(z));
    [116.0 * fy - 16.0, 500.0 * (fx - fy), 200.0 * (fy - fz)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_of_white_black_and_red() {
        let w = srgb_to_lab([255, 255, 255]);
        assert!((w[0] - 100.0).abs() < 0.01 && w[1].abs() < 0.01 && w[2].abs() < 0.01);
        assert!(srgb_to_lab([0, 0, 0])[0].abs() < 1e-9);
        let r = srgb_to_lab([255, 0, 0]);
        assert!(
            (r[0] - 53.24).abs() < 0.05 && (r[1] - 80.09).abs() < 0.1 && (r[2] - 67.20).abs() < 0.1
        );
    }
}
