//! Fake devices for the pipeline's unit tests: one apple under a downward camera, a gel
//! that shows a disc once the pad is below the apple's top, an arm that may refuse to go
//! low, and an estimator that always reads 2 MPa.

use super::*;
use crate::devices::DeviceError;
use crate::frames::TactileFrame;
use crate::frames::{DepthImage, RgbdFrame};
use crate::geometry::CameraIntrinsics;
use crate::geometry::Pose;
use crate::ground::detect::Detection;
use crate::ground::detect::{DetectError, RgbdView};
use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, ModulusInterval, PhysicsEvidence,
};
use crate::hardness::scale::Hardness;
use crate::tactile::spec::TactileSpec;
use glam::DVec3;
use image::{GrayImage, Luma, Rgb, RgbImage};
use std::cell::Cell;
use std::rc::Rc;

pub(super) const TOP_M: f64 = 0.03;
pub(super) const K: CameraIntrinsics = CameraIntrinsics {
    width: 64,
    height: 48,
    fx: 60.0,
    fy: 60.0,
    cx: 32.0,
    cy: 24.0,
};

pub(super) fn on_apple(x: u32, y: u32) -> bool {
    (x as f64 - 32.0).hypot(y as f64 - 24.0) < 14.0
}

pub(super) struct Camera;
impl RgbdCamera for Camera {
    fn name(&self) -> &str {
        "fake-camera"
    }
    fn intrinsics(&self) -> CameraIntrinsics {
        K
    }
    fn pose(&self) -> Pose {
        Pose::tool_down(DVec3::new(0.0, 0.0, 0.7))
    }
    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        Ok(RgbdFrame {
            color: RgbImage::from_fn(64, 48, |x, y| {
                if on_apple(x, y) {
                    Rgb([180, 30, 30])
                } else {
                    Rgb([120, 110, 100])
                }
            }),
            depth_m: DepthImage::from_fn(64, 48, |x, y| {
                Luma([if on_apple(x, y) {
                    0.7 - TOP_M as f32
                } else {
                    0.7
                }])
            }),
            timestamp_s: 0.0,
        })
    }
}

pub(super) struct OneApple;
impl Detector for OneApple {
    fn name(&self) -> &str {
        "one-apple"
    }
    fn detect(&self, _: &RgbdView<'_>) -> Result<Vec<Detection>, DetectError> {
        Ok(vec![Detection {
            label: "apple".into(),
            score: 0.9,
            bbox: [18, 10, 46, 38],
            mask: GrayImage::from_fn(64, 48, |x, y| Luma([255 * on_apple(x, y) as u8])),
            size_m: [0.07, 0.07, TOP_M],
        }])
    }
}

/// The gel shows a dark disc at `centre` growing with the pad's depth below the apple's
/// top (never, when `shows` is false). With `object_m` the disc is instead where a point
/// that far (world x, y) from the pad's first place lies under the pad, wherever the arm
/// has put the pad since.
pub(super) struct Gel {
    pub(super) z: Rc<Cell<f64>>,
    pub(super) xy: Rc<Cell<(f64, f64)>>,
    pub(super) first_xy: Cell<Option<(f64, f64)>>,
    pub(super) centre: (f64, f64),
    pub(super) object_m: Option<(f64, f64)>,
    pub(super) shows: bool,
    pub(super) spec: TactileSpec,
}
impl TactileSensor for Gel {
    fn name(&self) -> &str {
        "fake-gel"
    }
    fn spec(&self) -> &TactileSpec {
        &self.spec
    }
    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        let depth_mm = (TOP_M - self.z.get()) * 1e3;
        let radius = if self.shows && depth_mm > 0.0 {
            6.0 * depth_mm.sqrt()
        } else {
            0.0
        };
        // The pad's x along the world's, its y against it (`Pose::tool_down`).
        let first = *self.first_xy.get().get_or_insert(self.xy.get());
        self.first_xy.set(Some(first));
        let centre = self.object_m.map_or(self.centre, |(dx, dy)| {
            let (ox, oy) = (first.0 + dx, first.1 + dy);
            let (px, py) = self.xy.get();
            let mm_per_px = f64::from(self.spec.width_px) * self.spec.mm_per_px / 96.0;
            (
                48.0 + (ox - px) * 1e3 / mm_per_px,
                40.0 - (oy - py) * 1e3 / mm_per_px,
            )
        });
        Ok(TactileFrame {
            image: RgbImage::from_fn(96, 80, |x, y| {
                let base = 120 + ((x * 7 + y * 13) % 17) as u8;
                let r = (x as f64 - centre.0).hypot(y as f64 - centre.1);
                if r < radius {
                    Rgb([base / 3, base / 2, base])
                } else {
                    Rgb([base, base, base])
                }
            }),
            timestamp_s: 0.0,
        })
    }
}

pub(super) struct FakeArm {
    pub(super) z: Rc<Cell<f64>>,
    pub(super) xy: Rc<Cell<(f64, f64)>>,
    pub(super) refuse_below_m: f64,
}
impl Arm for FakeArm {
    fn name(&self) -> &str {
        "fake-arm"
    }
    fn pose(&self) -> Result<Pose, DeviceError> {
        let (x, y) = self.xy.get();
        Ok(Pose::tool_down(DVec3::new(x, y, self.z.get())))
    }
    fn move_linear(&mut self, target: &Pose, _: f64) -> Result<(), DeviceError> {
        if target.position.z < self.refuse_below_m {
            return Err(DeviceError::UnsafeMove {
                device: "fake-arm".into(),
                reason: "crush limit".into(),
            });
        }
        self.z.set(target.position.z);
        self.xy.set((target.position.x, target.position.y));
        Ok(())
    }
    fn stop(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }
}

/// Reads every press as 2 MPa: the pipeline is under test, not estimation.
pub(super) struct TwoMpa;
impl HardnessEstimator for TwoMpa {
    fn name(&self) -> &str {
        "two-mpa"
    }
    fn estimate(
        &self,
        press: &PressSequence,
        _: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        assert_eq!(press.frames.len(), 8);
        Ok(HardnessEstimate {
            hardness: Hardness::ModulusMpa(2.0),
            interval: ModulusInterval::log_normal(2f64.ln(), 0.1, "test"),
            evidence: Evidence::Physics(PhysicsEvidence {
                gel_share: 0.1,
                gel_share_se: 0.0,
                local_radius_mm: 30.0,
                first_contact_approach_mm: 0.1,
                last_contact_radius_mm: 3.0,
                last_gel_indentation_mm: 0.2,
                frames_used: 8,
                gel_layer_factor: 1.0,
                fit_residual_rms: 0.0,
                fit_residual_unit: "mm",
                object_poisson: 0.35,
                first_contact_aspect: None,
            }),
        })
    }
}
