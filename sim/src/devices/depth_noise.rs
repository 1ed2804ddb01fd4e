//! Intel RealSense D435 depth noise, applied to a clean depth render: per-frame subpixel
//! disparity noise (sigma_Z = Z^2 s / (f B)), the invalid band on the left edge where the
//! right imager does not see, flying pixels at depth edges, holes on dark and specular spots,
//! and the 1 mm depth unit of the Z16 stream. Each frame draws afresh, so that a 10-frame
//! median and an inner mask matter as they did on the real robot.

use rand::Rng;
use rand_distr::{Distribution, Normal};

/// Parameters of the D435 depth noise model.
#[derive(Clone, Debug, PartialEq)]
pub struct RealSenseNoise {
    /// Stereo baseline (D435: 50 mm).
    pub baseline_m: f64,
    /// 1-sigma subpixel disparity error (Intel's tuning guide: ~0.08 px at good texture).
    pub subpixel_sigma_px: f64,
    /// Pixels beside a depth jump larger than this can fly.
    pub edge_jump_m: f64,
    /// Chance per frame that an edge pixel flies (takes a depth between the two sides).
    pub flying_pixel_prob: f64,
    /// Pixels darker than this (mean of RGB in [0, 1]) have too little texture to match...
    pub dark_level: f64,
    /// ...and drop out with this chance per frame.
    pub dark_hole_prob: f64,
    /// Pixels whose specular highlight exceeds this drop out with `specular_hole_prob`.
    pub specular_level: f64,
    pub specular_hole_prob: f64,
    /// Depth quantum of the Z16 stream (D435 default depth unit: 1 mm).
    pub depth_unit_m: f64,
}

impl Default for RealSenseNoise {
    fn default() -> Self {
        Self {
            baseline_m: 0.050,
            subpixel_sigma_px: 0.08,
            edge_jump_m: 0.01,
            flying_pixel_prob: 0.5,
            dark_level: 0.07,
            dark_hole_prob: 0.6,
            specular_level: 0.25,
            specular_hole_prob: 0.8,
            depth_unit_m: 0.001,
        }
    }
}

/// What the noise needs of a clean render.
pub struct CleanDepth<'a> {
    pub width: usize,
    pub height: usize,
    /// Depth along the optical axis (m); 0 where nothing was hit.
    pub depth_m: &'a [f64],
    /// Shaded colour in [0, 1] and the specular part of it, per pixel.
    pub color: &'a [[f64; 3]],
    pub specular: &'a [f64],
    /// Focal length along x (pixels) of the depth stream.
    pub fx: f64,
}

