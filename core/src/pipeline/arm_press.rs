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
use crate::tactile::separable::{imageproc_gaussian_taps, separable_blur};
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
    /// Pressed frames so far (the first is the search's contact frame), to name a frame that
    /// cannot be read.
    recorded: usize,
    /// The first frame that carries no shading (which, and why), if one did: the press
    /// stopped there, since a blank reference makes every later frame read as contact and a
    /// blank pressed frame reads as a deep imprint.
    unreadable: Option<(String, String)>,
}

impl<T: TactileSensor, A: Arm> ArmProbe<'_, T, A> {
    fn above(&self, z: f64) -> Pose {
        Pose::tool_down_turned(DVec3::new(self.touch.x, self.touch.y, z), self.pad_yaw_rad)
    }

    /// The frame with the pad `k` steps down, and where the arm says the pad is (m); a frame
    /// that carries no shading (blank, or blown out) ends the press, as `which`.
    fn lowered(
        &mut self,
        k: usize,
        which: impl FnOnce() -> String,
    ) -> Result<(TactileFrame, f64), DeviceError> {
        let z = self.start_z_m - k as f64 * self.config.press.step_mm * 1e-3;
        self.arm
            .move_linear(&self.above(z), self.config.press_speed_m_s)?;
        let frame = self.tactile.capture()?;
        if let Some(why) = crate::image_file::rgb_frame_fault(&frame.image) {
            let which = which();
            let message = format!("the {which} carries no shading");
            self.unreadable = Some((which, why));
            return Err(DeviceError::Failure {
                device: self.tactile.name().to_string(),
                message,
            });
        }
        Ok((frame, self.arm.pose()?.position.z))
    }
}

impl<T: TactileSensor, A: Arm> PressProbe for ArmProbe<'_, T, A> {
    type Frame = (TactileFrame, f64);
    type Error = DeviceError;

    fn look(&mut self, at: Look) -> Result<(image::RgbImage, (TactileFrame, f64)), DeviceError> {
        let (k, which) = match at {
            // Both no-contact frames at the start: the second gives the noise floor.
            Look::Reference => (0, "no-contact frame".to_string()),
            Look::NoiseFloor => (0, "second no-contact frame".to_string()),
            Look::Search(k) => (k, format!("search frame {k} steps down")),
        };
        let (frame, z) = self.lowered(k, || which)?;
        Ok((frame.image.clone(), (frame, z)))
    }

    fn record(&mut self, k: usize) -> Result<(TactileFrame, f64), DeviceError> {
        self.recorded += 1;
        let n = self.recorded;
        self.lowered(k, || format!("pressed frame {n}"))
    }
    fn mm_per_px(&self) -> f64 {
        self.tactile.spec().mm_per_px
    }
}

