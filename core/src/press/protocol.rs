//! The paper's press protocol, once for every backend: take a no-contact reference frame
//! and a second one (the sensor's own noise floor), lower the pad in fixed steps until the
//! contact criterion fires on a frame, then record a fixed number of frames at the same
//! step from that first contact frame on.
//!
//! What "lower the pad and take a frame" means is the backend's: the pipeline moves an arm and
//! captures from a tactile sensor (twin or real), data generation solves the contact and
//! renders it, and `compare --session` reads a recorded descent back. Each implements
//! [`PressProbe`]; [`run_press`] is the one protocol they all run, with the one contact
//! criterion of `tactile::contact`.

use crate::tactile::contact::{ContactEvidence, ContactRule, ContactTest};
use image::RgbImage;

/// How a press is run: the paper's 0.25 mm steps and 8 frames by default.
#[derive(Clone, Copy, Debug)]
pub struct PressProtocol {
    pub step_mm: f64,
    /// Frames recorded from the first contact frame on.
    pub frames: usize,
    /// The search gives up after this many steps.
    pub max_search_steps: usize,
    pub rule: ContactRule,
}

impl Default for PressProtocol {
    fn default() -> Self {
        Self {
            step_mm: 0.25,
            frames: 8,
            max_search_steps: 24,
            rule: ContactRule::default(),
        }
    }
}

/// A frame the contact criterion reads: the two no-contact frames at the start, or the pad
/// lowered `k` steps (k >= 1) during the search.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Look {
    Reference,
    NoiseFloor,
    Search(usize),
}

/// Something that can be lowered onto an object in steps and imaged.
pub trait PressProbe {
    /// What the caller keeps of a frame (a captured frame, solver fields and a noise seed).
    type Frame;
    type Error;
    /// The frame at `at`, with its image for the contact criterion.
    fn look(&mut self, at: Look) -> Result<(RgbImage, Self::Frame), Self::Error>;
    /// The frame with the pad lowered `k` steps, recorded without a contact test.
    fn record(&mut self, k: usize) -> Result<Self::Frame, Self::Error>;
    /// The frames' pixel size (mm), which the contact criterion bins to its own.
    fn mm_per_px(&self) -> f64;
}

/// A press as the protocol recorded it.
#[derive(Clone, Debug)]
pub struct Pressed<F> {
    pub reference: F,
    /// Steps of descent from the start to the first contact frame.
    pub first_contact_step: usize,
    /// The criterion's evidence on the first contact frame.
    pub evidence: ContactEvidence,
    /// From the first contact frame on, `frames` of them.
    pub frames: Vec<F>,
}

#[derive(Clone, Debug)]
pub enum PressOutcome<F> {
    Pressed(Pressed<F>),
    /// The criterion never fired within the search; the evidence of its last frame.
    NoContact {
        travel_mm: f64,
        last: Option<ContactEvidence>,
    },
}

#[derive(Debug, thiserror::Error)]
pub enum PressError<E> {
    #[error(transparent)]
    Probe(E),
    #[error("press protocol: {0}")]
    Invalid(String),
}

impl PressProtocol {
    pub fn validate(&self) -> Result<(), String> {
        if !(self.step_mm.is_finite() && self.step_mm > 0.0) {
            return Err(format!("step_mm must be positive, got {}", self.step_mm));
        }
        if self.frames == 0 {
            return Err("frames must be at least 1".into());
        }
        if self.max_search_steps == 0 {
            return Err("max_search_steps must be at least 1".into());
        }
        Ok(())
    }
}

