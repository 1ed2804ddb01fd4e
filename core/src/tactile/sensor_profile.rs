//! A sensor profile: one file that describes a vision-based tactile sensor completely, so that
//! the twin renders with it, data generation draws around it, and the estimators read its
//! frames through it. The format is TOML (`tactex-sensor-profile/1`, documented in
//! `docs/sensor_profile.md`) with the no-contact frame as an adjacent PNG; `tactex calibrate`
//! writes one from ball presses, and the built-in GelSight Mini profile is the default.
//!
//! A profile is named in every output that depends on it by its name and the SHA-256 of its
//! contents (the canonical TOML, without the background's file name, then the background's
//! pixels), so two profiles that render alike hash alike wherever their files live.

use crate::tactile::gel_glow::GelGlow;
use crate::tactile::photometric::PhotometricModel;
use crate::tactile::shading_table::ShadingTable;
use crate::tactile::spec::{GelSpec, MarkerGrid, TactileSpec};
use image::RgbImage;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

pub const PROFILE_FORMAT: &str = "tactex-sensor-profile/1";
/// Its `source` note, free text of a few paragraphs at most.
pub const MAX_SOURCE_CHARS: usize = 10_000;
pub use crate::tactile::spec::{MAX_LIGHT_GAIN, MIN_GEL_THICKNESS_MM, MIN_MM_PER_PX};

/// How gel surface slopes become colour.
#[derive(Clone, Debug, PartialEq)]
pub enum Shading {
    /// Analytic: each colour channel lit by one light; gain over the background.
    Lights(PhotometricModel),
    /// Calibrated from real ball presses: colour change added to the background.
    Table(ShadingTable),
}

/// How the calibration that produced a profile went (`tactex calibrate`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CalibrationFit {
    /// The ball presses the table was fitted to.
    pub images: Vec<String>,
    pub samples: usize,
    /// Root mean square residual of the fit per channel (grey levels).
    #[serde(deserialize_with = "crate::serde_exact::array")]
    pub rms_grey: [f64; 3],
    pub ball_radius_mm: f64,
}

/// Everything about one sensor.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorProfile {
    /// Where the calibration images came from (attribution travels with the profile).
    pub source: String,
    /// Frame geometry, gel, shading (lights or calibrated table), marker grid and frame
    /// rate; its `model` is the profile's name.
    pub spec: TactileSpec,
    /// The no-contact frame; None: the twin's synthetic one.
    pub background: Option<RgbImage>,
    /// Camera noise per channel (grey levels, 1 sigma).
    pub noise_sigma_grey: f64,
    /// Relative darkening at the frame's corners (0 when the background is a real frame: it
    /// carries its own).
    pub vignette: f64,
    /// Gain on the light reaching the camera, relative to the background's (1: the exposure the
    /// profile was made at; 2: twice the exposure time or gain). Before the noise.
    pub exposure: f64,
    /// Fraction of the light a marker dot's centre blocks.
    pub marker_darkness: f64,
    pub fit: Option<CalibrationFit>,
}

/// A profile as outputs name it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct ProfileId {
    pub name: String,
    pub sha256: String,
}

impl ProfileId {
    /// Err names the field: the name one line of plain text, the hash 64 hexadecimal digits.
    pub fn check(&self) -> Result<(), (String, String)> {
        crate::printable::check_name(&self.name).map_err(|m| ("name".to_string(), m))?;
        if !(self.sha256.len() == 64 && self.sha256.chars().all(|c| c.is_ascii_hexdigit())) {
            return Err((
                "sha256".into(),
                format!(
                    "'{}', expected 64 hexadecimal digits",
                    crate::printable::printable(&self.sha256.chars().take(70).collect::<String>())
                ),
            ));
        }
        Ok(())
    }
}

impl std::fmt::Display for ProfileId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} ({})",
            self.name,
            &self.sha256[..12.min(self.sha256.len())]
        )
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{file}: {field}: {message}")]
pub struct ProfileError {
    /// The profile file (or "built-in").
    pub file: String,
    /// The field, as a TOML path (`camera.mm_per_px`), or "toml" for a parse error.
    pub field: String,
    pub message: String,
}

