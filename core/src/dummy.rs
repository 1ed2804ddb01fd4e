//! Dummy devices to test code against without hardware or the twin, as openrr's `arci`
//! ships them: one apple under a downward RGB-D camera, a detector that finds it, a gel that
//! shows a disc once the pad is below the apple's top, an arm that moves where it is told
//! (refusing below a limit), and an estimator that reads a fixed modulus. They are the least
//! a backend must do (the `devices` traits), and the pipeline's own tests run on them:
//!
//! ```text
//! use tactex_core::catalog::FruitCatalog;
//! use tactex_core::dummy::{DummyWorld, FixedEstimator};
//! use tactex_core::pipeline::{Devices, Language, PipelineConfig, answer};
//!
//! let mut world = DummyWorld::apple();
//! let devices = Devices { camera: &mut world.camera, tactile: &mut world.tactile, arm: &mut world.arm };
//! let a = answer("How hard is the apple?", &FruitCatalog::builtin(), devices, &world.detector,
//!                &FixedEstimator::new(2.0), Language::OFFLINE, &PipelineConfig::default())?;
//! ```
//!
//! To test your own device, put it in place of its dummy: your estimator or detector as is;
//! your arm holding `world.tactile.pad_place()` and setting it after each move (the dummy
//! arm tells the gel where the pad is; yours must too, for the gel to show the apple).

use crate::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use crate::frames::TactileFrame;
use crate::frames::{DepthImage, RgbdFrame};
use crate::geometry::CameraIntrinsics;
use crate::geometry::Pose;
use crate::ground::detect::{DetectError, Detection, Detector, RgbdView};
use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, ModulusInterval, PhysicsEvidence,
    PressSequence,
};
use crate::hardness::scale::Hardness;
use crate::tactile::spec::TactileSpec;
use glam::DVec3;
use image::{GrayImage, Luma, Rgb, RgbImage};
use std::cell::Cell;
use std::rc::Rc;

/// The dummy devices of one apple on a table, the gel and the arm sharing where the pad is.
pub struct DummyWorld {
    pub camera: DummyCamera,
    pub detector: DummyDetector,
    pub tactile: DummyGel,
    pub arm: DummyArm,
}

impl DummyWorld {
    /// The apple at the camera's centre, its contact shown at the gel frame's centre, the pad
    /// 0.3 m up, the arm free to go down to the table.
    pub fn apple() -> Self {
        let z = Rc::new(Cell::new(0.3));
        let xy = Rc::new(Cell::new((0.0, 0.0)));
        Self {
            camera: DummyCamera,
            detector: DummyDetector,
            tactile: DummyGel {
                z: z.clone(),
                xy: xy.clone(),
                first_xy: Cell::new(None),
                centre: (48.0, 40.0),
                object_m: None,
                shows: true,
                blown_out_from_mm: None,
                spec: TactileSpec::gelsight_mini(),
            },
            arm: DummyArm {
                z,
                xy,
                refuse_below_m: 0.0,
            },
        }
    }
}

/// The apple's top above the table (m).
pub const TOP_M: f64 = 0.03;
/// The camera's intrinsics: a 64 x 48 frame.
pub const K: CameraIntrinsics = CameraIntrinsics {
    width: 64,
    height: 48,
    fx: 60.0,
    fy: 60.0,
    cx: 32.0,
    cy: 24.0,
};

/// Whether pixel (x, y) of the camera's frame shows the apple.
pub fn on_apple(x: u32, y: u32) -> bool {
    (x as f64 - 32.0).hypot(y as f64 - 24.0) < 14.0
}

