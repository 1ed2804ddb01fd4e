//! The press stage on the arm and the sensor: the pad over a target, core's press protocol
//! run through the arm (ArmProbe), and a second press with the pad moved over an imprint
//! that the first found at the pad's edge.

use super::answer::{NotMeasured, NotMeasuredReason};
use super::config::{PipelineConfig, PipelineError};
use super::targets::Target;
use crate::devices::{Arm, DeviceError, TactileSensor};
use crate::frames::TactileFrame;
use crate::geometry::Pose;
use crate::hardness::estimate::PressSequence;
use crate::press::protocol::{Look, PressOutcome, PressProbe, PressProtocol, run_press};
use crate::tactile::contact::ContactEvidence;
use glam::DVec3;

pub(super) struct Press {
    pub(super) sequence: PressSequence,
    pub(super) search_mm: f64,
    pub(super) evidence: ContactEvidence,
    /// How far the pad was moved for a second press after the first imprint lay at its edge.
    pub(super) recentred_mm: Option<f64>,
}

/// What the pipeline keeps of a press once its sequence is handed to the hardness reader.
pub(super) struct PressTaken {
    pub(super) search_mm: f64,
    pub(super) evidence: ContactEvidence,
    pub(super) recentred_mm: Option<f64>,
}

/// The pad over a target, lowered in the protocol's steps from `start_z_m`.
pub(super) struct ArmProbe<'d, T: TactileSensor, A: Arm> {
    tactile: &'d mut T,
    arm: &'d mut A,
    touch: DVec3,
    pad_yaw_rad: f64,
    start_z_m: f64,
    config: &'d PipelineConfig,
}

impl<T: TactileSensor, A: Arm> ArmProbe<'_, T, A> {
    fn above(&self, z: f64) -> Pose {
        Pose::tool_down_turned(DVec3::new(self.touch.x, self.touch.y, z), self.pad_yaw_rad)
    }

    /// The frame with the pad `k` steps down, and where the arm says the pad is (m).
    fn lowered(&mut self, k: usize) -> Result<(TactileFrame, f64), DeviceError> {
        let z = self.start_z_m - k as f64 * self.config.press.step_mm * 1e-3;
        self.arm
            .move_linear(&self.above(z), self.config.press_speed_m_s)?;
        let frame = self.tactile.capture()?;
        Ok((frame, self.arm.pose()?.position.z))
    }
}

impl<T: TactileSensor, A: Arm> PressProbe for ArmProbe<'_, T, A> {
    type Frame = (TactileFrame, f64);
    type Error = DeviceError;

    fn look(&mut self, at: Look) -> Result<(image::RgbImage, (TactileFrame, f64)), DeviceError> {
        let k = match at {
            // Both no-contact frames at the start: the second gives the noise floor.
            Look::Reference | Look::NoiseFloor => 0,
            Look::Search(k) => k,
        };
        let (frame, z) = self.lowered(k)?;
        Ok((frame.image.clone(), (frame, z)))
    }

    fn record(&mut self, k: usize) -> Result<(TactileFrame, f64), DeviceError> {
        self.lowered(k)
    }
}

/// Where the imprint of the first contact frame lies, as a fraction of the frame's width and
/// height: the middle of its colour change against `reference` (where the change, smoothed
/// over a few pixels against noise and marker dots, exceeds half its largest value); None
/// when nothing changed. A press is cut when the middle falls in the frame's outer eighth: at
/// first contact the imprint is small and a press centred on the object has it in the middle,
/// a long ridge across the pad included; deeper frames of a large fruit reach the edge and are
/// still read.
pub(super) fn imprint_middle(
    first_contact: &TactileFrame,
    reference: &TactileFrame,
) -> Option<glam::DVec2> {
    let (a, b) = (&first_contact.image, &reference.image);
    if a.dimensions() != b.dimensions() {
        return None;
    }
    let (w, h) = a.dimensions();
    let change = image::ImageBuffer::<image::Luma<f32>, Vec<f32>>::from_fn(w, h, |x, y| {
        let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
        image::Luma([(0..3).map(|c| (p[c] as f32 - q[c] as f32).abs()).sum()])
    });
    let smooth = imageproc::filter::gaussian_blur_f32(&change, 4.0);
    let peak = smooth.pixels().map(|p| p[0]).fold(0.0, f32::max);
    if peak <= 0.0 {
        return None;
    }
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for (x, y, p) in smooth.enumerate_pixels() {
        if p[0] > 0.5 * peak {
            sx += x as f64;
            sy += y as f64;
            n += 1.0;
        }
    }
    Some(glam::DVec2::new(sx / n / w as f64, sy / n / h as f64))
}