// The file's layout. Kept apart from `SensorProfile` so that the file can stay stable while
// the types behind it change.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct ProfileFile {
    format: String,
    name: String,
    #[serde(default)]
    source: String,
    camera: CameraSection,
    gel: GelSection,
    optics: OpticsSection,
    markers: MarkersSection,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    fit: Option<CalibrationFit>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraSection {
    width_px: u32,
    height_px: u32,
    mm_per_px: f64,
    frame_rate_hz: f64,
    noise_sigma_grey: f64,
    vignette: f64,
    /// Written only when not 1, so that a profile made before the field keeps its hash.
    #[serde(default = "unit_exposure", skip_serializing_if = "is_unit_exposure")]
    exposure: f64,
}

fn unit_exposure() -> f64 {
    1.0
}

fn is_unit_exposure(v: &f64) -> bool {
    *v == 1.0
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct GelSection {
    modulus_mpa: f64,
    poisson: f64,
    thickness_mm: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct OpticsSection {
    /// "synthetic", or a PNG file relative to the profile.
    background: String,
    /// "lights" or "table".
    shading: String,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    lights: Option<LightsSection>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    table: Option<ShadingTable>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    glow: Option<GelGlow>,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct LightsSection {
    /// Unit directions from the surface towards the red, green and blue light (x along the
    /// frame's columns, y along its rows, z towards the camera).
    #[serde(deserialize_with = "crate::serde_exact::matrix")]
    directions: [[f64; 3]; 3],
    ambient: f64,
    gain: f64,
}

#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct MarkersSection {
    cols: u32,
    rows: u32,
    pitch_mm: f64,
    radius_mm: f64,
    darkness: f64,
}

const SYNTHETIC: &str = "synthetic";

impl SensorProfile {
    /// The stock GelSight Mini: its spec, analytic lights over the twin's synthetic
    /// background, vignetting and camera noise as the twin has always rendered it.
    pub fn gelsight_mini() -> Self {
        Self::stock(TactileSpec::gelsight_mini())
    }

    /// A profile for `spec` with the stock optics (a what-if sensor: another gel, another
    /// marker grid).
    pub fn stock(spec: TactileSpec) -> Self {
        Self {
            source: String::new(),
            spec,
            background: None,
            noise_sigma_grey: 0.5,
            vignette: 0.55,
            exposure: 1.0,
            marker_darkness: 0.82,
            fit: None,
        }
    }

    /// Reads and checks a profile file (its background PNG beside it); errors name the file
    /// and the field.
    pub fn load(path: &Path) -> Result<Self, ProfileError> {
        let file = path.display().to_string();
        let text = crate::text_file::read_to_string(path).map_err(|e| ProfileError {
            file: file.clone(),
            field: "file".into(),
            message: format!("cannot read: {e}"),
        })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::from_toml(&text, &file, &dir)
    }

    /// Parses and checks a profile's text; a background file is looked for in `dir`.
    pub fn from_toml(text: &str, file: &str, dir: &Path) -> Result<Self, ProfileError> {
        let err = |field: &str, message: String| ProfileError {
            file: file.into(),
            field: field.into(),
            message,
        };
        let mut raw: ProfileFile = toml::from_str(text)
            .map_err(|e| err("toml", crate::file_failure::toml_failure(text, &e)))?;
        if raw.format != PROFILE_FORMAT {
            return Err(err(
                "format",
                format!("'{}', expected '{PROFILE_FORMAT}'", raw.format),
            ));
        }
        // A table profile's lights are the stock ones: nothing reads them.
        let (photometric, table) = match raw.optics.shading.as_str() {
            "lights" => {
                let l = raw.optics.lights.as_ref().ok_or_else(|| {
                    err(
                        "optics.lights",
                        "missing: shading = \"lights\" needs an [optics.lights] table".into(),
                    )
                })?;
                let lights = PhotometricModel {
                    lights: l.directions.map(glam::DVec3::from_array),
                    ambient: l.ambient,
                    gain: l.gain,
                };
                (lights, None)
            }
            "table" => {
                let table = raw.optics.table.take().ok_or_else(|| {
                    err(
                        "optics.table",
                        "missing: shading = \"table\" needs an [optics.table] table".into(),
                    )
                })?;
                (PhotometricModel::default(), Some(table))
            }
            other => {
                return Err(err(
                    "optics.shading",
                    format!("'{other}', expected 'lights' or 'table'"),
                ));
            }
        };
        let background = match raw.optics.background.as_str() {
            SYNTHETIC => None,
            name => {
                let at = dir.join(name);
                let img = crate::image_file::open(&at).map_err(|e| {
                    err(
                        "optics.background",
                        format!("{}: not a readable image: {e}", at.display()),
                    )
                })?;
                if let Some(fault) = crate::image_file::tactile_frame_fault(&img) {
                    return Err(err(
                        "optics.background",
                        format!("{}: {fault}", at.display()),
                    ));
                }
                Some(img.to_rgb8())
            }
        };
        let c = &raw.camera;
        let m = &raw.markers;
        let profile = SensorProfile {
            source: raw.source.clone(),
            spec: TactileSpec {
                model: raw.name.clone(),
                width_px: c.width_px,
                height_px: c.height_px,
                mm_per_px: c.mm_per_px,
                gel: GelSpec {
                    modulus_mpa: raw.gel.modulus_mpa,
                    poisson: raw.gel.poisson,
                    thickness_mm: raw.gel.thickness_mm,
                },
                photometric,
                table,
                glow: raw.optics.glow,
                markers: MarkerGrid {
                    cols: m.cols,
                    rows: m.rows,
                    pitch_mm: m.pitch_mm,
                    radius_mm: m.radius_mm,
                },
                frame_rate_hz: c.frame_rate_hz,
            },
            background,
            noise_sigma_grey: c.noise_sigma_grey,
            vignette: c.vignette,
            exposure: c.exposure,
            marker_darkness: m.darkness,
            fit: raw.fit,
        };
        profile
            .validate()
            .map_err(|(field, message)| err(&field, message))?;
        Ok(profile)
    }

    /// Checks every field's range and that the parts agree; Err names the field as the
    /// profile file does.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let bad = |field: &str, message: String| Err((field.to_string(), message));
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if self.name().trim().is_empty() {
            return bad("name", "must not be empty".into());
        }
        if self.source.chars().count() > MAX_SOURCE_CHARS
            || self
                .source
                .chars()
                .any(|c| c.is_control() && c != '\n' && c != '\t')
        {
            return bad(
                "source",
                format!(
                    "{} characters, expected at most {MAX_SOURCE_CHARS} of text without control characters",
                    self.source.chars().count()
                ),
            );
        }
        let s = &self.spec;
        // The name as well: printed in every report and answer, a line of plain text.
        if let Err((field, message)) = s.check() {
            return bad(&profile_field(&field), message);
        }
        if !(self.noise_sigma_grey.is_finite() && (0.0..=64.0).contains(&self.noise_sigma_grey)) {
            return bad(
                "camera.noise_sigma_grey",
                format!("{}, expected 0..=64 grey levels", self.noise_sigma_grey),
            );
        }
        if !(self.vignette.is_finite() && (0.0..=1.0).contains(&self.vignette)) {
            return bad(
                "camera.vignette",
                format!("{}, expected 0..=1", self.vignette),
            );
        }
        if self.background.is_some() && self.vignette != 0.0 {
            return bad(
                "camera.vignette",
                format!(
                    "{}, but the background is a real frame, which holds its own vignetting: expected 0",
                    self.vignette
                ),
            );
        }
        if !(self.exposure.is_finite() && self.exposure > 0.0 && self.exposure <= 4.0) {
            return bad(
                "camera.exposure",
                format!(
                    "{}, expected a gain in (0, 4]",
                    crate::printable::short_number(self.exposure)
                ),
            );
        }
        if let Some(bg) = &self.background
            && bg.dimensions() != (s.width_px, s.height_px)
        {
            return bad(
                "optics.background",
                format!(
                    "the image is {} x {} px, the camera {} x {}",
                    bg.width(),
                    bg.height(),
                    s.width_px,
                    s.height_px
                ),
            );
        }
        if !(self.marker_darkness.is_finite() && (0.0..=1.0).contains(&self.marker_darkness)) {
            return bad(
                "markers.darkness",
                format!("{}, expected 0..=1", self.marker_darkness),
            );
        }
        if let Some(fit) = &self.fit
            && !(positive(fit.ball_radius_mm) && fit.rms_grey.iter().all(|v| v.is_finite()))
        {
            return bad(
                "fit",
                "ball_radius_mm must be > 0 and rms_grey finite".into(),
            );
        }
        Ok(())
    }

    fn to_file(&self, background: &str) -> ProfileFile {
        let s = &self.spec;
        let (shading, lights, table) = match &s.table {
            None => (
                "lights",
                Some(LightsSection {
                    directions: s.photometric.lights.map(|d| d.to_array()),
                    ambient: s.photometric.ambient,
                    gain: s.photometric.gain,
                }),
                None,
            ),
            Some(t) => ("table", None, Some(t.clone())),
        };
        ProfileFile {
            format: PROFILE_FORMAT.into(),
            name: self.name().into(),
            source: self.source.clone(),
            camera: CameraSection {
                width_px: s.width_px,
                height_px: s.height_px,
                mm_per_px: s.mm_per_px,
                frame_rate_hz: s.frame_rate_hz,
                noise_sigma_grey: self.noise_sigma_grey,
                vignette: self.vignette,
                exposure: self.exposure,
            },
            gel: GelSection {
                modulus_mpa: s.gel.modulus_mpa,
                poisson: s.gel.poisson,
                thickness_mm: s.gel.thickness_mm,
            },
            optics: OpticsSection {
                background: background.into(),
                shading: shading.into(),
                lights,
                table,
                glow: s.glow.clone(),
            },
            markers: MarkersSection {
                cols: s.markers.cols,
                rows: s.markers.rows,
                pitch_mm: s.markers.pitch_mm,
                radius_mm: s.markers.radius_mm,
                darkness: self.marker_darkness,
            },
            fit: self.fit.clone(),
        }
    }

    /// The profile's TOML, its background (if any) named `background_file`.
    pub fn to_toml(&self, background_file: &str) -> String {
        let name = if self.background.is_some() {
            background_file
        } else {
            SYNTHETIC
        };
        toml::to_string(&self.to_file(name)).expect("a profile serialises to TOML")
    }

    /// The background's file name beside a profile written to `path`: `NAME.background.png`.
    pub fn background_path(path: &Path) -> PathBuf {
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "sensor".into());
        path.with_file_name(format!("{stem}.background.png"))
    }

    /// The files the profile at `path` is made of: itself, and the background image its
    /// text names (when it names a file). Read loosely: for keeping outputs off them, not
    /// for loading.
    pub fn files(path: &Path) -> Vec<PathBuf> {
        let background = std::fs::read_to_string(path)
            .ok()
            .and_then(|text| text.parse::<toml::Table>().ok())
            .and_then(|t| {
                t.get("optics")?
                    .get("background")?
                    .as_str()
                    .filter(|name| *name != SYNTHETIC)
                    .map(|name| path.parent().unwrap_or(Path::new("")).join(name))
            });
        std::iter::once(path.to_path_buf())
            .chain(background)
            .collect()
    }

    /// Its name and the SHA-256 of its contents.
    pub fn id(&self) -> ProfileId {
        let mut h = Sha256::new();
        h.update(self.to_toml("").as_bytes());
        if let Some(bg) = &self.background {
            h.update(bg.width().to_le_bytes());
            h.update(bg.height().to_le_bytes());
            h.update(bg.as_raw());
        }
        let digest = h.finalize();
        ProfileId {
            name: self.name().into(),
            sha256: digest.iter().map(|b| format!("{b:02x}")).collect(),
        }
    }

    pub fn name(&self) -> &str {
        &self.spec.model
    }

    /// How its gel's slopes become colour.
    pub fn shading(&self) -> Shading {
        match &self.spec.table {
            Some(t) => Shading::Table(t.clone()),
            None => Shading::Lights(self.spec.photometric),
        }
    }
}

