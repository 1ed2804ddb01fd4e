//! What a vision-based tactile sensor is: image geometry, gel, optics and marker grid.

use crate::printable::{check_name, short_number};
use crate::tactile::gel_glow::GelGlow;
use crate::tactile::photometric::PhotometricModel;
use crate::tactile::shading_table::ShadingTable;
use serde::{Deserialize, Serialize};

/// The thinnest gel a spec or `--gel-thickness-mm` may give: vision-based tactile gels are
/// 0.5-5 mm, and a layer far thinner than its contact makes the layer solve stall (1e-9 mm
/// ran past a minute).
pub const MIN_GEL_THICKNESS_MM: f64 = 0.5;
/// The finest pixel a spec may have: a micrometre on the gel (GelSight sensors: 0.02-0.1 mm).
pub const MIN_MM_PER_PX: f64 = 0.001;
/// The largest ambient and light gain analytic lights may give, relative to the flat gel.
pub const MAX_LIGHT_GAIN: f64 = 10.0;
/// The widest marker pitch: tactile gels print dots 0.5-3 mm apart, and a pitch of 1e308 mm
/// let a dot's radius make a blur kernel of gigabytes.
pub const MAX_MARKER_PITCH_MM: f64 = 100.0;

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

    /// Checks every field's range and that the parts agree, wherever the spec was read from
    /// (a sensor profile, a recorded session). Err is the field, named as it is serialised
    /// (`mm_per_px`, `gel.modulus_mpa`, `glow.colour[0].sigma_px`), and what is wrong with it.
    pub fn check(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: String| Err((field.to_string(), message));
        let positive = |v: f64| v.is_finite() && v > 0.0;
        // Printed in every report and answer: one line of plain text.
        if let Err(message) = check_name(&self.model) {
            return bad("model", message);
        }
        for (field, v) in [("width_px", self.width_px), ("height_px", self.height_px)] {
            if !(8..=4096).contains(&v) {
                return bad(field, format!("{v} px, expected 8..=4096"));
            }
        }
        if !(self.mm_per_px.is_finite() && (MIN_MM_PER_PX..=1.0).contains(&self.mm_per_px)) {
            return bad(
                "mm_per_px",
                format!(
                    "{}, expected a scale in [{MIN_MM_PER_PX}, 1] mm per pixel",
                    short_number(self.mm_per_px)
                ),
            );
        }
        if !(positive(self.frame_rate_hz) && self.frame_rate_hz <= 10_000.0) {
            return bad(
                "frame_rate_hz",
                format!(
                    "{}, expected a rate in (0, 10000] Hz",
                    short_number(self.frame_rate_hz)
                ),
            );
        }
        let g = &self.gel;
        if !(positive(g.modulus_mpa) && g.modulus_mpa <= 1000.0) {
            return bad(
                "gel.modulus_mpa",
                format!("{}, expected (0, 1000] MPa", short_number(g.modulus_mpa)),
            );
        }
        if !(g.poisson.is_finite() && (0.0..=0.5).contains(&g.poisson)) {
            return bad(
                "gel.poisson",
                format!("{}, expected 0..=0.5", short_number(g.poisson)),
            );
        }
        if !(g.thickness_mm.is_finite() && (MIN_GEL_THICKNESS_MM..=50.0).contains(&g.thickness_mm))
        {
            return bad(
                "gel.thickness_mm",
                format!(
                    "{}, expected {MIN_GEL_THICKNESS_MM} to 50 mm",
                    short_number(g.thickness_mm)
                ),
            );
        }
        match &self.table {
            None => {
                let l = &self.photometric;
                if !l
                    .lights
                    .iter()
                    .all(|d| d.is_finite() && (d.length() - 1.0).abs() < 1e-3)
                {
                    return bad("photometric.lights", "must be unit vectors".into());
                }
                // Both relative to the flat gel's light: beyond ten times it the shading
                // overflows the frame's range long before the camera's, and 1e300 overflows
                // the renderer's arithmetic.
                if !(l.ambient.is_finite() && (0.0..=MAX_LIGHT_GAIN).contains(&l.ambient)) {
                    return bad(
                        "photometric.ambient",
                        format!(
                            "{}, expected 0 to {MAX_LIGHT_GAIN}",
                            short_number(l.ambient)
                        ),
                    );
                }
                if !(positive(l.gain) && l.gain <= MAX_LIGHT_GAIN) {
                    return bad(
                        "photometric.gain",
                        format!(
                            "{}, expected above 0 up to {MAX_LIGHT_GAIN}",
                            short_number(l.gain)
                        ),
                    );
                }
                if !l.lights.iter().all(|d| d.z > 0.0) {
                    return bad(
                        "photometric.lights",
                        "every light must shine on the flat gel (z > 0)".into(),
                    );
                }
                let det =
                    glam::DMat3::from_cols(l.lights[0], l.lights[1], l.lights[2]).determinant();
                if det.abs() < 1e-3 {
                    return bad(
                        "photometric.lights",
                        "the three lights must not lie in one plane (slopes could not be read back)"
                            .into(),
                    );
                }
            }
            Some(t) => {
                if let Err(e) = t.validate() {
                    return bad("table", e.to_string());
                }
            }
        }
        if let Some(glow) = &self.glow
            && let Err((field, message)) = glow.validate()
        {
            return bad(&field, message);
        }
        let m = &self.markers;
        if u64::from(m.cols) * u64::from(m.rows) > 10_000 {
            return bad(
                "markers",
                format!("{} x {} markers, at most 10000", m.cols, m.rows),
            );
        }
        if (m.cols == 0) != (m.rows == 0) {
            return bad(
                "markers",
                format!(
                    "cols = {}, rows = {}: a grid has both, or both are 0 for none",
                    m.cols, m.rows
                ),
            );
        }
        if !(positive(m.pitch_mm) && m.pitch_mm <= MAX_MARKER_PITCH_MM) {
            return bad(
                "markers.pitch_mm",
                format!(
                    "{}, expected above 0 up to {MAX_MARKER_PITCH_MM} mm",
                    short_number(m.pitch_mm)
                ),
            );
        }
        if !(m.radius_mm.is_finite() && m.radius_mm >= 0.0 && m.radius_mm < m.pitch_mm / 2.0) {
            return bad(
                "markers.radius_mm",
                format!(
                    "{}, expected 0 or more and under half the pitch ({} mm)",
                    short_number(m.radius_mm),
                    short_number(m.pitch_mm)
                ),
            );
        }
        Ok(())
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
