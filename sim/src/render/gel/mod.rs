//! GelSight image synthesis: the gel's displacement fields at pixel resolution -> surface
//! slopes -> shading over the no-contact background (analytic coloured lights or a calibrated
//! gradient table) -> vignetting -> glow (light scattered in the gel, when the profile has
//! one) -> marker dots moved by the lateral field -> seeded camera noise -> 8-bit RGB.
//!
//! One contract, two implementations: `CpuRenderer` (the reference, Rust, f32 like the
//! shaders) and `GpuRenderer` (the WGSL compute stages in `shaders/` through wgpu). Both
//! render batches of presses; the GPU renders a whole batch per dispatch.

mod cpu;
mod device;
mod fields;
mod gpu;
mod noise;

pub use crate::render::device::{DeviceChoice, RenderError, adapters};
pub use cpu::CpuRenderer;
pub use device::{RendererChoice, open_renderer};
pub use fields::image_fields;
pub use fields::{pad_rect, pixel_centre_mm};
pub use gpu::{GpuRenderer, SHADER_SOURCES, shader_source};
pub use noise::gaussian3;

use image::RgbImage;
pub use tactex_core::tactile::gel_glow::GelGlow;
use tactex_core::tactile::sensor_profile::SensorProfile;
pub use tactex_core::tactile::sensor_profile::Shading;
use tactex_core::tactile::spec::TactileSpec;

/// Everything about the sensor's optics that stays fixed from frame to frame.
#[derive(Clone, Debug, PartialEq)]
pub struct SensorOptics {
    pub width: u32,
    pub height: u32,
    pub mm_per_px: f64,
    /// The no-contact frame in grey levels, row-major (w * h).
    pub background: Vec<[f32; 3]>,
    pub shading: Shading,
    /// Rest centres of the marker dots (pixels, x right, y down; pixel centres at k + 1/2).
    pub markers: Vec<[f32; 2]>,
    pub marker_radius_px: f32,
    /// Fraction of the light a dot's centre blocks.
    pub marker_darkness: f32,
    /// Relative darkening at the frame's corners: gain 1 - vignette * (u^2 + v^2), u, v in
    /// [-1/2, 1/2]. Zero when the background is a real frame (it has the vignetting in it).
    pub vignette: f32,
    /// Gain on the light reaching the camera (the profile's `camera.exposure`), applied after
    /// the marker dots and before the noise.
    pub exposure: f32,
    /// Camera noise per channel (grey levels, 1 sigma).
    pub noise_sigma: f32,
    /// Light scattered in the gel: the shading's change is replaced by its glow (before the
    /// marker dots and the noise). None: the change as shaded.
    pub glow: Option<GelGlow>,
}

/// The gel's displacement at every pixel centre of one frame (mm; normal = into the gel,
/// towards the camera).
#[derive(Clone, Debug, PartialEq)]
pub struct GelImageFields {
    pub width: u32,
    pub height: u32,
    pub normal_mm: Vec<f32>,
    pub lateral_x_mm: Vec<f32>,
    pub lateral_y_mm: Vec<f32>,
}

impl GelImageFields {
    /// The undisturbed gel.
    pub fn flat(width: u32, height: u32) -> Self {
        let n = (width * height) as usize;
        Self {
            width,
            height,
            normal_mm: vec![0.0; n],
            lateral_x_mm: vec![0.0; n],
            lateral_y_mm: vec![0.0; n],
        }
    }
}

/// One frame to render: the gel's fields and the seed of its camera noise.
#[derive(Clone, Copy, Debug)]
pub struct PressFrame<'a> {
    pub fields: &'a GelImageFields,
    pub seed: u32,
}

pub(crate) fn invalid(field: &str, message: impl Into<String>) -> RenderError {
    RenderError::Invalid {
        field: field.into(),
        message: message.into(),
    }
}