/// A spec field (`TactileSpec::check`'s name) as the profile file names it: the camera's
/// numbers under `camera`, the shading under `optics`.
fn profile_field(spec_field: &str) -> String {
    match spec_field {
        "model" => "name".into(),
        "width_px" | "height_px" | "mm_per_px" | "frame_rate_hz" => format!("camera.{spec_field}"),
        "photometric.lights" => "optics.lights.directions".into(),
        "table" => "optics.table".into(),
        _ => match spec_field.split_once('.') {
            Some(("photometric", rest)) => format!("optics.lights.{rest}"),
            _ if spec_field.starts_with("glow") => format!("optics.{spec_field}"),
            _ => spec_field.into(),
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<SensorProfile, ProfileError> {
        SensorProfile::from_toml(text, "p.toml", Path::new("."))
    }

    #[test]
    fn the_stock_profile_round_trips_through_its_toml() {
        let stock = SensorProfile::gelsight_mini();
        let back = parse(&stock.to_toml("")).unwrap();
        assert_eq!(back, stock);
        assert_eq!(back.id(), stock.id());
        assert_eq!(stock.id().sha256.len(), 64);
    }

    #[test]
    fn a_calibrated_profile_round_trips_with_its_background() {
        let dir = tempfile::tempdir().unwrap();
        let mut p = SensorProfile::gelsight_mini();
        p.spec.model = "bench sensor".into();
        // A real background holds the sensor's vignetting already.
        p.vignette = 0.0;
        p.spec.table = Some(ShadingTable {
            mag_bins: 2,
            dir_bins: 3,
            mag_max: 1.5,
            coefficients: (0..2 * 3 * 3 * 6).map(|k| k as f32 * 0.37 - 3.1).collect(),
        });
        p.background = Some(RgbImage::from_fn(320, 240, |x, y| {
            image::Rgb([(x % 251) as u8, (y % 241) as u8, 90])
        }));
        p.spec.glow = Some(GelGlow {
            colour: vec![crate::tactile::gel_glow::ColourGlow {
                sigma_px: 3.0,
                mix: [[0.7, 0.1, 0.0], [0.0, 0.6, -0.05], [0.2, 0.0, 0.9]],
            }],
            magnitude: vec![crate::tactile::gel_glow::ScalarGlow {
                sigma_px: 27.0,
                colour: [0.11, -0.02, 0.3],
            }],
            indentation: vec![crate::tactile::gel_glow::ScalarGlow {
                sigma_px: 0.0,
                colour: [-23.5, -9.1, -6.5],
            }],
            indented_colour: vec![crate::tactile::gel_glow::ColourGlow {
                sigma_px: 0.0,
                mix: [[0.2, 0.0, 0.0], [0.0, 0.1, 0.0], [0.0, 0.0, -0.1]],
            }],
        });
        let path = dir.path().join("bench.toml");
        let bg = SensorProfile::background_path(&path);
        p.background.as_ref().unwrap().save(&bg).unwrap();
        std::fs::write(&path, p.to_toml("bench.background.png")).unwrap();
        let back = SensorProfile::load(&path).unwrap();
        assert_eq!(back, p);
        assert_eq!(back.id(), p.id());
        assert_ne!(back.id(), SensorProfile::gelsight_mini().id());
        // Vignetting laid over a real background again is refused.
        p.vignette = 1.0;
        std::fs::write(&path, p.to_toml("bench.background.png")).unwrap();
        let e = SensorProfile::load(&path).unwrap_err();
        assert_eq!(e.field, "camera.vignette", "{e}");
        // A background that is no tactile frame (greyscale, or blown out) is refused.
        p.vignette = 0.0;
        std::fs::write(&path, p.to_toml("bench.background.png")).unwrap();
        let (w, h) = p.background.as_ref().unwrap().dimensions();
        image::GrayImage::from_pixel(w, h, image::Luma([120]))
            .save(&bg)
            .unwrap();
        let e = SensorProfile::load(&path).unwrap_err();
        assert_eq!(e.field, "optics.background", "{e}");
        RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]))
            .save(&bg)
            .unwrap();
        let e = SensorProfile::load(&path).unwrap_err();
        assert!(e.to_string().contains("saturated"), "{e}");
    }

    #[test]
    fn any_change_of_contents_changes_the_hash() {
        let stock = SensorProfile::gelsight_mini();
        let mut softer = stock.clone();
        softer.spec.gel.modulus_mpa = 0.2;
        assert_ne!(softer.id().sha256, stock.id().sha256);
        // The exposure field is written only when it is not 1: the stock text is unchanged.
        assert!(!stock.to_toml("").contains("exposure"));
        let mut brighter = stock.clone();
        brighter.exposure = 1.5;
        let text = brighter.to_toml("");
        assert!(text.contains("exposure = 1.5"), "{text}");
        let back = SensorProfile::from_toml(&text, "b.toml", Path::new(".")).unwrap();
        assert_eq!(back.exposure, 1.5);
    }

    #[test]
    fn bad_fields_are_named() {
        let stock = SensorProfile::gelsight_mini().to_toml("");
        for (from, to, field) in [
            ("mm_per_px = 0.0634", "mm_per_px = -1.0", "camera.mm_per_px"),
            ("poisson = 0.49", "poisson = 0.7", "gel.poisson"),
            (
                "vignette = 0.55",
                "vignette = 0.55\nexposure = 0.0",
                "camera.exposure",
            ),
            (
                "vignette = 0.55",
                "vignette = 0.55\nexposure = 1e300",
                "camera.exposure",
            ),
            (
                "thickness_mm = 4.0",
                "thickness_mm = nan",
                "gel.thickness_mm",
            ),
            // A gel far thinner than its contact stalls the layer solve.
            (
                "thickness_mm = 4.0",
                "thickness_mm = 0.01",
                "gel.thickness_mm",
            ),
            ("vignette = 0.55", "vignette = 2.0", "camera.vignette"),
            ("gain = 1.0", "gain = 1e300", "optics.lights.gain"),
            ("ambient = 0.45", "ambient = 11.0", "optics.lights.ambient"),
            ("darkness = 0.82", "darkness = -0.1", "markers.darkness"),
            ("radius_mm = 0.25", "radius_mm = 1.5", "markers.radius_mm"),
            (
                "shading = \"lights\"",
                "shading = \"magic\"",
                "optics.shading",
            ),
            (
                "background = \"synthetic\"",
                "background = \"nowhere.png\"",
                "optics.background",
            ),
            (
                "format = \"tactex-sensor-profile/1\"",
                "format = \"tactex-sensor-profile/9\"",
                "format",
            ),
        ] {
            assert!(stock.contains(from), "{from} not in\n{stock}");
            let e = match parse(&stock.replacen(from, to, 1)) {
                Ok(_) => panic!("{to}: accepted"),
                Err(e) => e,
            };
            assert_eq!(e.field, field, "{to}: {e}");
            assert!(!e.to_string().contains('\n'), "{e}");
        }
        let glowing = format!(
            "{stock}\n[[optics.glow.magnitude]]\nsigma_px = 500.0\ncolour = [0.1, 0.2, 0.3]\n"
        );
        let e = parse(&glowing).unwrap_err();
        assert_eq!(e.field, "optics.glow.magnitude[0].sigma_px", "{e}");
        let e = parse("format = 3").unwrap_err();
        assert_eq!(e.field, "toml");
        // Text that reaches every report: one short printable line of a name, a bounded note.
        for (to, field) in [
            ("name = \"Mini\\u001b[31m\"", "name"),
            ("name = \"Mini\\u202Eevil\"", "name"),
            (
                &*format!(
                    "name = \"{}\"",
                    "x".repeat(crate::printable::MAX_NAME_CHARS + 1)
                ),
                "name",
            ),
            (
                &*format!(
                    "name = \"m\"\nsource = \"{}\"",
                    "x".repeat(MAX_SOURCE_CHARS + 1)
                ),
                "source",
            ),
        ] {
            let text = stock.replacen("name = \"GelSight Mini\"\nsource = \"\"", to, 1);
            assert_ne!(text, stock);
            let e = parse(&text).unwrap_err();
            assert_eq!(e.field, field, "{e}");
            assert!(
                e.to_string().len() < 400 && !e.to_string().contains('\u{1b}'),
                "{e}"
            );
        }
        // A scale no sensor has (1e-9 mm a pixel).
        let e = parse(&stock.replacen("mm_per_px = 0.0634", "mm_per_px = 1e-9", 1)).unwrap_err();
        assert_eq!(e.field, "camera.mm_per_px", "{e}");
        // Extra elements in a fixed-size list are refused, not dropped.
        let lights = stock.lines().find(|l| l.starts_with("directions")).unwrap();
        let longer = lights.replacen("]]", "], [0.0, 0.0, 1.0]]", 1);
        let e = parse(&stock.replacen(lights, &longer, 1)).unwrap_err();
        assert!(e.message.contains("exactly"), "{e}");
        let e = parse(&stock.replacen("[gel]", "[gel]\nshore = 3", 1)).unwrap_err();
        assert!(e.message.contains("shore"), "{e}");
    }
}