/// Above the target, run the press protocol from `approach_clearance_mm` above the surface
/// the camera saw, retract. An object that cannot be pressed (no contact, a refused move, an
/// imprint cut by the pad's edge) is reported as not measured, not a failure of the question;
/// a device that fails otherwise fails it.
pub(super) fn press<T: TactileSensor, A: Arm>(
    target: &Target,
    tactile: &mut T,
    arm: &mut A,
    config: &PipelineConfig,
) -> Result<Result<Press, NotMeasured>, PipelineError> {
    let offset_m = match press_at(target.touch, target, tactile, arm, config)? {
        Attempt::Pressed(p) => return Ok(Ok(p)),
        Attempt::NotMeasured(why) => return Ok(Err(why)),
        Attempt::Cut { offset_m } => offset_m,
    };
    // The imprint lay at the pad's edge: the object is off to that side. Press once more with
    // the pad moved over the imprint's middle, as an operator would.
    let moved_mm = offset_m.length() * 1e3;
    let moved = target.touch + offset_m.extend(0.0);
    Ok(match press_at(moved, target, tactile, arm, config)? {
        Attempt::Pressed(mut p) => {
            p.recentred_mm = Some(moved_mm);
            Ok(p)
        }
        Attempt::NotMeasured(why) => Err(why),
        Attempt::Cut { .. } => Err(NotMeasured {
            reason: NotMeasuredReason::ImprintCut,
            detail: format!(
                "the imprint was cut by the pad's edge, again with the pad moved {moved_mm:.1} mm over it: the pad came down beside the object"
            ),
        }),
    })
}

/// What one press came to.
pub(super) enum Attempt {
    Pressed(Press),
    NotMeasured(NotMeasured),
    /// The first imprint lay at the pad's edge; the pad's centre lies `offset_m` (world x, y)
    /// from the imprint's middle.
    Cut {
        offset_m: glam::DVec2,
    },
}

/// One press with the pad over `touch`.
pub(super) fn press_at<T: TactileSensor, A: Arm>(
    touch: DVec3,
    target: &Target,
    tactile: &mut T,
    arm: &mut A,
    config: &PipelineConfig,
) -> Result<Attempt, PipelineError> {
    // The pad's size, for where on it an imprint lies.
    let pad_mm = tactile.spec().pad_size_mm();
    let refused = |e: DeviceError| match e {
        DeviceError::UnsafeMove { reason, .. } => Ok(NotMeasured::arm_refused(&reason)),
        e => Err(PipelineError::Device(e)),
    };
    let above =
        |z: f64| Pose::tool_down_turned(DVec3::new(touch.x, touch.y, z), target.pad_yaw_rad);
    let safe = above(touch.z + config.safe_height_m);
    let start_z_m = touch.z + config.approach_clearance_mm * 1e-3;
    let approach = arm
        .move_linear(&safe, config.travel_speed_m_s)
        .and_then(|()| arm.move_linear(&above(start_z_m), config.travel_speed_m_s));
    if let Err(e) = approach {
        return Ok(Attempt::NotMeasured(refused(e)?));
    }
    let protocol = PressProtocol {
        max_search_steps: (config.max_search_mm / config.press.step_mm).ceil() as usize,
        ..config.press
    };
    let mut probe = ArmProbe {
        tactile,
        arm,
        touch,
        pad_yaw_rad: target.pad_yaw_rad,
        start_z_m,
        config,
    };
    let outcome = run_press(&protocol, &mut probe);
    // Whatever happened below, the pad goes back up before the next object.
    arm.move_linear(&safe, config.travel_speed_m_s)?;
    let pressed = match outcome {
        Ok(PressOutcome::Pressed(p)) => p,
        Ok(PressOutcome::NoContact { travel_mm, .. }) => {
            return Ok(Attempt::NotMeasured(NotMeasured::no_contact(travel_mm)));
        }
        Err(crate::press::protocol::PressError::Probe(e)) => {
            return Ok(Attempt::NotMeasured(refused(e)?));
        }
        Err(crate::press::protocol::PressError::Invalid(m)) => {
            return Err(PipelineError::Camera(format!("tactile sensor: {m}")));
        }
    };
    let (reference, _) = pressed.reference;
    let contact_z = pressed.frames[0].1;
    let travel_mm = pressed
        .frames
        .iter()
        .map(|(_, z)| (contact_z - z) * 1e3)
        .collect();
    let frames: Vec<TactileFrame> = pressed.frames.into_iter().map(|(f, _)| f).collect();
    if let Some(middle) = imprint_middle(&frames[0], &reference)
        && !((0.125..=0.875).contains(&middle.x) && (0.125..=0.875).contains(&middle.y))
    {
        // From the frame's middle to the imprint's, in the pad's frame, then the world's.
        let in_pad_mm = DVec3::new(
            (middle.x - 0.5) * pad_mm[0],
            (middle.y - 0.5) * pad_mm[1],
            0.0,
        );
        let in_world = above(0.0).rotation * in_pad_mm * 1e-3;
        return Ok(Attempt::Cut {
            offset_m: in_world.truncate(),
        });
    }
    Ok(Attempt::Pressed(Press {
        sequence: PressSequence {
            reference,
            frames,
            travel_mm,
        },
        search_mm: pressed.first_contact_step as f64 * config.press.step_mm,
        evidence: pressed.evidence,
        recentred_mm: None,
    }))
}
