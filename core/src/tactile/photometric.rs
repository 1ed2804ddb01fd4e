//! The photometric model of the gel: three coloured lights, one per colour channel, shining
//! on the gel surface as the camera sees it from behind the acrylic.
//!
//! Forward (rendering): surface gradient -> per-channel gain over the no-contact frame.
//! Inverse (perception): per-channel gain -> surface gradient, exact for this model (three
//! independent light directions make it a 3x3 photometric-stereo solve).
//!
//! Image axes: x along columns, y along rows (down), z towards the camera. The gel's normal
//! indentation w (mm, positive into the gel, towards the camera) is the surface height.

use glam::{DMat3, DVec3};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhotometricModel {
    /// Unit direction from the surface towards the red, green and blue light.
    pub lights: [DVec3; 3],
    pub ambient: f64,
    pub gain: f64,
}

impl Default for PhotometricModel {
    /// Lights at 120 degree spacing around the pad, 35 degrees above the gel plane, as in the
    /// GelSight Mini's ring of red, green and blue LEDs.
    fn default() -> Self {
        let elevation = 35f64.to_radians();
        let light = |azimuth_deg: f64| {
            let a = azimuth_deg.to_radians();
            DVec3::new(
                a.cos() * elevation.cos(),
                a.sin() * elevation.cos(),
                elevation.sin(),
            )
        };
        Self {
            lights: [light(90.0), light(210.0), light(330.0)],
            ambient: 0.45,
            gain: 1.0,
        }
    }
}

impl PhotometricModel {
    fn normal(gx: f64, gy: f64) -> DVec3 {
        DVec3::new(-gx, -gy, 1.0).normalize()
    }

    /// Per-channel intensity relative to the flat gel for surface slope (dw/dx, dw/dy).
    pub fn gain_for_slope(&self, gx: f64, gy: f64) -> [f64; 3] {
        let n = Self::normal(gx, gy);
        std::array::from_fn(|c| {
            let l = self.lights[c];
            (self.ambient + self.gain * n.dot(l).max(0.0)) / (self.ambient + self.gain * l.z)
        })
    }

    /// Surface slope (dw/dx, dw/dy) from per-channel gains over the no-contact frame.
    /// None where the gains are not consistent with any lit surface (saturated, shadowed).
    pub fn slope_for_gain(&self, gain: [f64; 3]) -> Option<(f64, f64)> {
        let m = DVec3::from_array(std::array::from_fn(|c| {
            let flat = self.ambient + self.gain * self.lights[c].z;
            (gain[c] * flat - self.ambient) / self.gain
        }));
        let l = DMat3::from_cols(self.lights[0], self.lights[1], self.lights[2]).transpose();
        let n = l.inverse() * m;
        (n.z > 0.05).then(|| (-n.x / n.z, -n.y / n.z))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_gel_has_unit_gain() {
        let g = PhotometricModel::default().gain_for_slope(0.0, 0.0);
        assert!(g.iter().all(|v| (v - 1.0).abs() < 1e-12));
    }

    #[test]
    fn inverse_recovers_slopes_exactly() {
        let model = PhotometricModel::default();
        for (gx, gy) in [(0.0, 0.0), (0.3, -0.1), (-0.5, 0.4), (0.05, 0.6)] {
            let (rx, ry) = model.slope_for_gain(model.gain_for_slope(gx, gy)).unwrap();
            assert!(
                (rx - gx).abs() < 1e-9 && (ry - gy).abs() < 1e-9,
                "({gx},{gy}) -> ({rx},{ry})"
            );
        }
    }
}