/// Runs the protocol on `probe` (see the module docs).
pub fn run_press<P: PressProbe>(
    protocol: &PressProtocol,
    probe: &mut P,
) -> Result<PressOutcome<P::Frame>, PressError<P::Error>> {
    protocol.validate().map_err(PressError::Invalid)?;
    let (reference_image, reference) = probe.look(Look::Reference).map_err(PressError::Probe)?;
    let (second, _) = probe.look(Look::NoiseFloor).map_err(PressError::Probe)?;
    let test = ContactTest::with_noise_floor(
        &reference_image,
        &second,
        &protocol.rule,
        Some(probe.mm_per_px()),
    )
        .ok_or_else(|| {
            PressError::Invalid(format!(
                "a {}x{} frame is smaller than one {} px SSIM tile, or the two no-contact frames differ in size",
                reference_image.width(),
                reference_image.height(),
                protocol.rule.tile_px
            ))
        })?;
    let mut last = None;
    for k in 1..=protocol.max_search_steps {
        let (image, frame) = probe.look(Look::Search(k)).map_err(PressError::Probe)?;
        let evidence = test.evidence(&image).ok_or_else(|| {
            PressError::Invalid(format!(
                "search frame {k} is {}x{}, the reference {}x{}",
                image.width(),
                image.height(),
                reference_image.width(),
                reference_image.height()
            ))
        })?;
        if evidence.contact {
            let mut frames = Vec::with_capacity(protocol.frames);
            frames.push(frame);
            for j in 1..protocol.frames {
                frames.push(probe.record(k + j).map_err(PressError::Probe)?);
            }
            return Ok(PressOutcome::Pressed(Pressed {
                reference,
                first_contact_step: k,
                evidence,
                frames,
            }));
        }
        last = Some(evidence);
    }
    Ok(PressOutcome::NoContact {
        travel_mm: protocol.max_search_steps as f64 * protocol.step_mm,
        last,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    /// A gel that shows a dark disc growing past step `touch`: enough to pin the protocol's
    /// order of frames without any physics.
    struct Disc {
        touch: usize,
        looks: Vec<Look>,
        recorded: Vec<usize>,
    }

    fn disc_frame(radius: f64) -> RgbImage {
        RgbImage::from_fn(96, 80, |x, y| {
            let r = ((x as f64 - 48.0).powi(2) + (y as f64 - 40.0).powi(2)).sqrt();
            // A textured background, so that SSIM sees structure.
            let base = 120 + ((x * 7 + y * 13) % 17) as u8;
            if r < radius {
                Rgb([base / 3, base / 2, base])
            } else {
                Rgb([base, base, base])
            }
        })
    }

    impl PressProbe for Disc {
        type Frame = usize;
        type Error = String;
        fn look(&mut self, at: Look) -> Result<(RgbImage, usize), String> {
            self.looks.push(at);
            let k = match at {
                Look::Search(k) => k,
                _ => 0,
            };
            let radius = if k >= self.touch {
                4.0 + 3.0 * (k - self.touch) as f64
            } else {
                0.0
            };
            Ok((disc_frame(radius), k))
        }
        fn record(&mut self, k: usize) -> Result<usize, String> {
            self.recorded.push(k);
            Ok(k)
        }
        fn mm_per_px(&self) -> f64 {
            0.05
        }
    }

    #[test]
    fn records_the_frames_from_the_one_the_criterion_fired_on() {
        let mut probe = Disc {
            touch: 5,
            looks: Vec::new(),
            recorded: Vec::new(),
        };
        let PressOutcome::Pressed(p) = run_press(&PressProtocol::default(), &mut probe).unwrap()
        else {
            panic!("the disc is seen");
        };
        assert_eq!(p.first_contact_step, 5);
        assert_eq!(p.frames, (5..13).collect::<Vec<_>>());
        assert_eq!(probe.recorded, (6..13).collect::<Vec<_>>());
        assert_eq!(
            probe.looks[..3],
            [Look::Reference, Look::NoiseFloor, Look::Search(1)]
        );
        assert!(p.evidence.contact);
    }

    #[test]
    fn a_press_that_never_touches_reports_how_far_it_went() {
        let mut probe = Disc {
            touch: 100,
            looks: Vec::new(),
            recorded: Vec::new(),
        };
        let protocol = PressProtocol {
            max_search_steps: 6,
            ..PressProtocol::default()
        };
        match run_press(&protocol, &mut probe).unwrap() {
            PressOutcome::NoContact { travel_mm, last } => {
                assert_eq!(travel_mm, 1.5);
                assert!(!last.unwrap().contact);
            }
            PressOutcome::Pressed(_) => panic!("nothing to touch"),
        }
        assert!(probe.recorded.is_empty());
    }

    #[test]
    fn a_protocol_without_steps_or_frames_is_refused() {
        for protocol in [
            PressProtocol {
                step_mm: f64::NAN,
                ..PressProtocol::default()
            },
            PressProtocol {
                frames: 0,
                ..PressProtocol::default()
            },
            PressProtocol {
                max_search_steps: 0,
                ..PressProtocol::default()
            },
        ] {
            let mut probe = Disc {
                touch: 1,
                looks: Vec::new(),
                recorded: Vec::new(),
            };
            assert!(matches!(
                run_press(&protocol, &mut probe),
                Err(PressError::Invalid(_))
            ));
            assert!(probe.looks.is_empty());
        }
    }
}
