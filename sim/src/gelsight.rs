//! The simulated GelSight Mini: gel fields from the contact model -> surface slopes ->
//! shading of the no-contact background by the photometric model -> marker dots moved by the
//! lateral field -> seeded camera noise. This is the CPU path; the wgpu renderer implements
//! the same contract.

use crate::contact::{GelFields, gel_fields};
use crate::world::SharedWorld;
use image::{Rgb, RgbImage};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use tactex_core::devices::{DeviceError, TactileSensor};
use tactex_core::frames::TactileFrame;
use tactex_core::tactile_spec::TactileSpec;

pub struct SimGelSight {
    world: SharedWorld,
    spec: TactileSpec,
    background: Vec<[f64; 3]>,
    rng: ChaCha8Rng,
    /// Per-channel Gaussian noise (grey levels, 1 sigma).
    pub noise_levels: f64,
}

/// The no-contact frame of a GelSight-like sensor: a bluish-grey pad, lit from the sides,
/// darker towards the corners.
pub fn background(spec: &TactileSpec) -> Vec<[f64; 3]> {
    let (w, h) = (spec.width_px as f64, spec.height_px as f64);
    (0..spec.height_px)
        .flat_map(|j| (0..spec.width_px).map(move |i| (i, j)))
        .map(|(i, j)| {
            let (x, y) = ((i as f64 + 0.5) / w - 0.5, (j as f64 + 0.5) / h - 0.5);
            let vignette = 1.0 - 0.55 * (x * x + y * y);
            [
                (150.0 + 18.0 * y) * vignette,
                (138.0 - 14.0 * x) * vignette,
                (158.0 + 14.0 * x) * vignette,
            ]
        })
        .collect()
}

/// Renders the sensor image for gel fields (None: no contact). Deterministic given `noise`.
pub fn render(
    spec: &TactileSpec,
    background: &[[f64; 3]],
    fields: Option<&GelFields>,
    mut noise: impl FnMut() -> f64,
) -> RgbImage {
    let (w, h) = (spec.width_px as usize, spec.height_px as usize);
    let px = spec.mm_per_px;
    let mut img = vec![[0.0f64; 3]; w * h];
    for j in 0..h {
        for i in 0..w {
            let k = j * w + i;
            let gain = match fields {
                Some(f) => {
                    let at = |ii: usize, jj: usize| f.normal_mm[jj * w + ii];
                    let gx = (at((i + 1).min(w - 1), j) - at(i.saturating_sub(1), j))
                        / (((i + 1).min(w - 1) - i.saturating_sub(1)) as f64 * px);
                    let gy = (at(i, (j + 1).min(h - 1)) - at(i, j.saturating_sub(1)))
                        / (((j + 1).min(h - 1) - j.saturating_sub(1)) as f64 * px);
                    spec.photometric.gain_for_slope(gx, gy)
                }
                None => [1.0; 3],
            };
            img[k] = std::array::from_fn(|c| background[k][c] * gain[c]);
        }
    }
    // Markers: dark dots with an anti-aliased rim, centred where the lateral field moved them.
    let radius_px = spec.markers.radius_mm / px;
    for (mx, my) in spec.marker_rest_px() {
        let (dx, dy) = match fields {
            Some(f) => {
                let (ii, jj) = ((mx as usize).min(w - 1), (my as usize).min(h - 1));
                (
                    f.lateral_x_mm[jj * w + ii] / px,
                    f.lateral_y_mm[jj * w + ii] / px,
                )
            }
            None => (0.0, 0.0),
        };
        let (cx, cy) = (mx + dx, my + dy);
        let reach = radius_px + 1.5;
        for j in
            ((cy - reach).floor().max(0.0) as usize)..((cy + reach).ceil().min(h as f64) as usize)
        {
            for i in ((cx - reach).floor().max(0.0) as usize)
                ..((cx + reach).ceil().min(w as f64) as usize)
            {
                let d = (i as f64 + 0.5 - cx).hypot(j as f64 + 0.5 - cy);
                let cover = (radius_px + 0.5 - d).clamp(0.0, 1.0);
                for c in &mut img[j * w + i] {
                    *c *= 1.0 - 0.82 * cover;
                }
            }
        }
    }
    let mut out = RgbImage::new(spec.width_px, spec.height_px);
    for (p, v) in out.pixels_mut().zip(&img) {
        *p = Rgb(std::array::from_fn(|c| {
            (v[c] + noise()).round().clamp(0.0, 255.0) as u8
        }));
    }
    out
}

impl SimGelSight {
    pub fn new(world: SharedWorld, spec: TactileSpec, seed: u64) -> Self {
        let background = background(&spec);
        Self {
            world,
            spec,
            background,
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x6e15_5157),
            noise_levels: 0.5,
        }
    }
}

impl TactileSensor for SimGelSight {
    fn name(&self) -> &str {
        "sim-gelsight-mini"
    }

    fn spec(&self) -> &TactileSpec {
        &self.spec
    }

    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        let mut world = self.world.lock().expect("world lock");
        let fields = gel_fields(&world, &world.tool, &self.spec);
        let normal =
            Normal::new(0.0, self.noise_levels.max(0.0)).map_err(|e| DeviceError::Failure {
                device: "sim-gelsight-mini".into(),
                message: e.to_string(),
            })?;
        let rng = &mut self.rng;
        let image = render(&self.spec, &self.background, fields.as_ref(), || {
            normal.sample(rng)
        });
        world.time_s += 1.0 / self.spec.frame_rate_hz;
        Ok(TactileFrame {
            image,
            timestamp_s: world.time_s,
        })
    }
}
