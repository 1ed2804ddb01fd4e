//! What a vision-based tactile sensor is: image geometry, gel, optics and marker grid.

use crate::tactile::gel_glow::GelGlow;
use crate::tactile::photometric::PhotometricModel;
use crate::tactile::shading_table::ShadingTable;
use serde::{Deserialize, Serialize};

/// The elastomer layer bonded to the sensor's rigid acrylic window.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GelSpec {
    pub modulus_mpa: f64,
    pub poisson: f64,
    pub thickness_mm: f64,
}

/// The grid of dark dots printed on the gel surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct MarkerGrid {
    pub cols: u32,
    pub rows: u32,
    pub pitch_mm: f64,
    pub radius_mm: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TactileSpec {
    pub model: String,
    pub width_px: u32,
    pub height_px: u32,
    pub mm_per_px: f64,
    pub gel: GelSpec,
    /// The analytic lights; the shading unless a calibrated table is given.
    pub photometric: PhotometricModel,
    /// The calibrated gradient -> colour table of a real sensor (`tactex calibrate`): frames
    /// are rendered and read through it instead of the lights.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub table: Option<ShadingTable>,
    /// Light scattered in the gel round a contact (fitted by `calibrate`): frames are rendered
    /// with it and read through it. None: no glow.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub glow: Option<GelGlow>,
    pub markers: MarkerGrid,
    pub frame_rate_hz: f64,
}

impl TactileSpec {
    /// GelSight Mini at its 320x240 output: 0.0634 mm/px (20.3 x 15.2 mm), ~4 mm gel of
    /// E ~ 0.15-0.45 MPa (0.3 MPa taken), nu 0.49, 7 x 9 markers at 2 mm pitch, 25 fps.
    pub fn gelsight_mini() -> Self {
        Self {
            model: "GelSight Mini".into(),
            width_px: 320,
            height_px: 240,
            mm_per_px: 0.0634,
            gel: GelSpec {
                modulus_mpa: 0.3,
                poisson: 0.49,
                thickness_mm: 4.0,
            },
            photometric: PhotometricModel::default(),
            table: None,
            glow: None,
            markers: MarkerGrid {
                cols: 9,
                rows: 7,
                pitch_mm: 2.0,
                radius_mm: 0.25,
            },
            frame_rate_hz: 25.0,
        }
    }

    /// Rest positions of the marker centres in pixels (x, y), row-major.
    /// The pad the frame images (x along the frame's columns, y along its rows), mm.
    pub fn pad_size_mm(&self) -> [f64; 2] {
        [
            f64::from(self.width_px) * self.mm_per_px,
            f64::from(self.height_px) * self.mm_per_px,
        ]
    }

    pub fn marker_rest_px(&self) -> Vec<(f64, f64)> {
        let m = &self.markers;
        let pitch_px = m.pitch_mm / self.mm_per_px;
        let cx = self.width_px as f64 / 2.0;
        let cy = self.height_px as f64 / 2.0;
        let mut out = Vec::with_capacity((m.cols * m.rows) as usize);
        for r in 0..m.rows {
            for c in 0..m.cols {
                out.push((
                    cx + (c as f64 - (m.cols as f64 - 1.0) / 2.0) * pitch_px,
                    cy + (r as f64 - (m.rows as f64 - 1.0) / 2.0) * pitch_px,
                ));
            }
        }
        out
    }
}