/// Renders batches of presses through one optics description.
pub trait GelRenderer {
    /// What renders: "cpu" or the GPU adapter's name.
    fn name(&self) -> String;
    fn render_batch(
        &mut self,
        optics: &SensorOptics,
        frames: &[PressFrame],
    ) -> Result<Vec<RgbImage>, RenderError>;
}

/// The synthetic no-contact frame of a GelSight-like sensor: a bluish-grey pad lit from the
/// sides (vignetting is applied by the renderer, not baked in).
fn synthetic_background(width: u32, height: u32) -> Vec<[f32; 3]> {
    let (w, h) = (width as f32, height as f32);
    (0..height)
        .flat_map(|j| (0..width).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x, y) = ((i as f32 + 0.5) / w - 0.5, (j as f32 + 0.5) / h - 0.5);
            [150.0 + 18.0 * y, 138.0 - 14.0 * x, 158.0 + 14.0 * x]
        })
        .collect()
}

impl SensorOptics {
    /// The spec's sensor with the stock optics (synthetic background, analytic lights, its
    /// marker grid): `SensorProfile::stock`.
    pub fn for_spec(spec: &TactileSpec) -> Self {
        Self::for_profile(&SensorProfile::stock(spec.clone()))
    }

    /// What the profile's sensor renders with: its background (or the synthetic one), its
    /// shading, marker grid, vignetting and camera noise.
    pub fn for_profile(profile: &SensorProfile) -> Self {
        let spec = &profile.spec;
        let background = match &profile.background {
            Some(img) => img.pixels().map(|p| p.0.map(f32::from)).collect(),
            None => synthetic_background(spec.width_px, spec.height_px),
        };
        Self {
            width: spec.width_px,
            height: spec.height_px,
            mm_per_px: spec.mm_per_px,
            background,
            shading: profile.shading(),
            markers: spec
                .marker_rest_px()
                .into_iter()
                .map(|(x, y)| [x as f32, y as f32])
                .collect(),
            marker_radius_px: (spec.markers.radius_mm / spec.mm_per_px) as f32,
            marker_darkness: profile.marker_darkness as f32,
            vignette: profile.vignette as f32,
            exposure: profile.exposure as f32,
            noise_sigma: profile.noise_sigma_grey as f32,
            glow: profile.spec.glow.clone(),
        }
    }