/// A camera 0.7 m above the table, looking down at the apple.
pub struct DummyCamera;
impl RgbdCamera for DummyCamera {
    fn name(&self) -> &str {
        "dummy-camera"
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

/// Finds the apple, with its mask.
pub struct DummyDetector;
impl Detector for DummyDetector {
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
pub struct DummyGel {
    z: Rc<Cell<f64>>,
    xy: Rc<Cell<(f64, f64)>>,
    first_xy: Cell<Option<(f64, f64)>>,
    /// Where the disc stands in the 96 x 80 frame (px).
    pub centre: (f64, f64),
    /// Instead of `centre`: the object's offset (m, world x, y) from the pad's first place.
    pub object_m: Option<(f64, f64)>,
    /// Whether the gel ever shows a contact.
    pub shows: bool,
    /// A frame taken this far (mm) or more below the apple's top is blown out (every pixel
    /// 255); None: never. Below the top's height (a negative depth) every frame is.
    pub blown_out_from_mm: Option<f64>,
    pub spec: TactileSpec,
}
/// Where the pad is, shared by the gel and whichever arm moves the pad.
#[derive(Clone)]
pub struct PadPlace {
    z: Rc<Cell<f64>>,
    xy: Rc<Cell<(f64, f64)>>,
}

impl PadPlace {
    /// The pad's centre now (world metres): what an arm other than `DummyArm` calls after
    /// each move, so that the gel shows the apple under it.
    pub fn set(&self, position: DVec3) {
        self.z.set(position.z);
        self.xy.set((position.x, position.y));
    }
}

impl DummyGel {
    /// The pad's place this gel reads: hand it to your own arm.
    pub fn pad_place(&self) -> PadPlace {
        PadPlace {
            z: self.z.clone(),
            xy: self.xy.clone(),
        }
    }
}

impl TactileSensor for DummyGel {
    fn name(&self) -> &str {
        "dummy-gel"
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
        let blown_out = self.blown_out_from_mm.is_some_and(|d| depth_mm >= d);
        Ok(TactileFrame {
            image: RgbImage::from_fn(96, 80, |x, y| {
                if blown_out {
                    return Rgb([255; 3]);
                }
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

/// Moves the pad where it is told, refusing a move below `refuse_below_m` (a crush limit).
pub struct DummyArm {
    z: Rc<Cell<f64>>,
    xy: Rc<Cell<(f64, f64)>>,
    /// The lowest the pad may go (m above the table).
    pub refuse_below_m: f64,
}
impl Arm for DummyArm {
    fn name(&self) -> &str {
        "dummy-arm"
    }
    fn pose(&self) -> Result<Pose, DeviceError> {
        let (x, y) = self.xy.get();
        Ok(Pose::tool_down(DVec3::new(x, y, self.z.get())))
    }
    fn move_linear(&mut self, target: &Pose, _: f64) -> Result<(), DeviceError> {
        if target.position.z < self.refuse_below_m {
            return Err(DeviceError::UnsafeMove {
                device: "dummy-arm".into(),
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

/// Reads every press of 8 frames as one modulus: for testing what is around estimation.
pub struct FixedEstimator {
    pub modulus_mpa: f64,
}

impl FixedEstimator {
    pub fn new(modulus_mpa: f64) -> Self {
        Self { modulus_mpa }
    }
}

impl HardnessEstimator for FixedEstimator {
    fn name(&self) -> &str {
        "fixed"
    }
    fn estimate(
        &self,
        press: &PressSequence,
        _: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        if press.frames.len() != 8 {
            return Err(EstimateError::BadSequence(format!(
                "{} frames, the protocol records 8",
                press.frames.len()
            )));
        }
        let e = self.modulus_mpa;
        Ok(HardnessEstimate {
            hardness: Hardness::ModulusMpa(e),
            interval: ModulusInterval::log_normal(e.ln(), 0.1, "fixed"),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::catalog::FruitCatalog;
    use crate::pipeline::{Devices, Language, PipelineConfig, answer};

    /// A user's own arm: moves where told and says where the pad went.
    struct MyArm {
        at: Pose,
        pad: PadPlace,
    }
    impl Arm for MyArm {
        fn name(&self) -> &str {
            "my-arm"
        }
        fn pose(&self) -> Result<Pose, DeviceError> {
            Ok(self.at)
        }
        fn move_linear(&mut self, target: &Pose, _: f64) -> Result<(), DeviceError> {
            self.at = *target;
            self.pad.set(target.position);
            Ok(())
        }
        fn stop(&mut self) -> Result<(), DeviceError> {
            Ok(())
        }
    }

    #[test]
    fn a_users_own_arm_in_the_dummy_world_presses_the_apple() {
        let mut world = DummyWorld::apple();
        let mut arm = MyArm {
            at: Pose::tool_down(DVec3::new(0.0, 0.0, 0.3)),
            pad: world.tactile.pad_place(),
        };
        let devices = Devices {
            camera: &mut world.camera,
            tactile: &mut world.tactile,
            arm: &mut arm,
        };
        let a = answer(
            "How hard is the apple?",
            &FruitCatalog::builtin(),
            devices,
            &world.detector,
            &FixedEstimator::new(2.0),
            Language::OFFLINE,
            &PipelineConfig::default(),
        )
        .unwrap();
        let apple = &a.objects[0];
        assert!(apple.not_measured.is_none(), "{:?}", apple.not_measured);
        assert_eq!(apple.hardness.as_ref().unwrap().modulus_mpa, Some(2.0));
    }
}
