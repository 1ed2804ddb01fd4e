//! A sensor calibration file: the fitted shading table with the no-contact frame it was
//! fitted against (embedded as PNG, so the file is self-contained), the frame's scale, the
//! gel, and how the fit went.

use super::{RenderError, SensorOptics, Shading, invalid};
use base64::Engine;
use image::RgbImage;
use serde::{Deserialize, Serialize};
use tactex_core::shading_table::ShadingTable;
use tactex_core::tactile_spec::GelSpec;

pub const CALIBRATION_FORMAT: &str = "tactex-gelsight-calibration/1";

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FitReport {
    /// The presses the table was fitted to.
    pub images: Vec<String>,
    pub samples: usize,
    /// Root mean square residual of the fit per channel (grey levels).
    pub rms_grey: [f64; 3],
    pub ball_radius_mm: f64,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct GelCalibration {
    pub format: String,
    pub width: u32,
    pub height: u32,
    pub mm_per_px: f64,
    pub gel: GelSpec,
    pub table: ShadingTable,
    /// The no-contact frame, PNG, base64.
    pub background_png: String,
    pub fit: FitReport,
    /// Where the calibration images came from (attribution travels with the file).
    pub source: String,
}

impl GelCalibration {
    pub fn encode_background(background: &RgbImage) -> String {
        let mut png = Vec::new();
        background
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .expect("encoding a PNG into memory");
        base64::engine::general_purpose::STANDARD.encode(png)
    }

    pub fn background(&self) -> Result<RgbImage, RenderError> {
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(&self.background_png)
            .map_err(|e| invalid("background_png", format!("not base64: {e}")))?;
        let img = image::load_from_memory_with_format(&bytes, image::ImageFormat::Png)
            .map_err(|e| invalid("background_png", format!("not a PNG: {e}")))?
            .to_rgb8();
        if img.dimensions() != (self.width, self.height) {
            return Err(invalid(
                "background_png",
                format!(
                    "is {} x {}, the calibration says {} x {}",
                    img.width(),
                    img.height(),
                    self.width,
                    self.height
                ),
            ));
        }
        Ok(img)
    }

    /// Parses and checks a calibration file's text; errors name the field.
    pub fn from_json(text: &str) -> Result<Self, RenderError> {
        let calib: GelCalibration =
            serde_json::from_str(text).map_err(|e| invalid("calibration", e.to_string()))?;
        if calib.format != CALIBRATION_FORMAT {
            return Err(invalid(
                "format",
                format!("'{}', expected '{CALIBRATION_FORMAT}'", calib.format),
            ));
        }
        calib
            .table
            .validate()
            .map_err(|e| invalid("table", e.to_string()))?;
        calib.to_optics()?.validate()?;
        Ok(calib)
    }

    /// The calibrated sensor: real background, fitted table, no markers (the ball presses
    /// have none), no vignetting (the background carries it) and no added noise.
    pub fn to_optics(&self) -> Result<SensorOptics, RenderError> {
        let background = self
            .background()?
            .pixels()
            .map(|p| p.0.map(|v| v as f32))
            .collect();
        Ok(SensorOptics {
            width: self.width,
            height: self.height,
            mm_per_px: self.mm_per_px,
            background,
            shading: Shading::Table(self.table.clone()),
            markers: Vec::new(),
            marker_radius_px: 0.0,
            marker_darkness: 0.0,
            vignette: 0.0,
            noise_sigma: 0.0,
        })
    }
}