/// How far the first contact frame's imprint lies from the frame's middle, as fractions of
/// the frame's width and height; None when nothing changed. The imprint is where its colour
/// change against `reference` (smoothed over a few pixels against noise and marker dots)
/// rises more than half way from the frame's median change (camera noise) to its peak. A
/// press is cut when the offset reaches the frame's outer eighth: at first contact the
/// imprint is small and a press centred on the object has it in the middle; deeper frames of
/// a large fruit reach the edge and are still read. A ridge (an imprint at least three times
/// as long as wide: a banana's or a cucumber's top) crosses the pad whatever the pad's place
/// along it, brighter where the ridge stands higher, so only its offset across counts.
pub(super) fn imprint_offset(
    first_contact: &TactileFrame,
    reference: &TactileFrame,
) -> Option<glam::DVec2> {
    let (a, b) = (&first_contact.image, &reference.image);
    if a.dimensions() != b.dimensions() {
        return None;
    }
    let (w, h) = a.dimensions();
    let change: Vec<[f32; 1]> = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| [(0..3).map(|c| (p[c] as f32 - q[c] as f32).abs()).sum()])
        .collect();
    let taps = imageproc_gaussian_taps(4.0);
    let smooth = separable_blur(&change, w as usize, h as usize, &taps).into_flattened();
    let mut levels = smooth.clone();
    let peak = levels.iter().copied().fold(0.0, f32::max);
    let middle_level = levels.len() / 2;
    let noise = *levels
        .select_nth_unstable_by(middle_level, f32::total_cmp)
        .1;
    if peak <= noise {
        return None;
    }
    let cut = noise + 0.5 * (peak - noise);
    let inside: Vec<glam::DVec2> = smooth
        .iter()
        .enumerate()
        .filter(|(_, p)| **p > cut)
        .map(|(i, _)| {
            let (x, y) = (i as u32 % w, i as u32 / w);
            glam::DVec2::new(x as f64 + 0.5, y as f64 + 0.5)
        })
        .collect();
    let n = inside.len() as f64;
    let mean = inside.iter().sum::<glam::DVec2>() / n;
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for d in inside.iter().map(|p| *p - mean) {
        sxx += d.x * d.x;
        syy += d.y * d.y;
        sxy += d.x * d.y;
    }
    let (sxx, syy, sxy) = (sxx / n, syy / n, sxy / n);
    // The spread's principal axes: a ridge's long one runs along it.
    let half_gap = (0.25 * (sxx - syy).powi(2) + sxy * sxy).sqrt();
    let (long, short) = (0.5 * (sxx + syy) + half_gap, 0.5 * (sxx + syy) - half_gap);
    let mut offset = mean - 0.5 * glam::DVec2::new(w as f64, h as f64);
    if long >= 9.0 * short.max(0.0) && long > 0.0 {
        let angle = 0.5 * (2.0 * sxy).atan2(sxx - syy);
        let along = glam::DVec2::new(angle.cos(), angle.sin());
        offset -= offset.dot(along) * along;
    }
    Some(offset / glam::DVec2::new(w as f64, h as f64))
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
        recorded: 1,
        unreadable: None,
    };
    let outcome = run_press(&protocol, &mut probe);
    let unreadable = probe.unreadable.take();
    // Whatever happened below, the pad goes back up before the next object.
    arm.move_linear(&safe, config.travel_speed_m_s)?;
    // A sensor whose LEDs failed, or a camera blown out, gives frames that read as contact
    // or a deep imprint everywhere: that object is not measured, with why.
    if let Some((which, why)) = unreadable {
        return Ok(Attempt::NotMeasured(NotMeasured {
            reason: NotMeasuredReason::UnreadableFrame,
            detail: format!("the tactile sensor's {which} cannot be read: {why}"),
        }));
    }
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
    if let Some(offset) = imprint_offset(&frames[0], &reference)
        && (offset.x.abs() > 0.375 || offset.y.abs() > 0.375)
    {
        // From the frame's middle to the imprint's, in the pad's frame, then the world's.
        let in_pad_mm = DVec3::new(offset.x * pad_mm[0], offset.y * pad_mm[1], 0.0);
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

#[cfg(test)]
mod tests {
    use super::*;
    use image::{Rgb, RgbImage};

    /// A 160 x 120 gel with camera noise, darkened by `dent(x, y)` grey levels.
    fn frame(seed: u64, dent: impl Fn(f64, f64) -> f64) -> TactileFrame {
        let mut state = seed;
        let image = RgbImage::from_fn(160, 120, |x, y| {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let noise = ((state >> 33) % 3) as f64 - 1.0;
            let v = (120.0 + noise - dent(x as f64, y as f64)).round() as u8;
            Rgb([v, v, v])
        });
        TactileFrame {
            image,
            timestamp_s: 0.0,
        }
    }

    fn offset(dent: impl Fn(f64, f64) -> f64) -> glam::DVec2 {
        imprint_offset(&frame(7, dent), &frame(1, |_, _| 0.0)).unwrap()
    }

    fn disc(cx: f64, cy: f64) -> impl Fn(f64, f64) -> f64 {
        move |x, y| {
            if (x - cx).hypot(y - cy) < 8.0 {
                30.0
            } else {
                0.0
            }
        }
    }

    #[test]
    fn a_round_imprint_is_placed_where_it_lies() {
        let o = offset(disc(80.0, 60.0));
        assert!(o.length() < 0.02, "{o}");
        let o = offset(disc(12.0, 60.0));
        assert!(o.x < -0.375 && o.y.abs() < 0.02, "{o}");
    }

    /// A ridge along a line through (cx, cy) at `angle`, deeper towards +x: a banana's top.
    fn ridge(cx: f64, cy: f64, angle: f64) -> impl Fn(f64, f64) -> f64 {
        let (along, across) = (
            glam::DVec2::new(angle.cos(), angle.sin()),
            glam::DVec2::new(-angle.sin(), angle.cos()),
        );
        move |x, y| {
            let d = glam::DVec2::new(x - cx, y - cy);
            if d.dot(across).abs() < 4.0 {
                20.0 + 0.2 * d.dot(along)
            } else {
                0.0
            }
        }
    }

    #[test]
    fn a_ridge_across_the_pad_counts_only_its_offset_across() {
        // Brighter at one end, so its bright half lies far out along it, but through the middle.
        for angle in [0.0f64, 0.3, -0.5, 1.2] {
            let o = offset(ridge(80.0, 60.0, angle));
            assert!(o.x.abs() < 0.375 && o.y.abs() < 0.375, "angle {angle}: {o}");
            assert!(o.length() < 0.05, "angle {angle}: {o}");
        }
        // Along the frame's top edge: cut, and the pad is sent straight across to it.
        let o = offset(ridge(80.0, 8.0, 0.0));
        assert!(o.y < -0.375 && o.x.abs() < 0.01, "{o}");
    }

    #[test]
    fn noise_alone_places_no_imprint_off_the_middle() {
        let o = imprint_offset(&frame(7, |_, _| 0.0), &frame(1, |_, _| 0.0));
        assert!(
            o.is_none_or(|o| o.x.abs() < 0.375 && o.y.abs() < 0.375),
            "{o:?}"
        );
    }
}