    pub fn pixel_count(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// Checks sizes and ranges; names the field that is wrong.
    pub fn validate(&self) -> Result<(), RenderError> {
        if self.width < 2 || self.height < 2 || self.width > 8192 || self.height > 8192 {
            return Err(invalid(
                "optics.size",
                format!("{} x {} px (each side 2..=8192)", self.width, self.height),
            ));
        }
        if !(self.mm_per_px.is_finite() && self.mm_per_px > 0.0) {
            return Err(invalid("optics.mm_per_px", "must be a positive number"));
        }
        if self.background.len() != self.pixel_count() {
            return Err(invalid(
                "optics.background",
                format!(
                    "has {} pixels, the frame {}",
                    self.background.len(),
                    self.pixel_count()
                ),
            ));
        }
        if !all_finite(self.background.as_flattened()) {
            return Err(invalid("optics.background", "must be finite"));
        }
        let finite_nonneg = |v: f32| v.is_finite() && v >= 0.0;
        for (name, v) in [
            ("optics.marker_radius_px", self.marker_radius_px),
            ("optics.vignette", self.vignette),
            ("optics.exposure", self.exposure),
            ("optics.noise_sigma", self.noise_sigma),
        ] {
            if !finite_nonneg(v) {
                return Err(invalid(
                    name,
                    format!("must be a non-negative number, got {v}"),
                ));
            }
        }
        if !(0.0..=1.0).contains(&self.marker_darkness) {
            return Err(invalid("optics.marker_darkness", "must be in [0, 1]"));
        }
        if self.markers.iter().flatten().any(|v| !v.is_finite()) {
            return Err(invalid("optics.markers", "positions must be finite"));
        }
        if self.markers.len() > 65_536 {
            return Err(invalid("optics.markers", "at most 65536 markers"));
        }
        match &self.shading {
            Shading::Lights(model) => {
                let ok = model.lights.iter().all(|l| l.is_finite())
                    && model.ambient.is_finite()
                    && model.gain.is_finite()
                    && model
                        .lights
                        .iter()
                        .all(|l| model.ambient + model.gain * l.z > 0.0);
                if !ok {
                    return Err(invalid(
                        "optics.shading",
                        "lights must be finite and light the flat gel",
                    ));
                }
            }
            Shading::Table(table) => table
                .validate()
                .map_err(|e| invalid("optics.shading", e.to_string()))?,
        }
        if let Some(glow) = &self.glow {
            glow.validate()
                .map_err(|(field, message)| invalid(&field, message))?;
        }
        Ok(())
    }

    pub(crate) fn check_frames(&self, frames: &[PressFrame]) -> Result<(), RenderError> {
        self.validate()?;
        for (k, f) in frames.iter().enumerate() {
            let n = self.pixel_count();
            let f = f.fields;
            if (f.width, f.height) != (self.width, self.height)
                || f.normal_mm.len() != n
                || f.lateral_x_mm.len() != n
                || f.lateral_y_mm.len() != n
            {
                return Err(invalid(
                    &format!("frames[{k}]"),
                    format!(
                        "fields are {} x {}, the sensor {} x {}",
                        f.width, f.height, self.width, self.height
                    ),
                ));
            }
            if !(all_finite(&f.normal_mm)
                && all_finite(&f.lateral_x_mm)
                && all_finite(&f.lateral_y_mm))
            {
                return Err(invalid(&format!("frames[{k}]"), "fields must be finite"));
            }
        }
        Ok(())
    }
}

/// Whether every value is finite, without stopping at the first that is not: a plain
/// reduction vectorises, and the check runs on every frame's three fields.
fn all_finite(values: &[f32]) -> bool {
    values.iter().fold(true, |ok, v| ok & v.is_finite())
}

/// The uniform block every shader stage reads (`RenderParams` in shaders/common.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct RenderParams {
    pub lights: [[f32; 4]; 3],
    pub width: u32,
    pub height: u32,
    pub frames: u32,
    pub shading: u32,
    pub mm_per_px: f32,
    pub ambient: f32,
    pub light_gain: f32,
    pub noise_sigma: f32,
    pub vignette: f32,
    pub marker_radius_px: f32,
    pub marker_darkness: f32,
    pub markers: u32,
    pub mag_bins: u32,
    pub dir_bins: u32,
    pub mag_max: f32,
    pub exposure: f32,
}

impl RenderParams {
    pub(crate) fn new(optics: &SensorOptics, frames: u32) -> Self {
        let (lights, ambient, light_gain, shading, mag_bins, dir_bins, mag_max) =
            match &optics.shading {
                Shading::Lights(m) => (
                    m.lights.map(|l| [l.x as f32, l.y as f32, l.z as f32, 0.0]),
                    m.ambient as f32,
                    m.gain as f32,
                    0,
                    2,
                    1,
                    1.0,
                ),
                Shading::Table(t) => (
                    [[0.0; 4]; 3],
                    0.0,
                    0.0,
                    1,
                    t.mag_bins,
                    t.dir_bins,
                    t.mag_max,
                ),
            };
        Self {
            lights,
            width: optics.width,
            height: optics.height,
            frames,
            shading,
            mm_per_px: optics.mm_per_px as f32,
            ambient,
            light_gain,
            noise_sigma: optics.noise_sigma,
            vignette: optics.vignette,
            marker_radius_px: optics.marker_radius_px,
            marker_darkness: optics.marker_darkness,
            markers: optics.markers.len() as u32,
            mag_bins,
            dir_bins,
            mag_max,
            exposure: optics.exposure,
        }
    }
}