impl RealSenseNoise {
    /// One noisy depth frame (m, 0 = no depth).
    pub fn apply<R: Rng>(&self, clean: &CleanDepth, rng: &mut R) -> Vec<f32> {
        let (w, h) = (clean.width, clean.height);
        let unit = Normal::new(0.0, 1.0).expect("valid");
        let fb = clean.fx * self.baseline_m;
        let mut out = vec![0f32; w * h];
        for y in 0..h {
            for x in 0..w {
                let i = y * w + x;
                let z = clean.depth_m[i];
                if z <= 0.0 {
                    continue;
                }
                // Noise lives in disparity: d = f B / Z, matched to a fraction of a pixel.
                let mut d = fb / z + self.subpixel_sigma_px * unit.sample(rng);
                if (x as f64) < d {
                    continue;
                }
                let far = [(0i64, 1i64), (0, -1), (1, 0), (-1, 0)]
                    .iter()
                    .filter_map(|(dx, dy)| {
                        let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                        (nx >= 0 && ny >= 0 && (nx as usize) < w && (ny as usize) < h)
                            .then(|| clean.depth_m[ny as usize * w + nx as usize])
                    })
                    .filter(|n| *n > 0.0)
                    .max_by(|a, b| (a - z).abs().total_cmp(&(b - z).abs()));
                if let Some(n) = far
                    && (n - z).abs() > self.edge_jump_m
                    && rng.random::<f64>() < self.flying_pixel_prob
                {
                    // Block matching straddles the edge: a depth somewhere between the sides.
                    let t = rng.random::<f64>();
                    d = fb / (z + t * (n - z));
                }
                let c = clean.color[i];
                let luma = (c[0] + c[1] + c[2]) / 3.0;
                if (luma < self.dark_level && rng.random::<f64>() < self.dark_hole_prob)
                    || (clean.specular[i] > self.specular_level
                        && rng.random::<f64>() < self.specular_hole_prob)
                {
                    continue;
                }
                if d <= 0.0 {
                    continue;
                }
                let noisy = fb / d;
                out[i] = ((noisy / self.depth_unit_m).round() * self.depth_unit_m) as f32;
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// A flat clean render at depth z, mid-grey, matte; tests then edit its pixels.
    struct Plane {
        w: usize,
        h: usize,
        fx: f64,
        depth: Vec<f64>,
        color: Vec<[f64; 3]>,
        specular: Vec<f64>,
    }

    impl Plane {
        fn new(w: usize, h: usize, fx: f64, z: f64) -> Self {
            Self {
                w,
                h,
                fx,
                depth: vec![z; w * h],
                color: vec![[0.5; 3]; w * h],
                specular: vec![0.0; w * h],
            }
        }

        fn view(&self) -> CleanDepth<'_> {
            CleanDepth {
                width: self.w,
                height: self.h,
                depth_m: &self.depth,
                color: &self.color,
                specular: &self.specular,
                fx: self.fx,
            }
        }
    }

    #[test]
    fn depth_noise_grows_with_the_square_of_depth_as_stereo_theory_says() {
        let noise = RealSenseNoise {
            depth_unit_m: 1e-6,
            ..RealSenseNoise::default()
        };
        let (w, h, fx) = (200, 100, 600.0);
        for z in [0.5, 1.0, 2.0] {
            let plane = Plane::new(w, h, fx, z);
            let frame = noise.apply(&plane.view(), &mut ChaCha8Rng::seed_from_u64(1));
            let valid: Vec<f64> = frame
                .iter()
                .filter(|v| **v > 0.0)
                .map(|v| *v as f64 - z)
                .collect();
            let n = valid.len() as f64;
            let mean = valid.iter().sum::<f64>() / n;
            let sd = (valid.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let theory = z * z * 0.08 / (fx * 0.05);
            assert!(
                (sd / theory - 1.0).abs() < 0.05,
                "z {z}: sd {sd} vs Z^2 s/(fB) {theory}"
            );
        }
    }

    #[test]
    fn the_left_band_is_invalid_and_as_wide_as_the_disparity() {
        let noise = RealSenseNoise::default();
        let (w, h, fx, z) = (300, 10, 600.0, 0.6);
        let plane = Plane::new(w, h, fx, z);
        let frame = noise.apply(&plane.view(), &mut ChaCha8Rng::seed_from_u64(2));
        // The invalid band on the left edge is as wide as the disparity f B / Z.
        let band = fx * noise.baseline_m / z;
        assert_eq!(band, 50.0);
        for y in 0..h {
            assert!(frame[y * w..y * w + 49].iter().all(|v| *v == 0.0));
            assert!(frame[y * w + 52..(y + 1) * w].iter().all(|v| *v > 0.0));
        }
    }

    #[test]
    fn edges_fly_and_dark_or_specular_spots_drop_out() {
        let noise = RealSenseNoise::default();
        let (w, h, fx) = (200, 40, 600.0);
        let mut plane = Plane::new(w, h, fx, 0.7);
        for y in 0..h {
            for x in 120..w {
                plane.depth[y * w + x] = 0.6;
            }
            plane.color[y * w + 100] = [0.02; 3];
            plane.specular[y * w + 110] = 0.6;
        }
        let frame = noise.apply(&plane.view(), &mut ChaCha8Rng::seed_from_u64(3));
        let frame = &frame;
        let col = |x: usize| (0..h).map(move |y| frame[y * w + x]);
        let between = col(119)
            .chain(col(120))
            .filter(|v| *v > 0.61 && *v < 0.69)
            .count();
        assert!(between > 10, "{between} flying pixels of {}", 2 * h);
        assert!(col(100).filter(|v| *v == 0.0).count() > h / 3);
        assert!(col(110).filter(|v| *v == 0.0).count() > h / 2);
        assert!(col(90).all(|v| (v - 0.7).abs() < 0.01));
    }
}
