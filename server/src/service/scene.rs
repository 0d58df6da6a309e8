//! The frame every 3D file and description the service hands out shares:
//! glTF's, +Y up, in metres. A model's coordinates (those of the decoded
//! stream, in which annotations are stored) reach it by the rotation that
//! turns the recorded up axis to +Y, then the scale of the recorded unit to
//! metres. A GLB download writes this as its node matrix (`download.rs`);
//! a IIIF Scene places its cameras, lights and annotation points in it
//! (`iiif/`), so both say the same thing about where a point is.

use crate::ingest::curation::metres_per_unit;
use crate::storage::{Curation, UpAxis};

/// From model coordinates to the scene's (+Y up, metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SceneFrame {
    /// World axis `r` is `rows[r] · p` (`UpAxis::to_y_up`).
    rows: [[f32; 3]; 3],
    /// Metres per model unit; 1 when no unit was recorded.
    scale: f32,
    /// `scale` as the decimal a glTF file's JSON writes it (`0.001`, not
    /// the f32's exact binary value), so that a point here is where a
    /// client that reads the GLB's node matrix puts it.
    decimal_scale: f64,
}

impl SceneFrame {
    pub fn of(curation: &Curation) -> SceneFrame {
        let scale = curation
            .unit
            .as_deref()
            .and_then(metres_per_unit)
            .unwrap_or(1.0);
        SceneFrame {
            rows: curation.up_axis.unwrap_or(UpAxis::Y).to_y_up(),
            scale,
            // The shortest decimal that reads back as this f32 (what JSON holds).
            decimal_scale: scale.to_string().parse().unwrap_or(f64::from(scale)),
        }
    }

    /// Whether model coordinates already are scene coordinates.
    pub fn is_identity(&self) -> bool {
        self.rows == UpAxis::Y.to_y_up() && self.scale == 1.0
    }

    /// The glTF node matrix (column-major) of this frame.
    pub fn matrix(&self) -> [f32; 16] {
        let mut matrix = [0.0f32; 16];
        for (r, row) in self.rows.iter().enumerate() {
            for (c, &value) in row.iter().enumerate() {
                matrix[4 * c + r] = value * self.scale;
            }
        }
        matrix[15] = 1.0;
        matrix
    }

    /// A point in model coordinates, in the scene's.
    pub fn to_scene(self, p: [f64; 3]) -> [f64; 3] {
        let scale = self.decimal_scale;
        self.rows.map(|row| {
            scale
                * row
                    .iter()
                    .zip(p)
                    .map(|(&a, b)| f64::from(a) * b)
                    .sum::<f64>()
        })
    }

    /// A point of the viewer's world frame (model coordinates already turned
    /// upright: `web/src/frame.js`), in the scene's: only the unit differs.
    pub fn upright_to_scene(self, p: [f64; 3]) -> [f64; 3] {
        p.map(|v| v * self.decimal_scale)
    }

    /// A point in scene coordinates, in the model's (the inverse of
    /// [`SceneFrame::to_scene`]: the rotation's transpose, then the unit).
    pub fn to_model(self, p: [f64; 3]) -> [f64; 3] {
        let scale = self.decimal_scale;
        let mut out = [0.0; 3];
        for (c, value) in out.iter_mut().enumerate() {
            *value = (0..3)
                .map(|r| f64::from(self.rows[r][c]) * p[r])
                .sum::<f64>()
                / scale;
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn curation(up: UpAxis, unit: &str) -> Curation {
        Curation {
            up_axis: Some(up),
            unit: Some(unit.into()),
            ..Curation::default()
        }
    }

    #[test]
    fn points_go_to_the_scene_and_back() {
        for up in UpAxis::ALL {
            for unit in ["mm", "cm", "m", "in"] {
                let frame = SceneFrame::of(&curation(up, unit));
                let p = [12.5, -3.25, 7.0];
                let back = frame.to_model(frame.to_scene(p));
                for i in 0..3 {
                    assert!((back[i] - p[i]).abs() < 1e-9, "{up:?} {unit}: {back:?}");
                }
            }
        }
    }

    #[test]
    fn the_up_axis_becomes_plus_y_in_metres() {
        let frame = SceneFrame::of(&curation(UpAxis::Z, "mm"));
        let up = frame.to_scene([0.0, 0.0, 1000.0]);
        assert!(
            (up[1] - 1.0).abs() < 1e-6 && up[0] == 0.0 && up[2] == 0.0,
            "{up:?}"
        );
        // The node matrix says the same (column-major: m[4c + r]).
        let m = frame.matrix();
        let p = [3.0f32, 4.0, 5.0];
        let by_matrix: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| f64::from(m[4 * c + r] * p[c])).sum())
            .collect();
        let by_frame = frame.to_scene(p.map(f64::from));
        for r in 0..3 {
            assert!((by_matrix[r] - by_frame[r]).abs() < 1e-6);
        }
        assert!(SceneFrame::of(&Curation::default()).is_identity());
    }
}
