//! The paper's press protocol (`tactex_core::press::protocol`) on the contact solver alone (no world,
//! no arm): each step of the descent is a contact solve at the step's approach, through the
//! same per-press grid as the sim GelSight's (`contact::pad::PressGrid`). Data generation and
//! the hardness evaluations run it directly; the pipeline runs the same protocol through the
//! device traits.
//!
//! Search frames are rendered on the CPU reference path so that where contact fires never
//! depends on the device; the recorded frames come back as gel fields and noise seeds, for any
//! renderer to draw in batches. Frame k of the descent has noise seed `frame_seed(seed, k)`,
//! so the recorded first frame is the very frame the criterion fired on.

use crate::contact::pad::{PressGrid, Spot};
use crate::contact::{ContactError, ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use crate::render::gel::{
    CpuRenderer, GelImageFields, GelRenderer, PressFrame, RenderError, SensorOptics, image_fields,
    pad_rect,
};
use image::RgbImage;
use tactex_core::frames::TactileFrame;
use tactex_core::hardness::estimate::PressSequence;
use tactex_core::hertz::Elastic;
use tactex_core::press::protocol::{Look, PressOutcome, PressProbe, PressProtocol, run_press};
use tactex_core::tactile::contact::ContactEvidence;
use tactex_core::tactile::spec::GelSpec;

/// One object under the pad, and the sensor that presses it.
#[derive(Clone, Copy, Debug)]
pub struct PressSetup<'a> {
    pub surface: &'a ObjectSurface,
    pub object: Elastic,
    pub gel: GelSpec,
    pub fidelity: Fidelity,
    pub optics: &'a SensorOptics,
    /// Where the first touch falls between two steps: the pad's approach at step k is
    /// k * step - phase, phase in [0, step). Step 0 is the no-contact reference frame.
    pub phase_mm: f64,
    /// Solver cell (mm); None picks one from the contact's size.
    pub cell_mm: Option<f64>,
    pub seed: u32,
}

/// One recorded frame: what the gel did, and the solver's facts about it.
#[derive(Clone, Debug)]
pub struct PressedFrame {
    pub fields: GelImageFields,
    pub seed: u32,
    /// Total approach of gel and object past first touch (mm).
    pub approach_mm: f64,
    /// Robot travel past the first contact frame (mm).
    pub travel_mm: f64,
    pub force_n: f64,
    pub contact_radius_mm: f64,
    pub gel_max_indentation_mm: f64,
    /// The solver's warnings on this frame.
    pub warnings: Vec<String>,
}

/// The press as recorded, before rendering.
#[derive(Clone, Debug)]
pub struct PlannedPress {
    pub reference_seed: u32,
    pub frames: Vec<PressedFrame>,
    /// Steps of descent from the reference to the first contact frame.
    pub search_steps: usize,
    /// The criterion's evidence on the first contact frame.
    pub contact: ContactEvidence,
    pub warnings: Vec<String>,
}

#[derive(Debug, thiserror::Error)]
pub enum PressError {
    #[error("contact solve: {0}")]
    Contact(#[from] ContactError),
    #[error("render: {0}")]
    Render(#[from] RenderError),
    #[error("no contact detected within {travel_mm} mm of travel past first touch")]
    NoContact { travel_mm: f64 },
    #[error("press protocol: {0}")]
    Invalid(String),
}

/// Descent index of the second no-contact frame, which measures the noise floor.
const NOISE_FLOOR_FRAME: usize = 1 << 20;

/// The noise seed of frame `k` of a descent seeded `seed` (splitmix-style mixing, so that
/// neighbouring seeds and frames give unrelated noise).
fn frame_seed(seed: u32, k: usize) -> u32 {
    let mut z = (seed as u64) << 32 | k as u64;
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    (z ^ (z >> 31)) as u32
}

/// The descent as the solver sees it: step k is a solve at approach k * step - phase.
struct SolverProbe<'s, 'a> {
    solver: &'s mut ContactSolver,
    grid: PressGrid,
    setup: &'s PressSetup<'a>,
    step_mm: f64,
}

impl SolverProbe<'_, '_> {
    /// Frame `k` of the descent (0 and `NOISE_FLOOR_FRAME`: no contact).
    fn frame(&mut self, k: usize) -> Result<PressedFrame, PressError> {
        let setup = self.setup;
        let optics = setup.optics;
        let approach_mm = if k == NOISE_FLOOR_FRAME {
            0.0
        } else {
            k as f64 * self.step_mm - setup.phase_mm
        };
        let mut frame = PressedFrame {
            fields: GelImageFields::flat(optics.width, optics.height),
            seed: frame_seed(setup.seed, k),
            approach_mm,
            travel_mm: 0.0,
            force_n: 0.0,
            contact_radius_mm: 0.0,
            gel_max_indentation_mm: 0.0,
            warnings: Vec::new(),
        };
        if approach_mm <= 0.0 {
            return Ok(frame);
        }
        let problem = ContactProblem {
            surface: setup.surface,
            object: setup.object,
            gel: setup.gel,
            pad: pad_rect(optics),
            approach_mm,
            cell_mm: setup.cell_mm,
        };
        let spot = Spot {
            object: 0,
            across_m: glam::DVec2::ZERO,
            rotation: glam::DQuat::IDENTITY,
        };
        let solution = self
            .grid
            .solve(self.solver, &problem, setup.fidelity, spot)?;
        frame.fields = image_fields(self.solver, &solution, &setup.gel, optics);
        frame.force_n = solution.force_n;
        frame.contact_radius_mm = solution.contact_radius_mm;
        frame.gel_max_indentation_mm = solution.gel_max_indentation_mm;
        frame.warnings = solution.warnings;
        Ok(frame)
    }
}

impl PressProbe for SolverProbe<'_, '_> {
    type Frame = PressedFrame;
    type Error = PressError;

    fn look(&mut self, at: Look) -> Result<(RgbImage, PressedFrame), PressError> {
        let k = match at {
            Look::Reference => 0,
            Look::NoiseFloor => NOISE_FLOOR_FRAME,
            Look::Search(k) => k,
        };
        let frame = self.frame(k)?;
        let image = CpuRenderer.render_one(
            self.setup.optics,
            &PressFrame {
                fields: &frame.fields,
                seed: frame.seed,
            },
        );
        Ok((image, frame))
    }

    fn record(&mut self, k: usize) -> Result<PressedFrame, PressError> {
        self.frame(k)
    }
    fn mm_per_px(&self) -> f64 {
        self.setup.optics.mm_per_px
    }
}

/// Runs the protocol on the solver (see the module docs); `max_search_steps` counts from
/// first touch.
pub fn plan_press(
    solver: &mut ContactSolver,
    setup: &PressSetup,
    protocol: &PressProtocol,
) -> Result<PlannedPress, PressError> {
    protocol.validate().map_err(PressError::Invalid)?;
    let step = protocol.step_mm;
    if !(setup.phase_mm.is_finite() && (0.0..step).contains(&setup.phase_mm)) {
        return Err(PressError::Invalid(format!(
            "phase_mm must be in [0, {step}), got {}",
            setup.phase_mm
        )));
    }
    setup.optics.validate()?;
    let mut probe = SolverProbe {
        solver,
        grid: PressGrid::default(),
        setup,
        step_mm: step,
    };
    let pressed = match run_press(protocol, &mut probe).map_err(|e| match e {
        tactex_core::press::protocol::PressError::Probe(e) => e,
        tactex_core::press::protocol::PressError::Invalid(m) => PressError::Invalid(m),
    })? {
        PressOutcome::Pressed(p) => p,
        PressOutcome::NoContact { travel_mm, .. } => {
            return Err(PressError::NoContact {
                travel_mm: travel_mm - setup.phase_mm,
            });
        }
    };
    let mut warnings: Vec<String> = Vec::new();
    let mut frames = pressed.frames;
    for (j, f) in frames.iter_mut().enumerate() {
        f.travel_mm = j as f64 * step;
        for w in &f.warnings {
            if !warnings.contains(w) {
                warnings.push(w.clone());
            }
        }
    }
    Ok(PlannedPress {
        reference_seed: pressed.reference.seed,
        frames,
        search_steps: pressed.first_contact_step,
        contact: pressed.evidence,
        warnings,
    })
}

impl PlannedPress {
    /// The no-contact reference frame, then the recorded frames, in one batch.
    pub fn render(
        &self,
        renderer: &mut dyn GelRenderer,
        optics: &SensorOptics,
    ) -> Result<Vec<RgbImage>, RenderError> {
        let flat = GelImageFields::flat(optics.width, optics.height);
        let mut batch = vec![PressFrame {
            fields: &flat,
            seed: self.reference_seed,
        }];
        batch.extend(self.frames.iter().map(|f| PressFrame {
            fields: &f.fields,
            seed: f.seed,
        }));
        renderer.render_batch(optics, &batch)
    }

    /// The press as the estimators read it: the rendered reference and frames (from
    /// `render`) with each frame's travel past the first contact frame.
    pub fn sequence(&self, images: Vec<RgbImage>) -> PressSequence {
        let mut frames = images.into_iter().map(|image| TactileFrame {
            image,
            timestamp_s: 0.0,
        });
        PressSequence {
            reference: frames.next().expect("the reference frame comes first"),
            frames: frames.collect(),
            travel_mm: self.frames.iter().map(|f| f.travel_mm).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;
    use tactex_core::tactile::spec::TactileSpec;

    fn press(modulus_mpa: Option<f64>, phase_mm: f64) -> PlannedPress {
        let spec = TactileSpec::gelsight_mini();
        let optics = SensorOptics::for_spec(&spec);
        let surface = ObjectSurface::Sphere {
            radius_mm: 12.0,
            centre_mm: DVec2::new(1.0, -0.5),
        };
        let setup = PressSetup {
            surface: &surface,
            object: Elastic {
                modulus_mpa,
                poisson: 0.4,
            },
            gel: spec.gel,
            fidelity: Fidelity::Hertz,
            optics: &optics,
            phase_mm,
            cell_mm: None,
            seed: 7,
        };
        plan_press(&mut ContactSolver::new(), &setup, &PressProtocol::default()).unwrap()
    }

    #[test]
    fn records_eight_frames_at_quarter_millimetre_steps_from_first_contact() {
        let p = press(Some(1.0), 0.1);
        assert_eq!(p.frames.len(), 8);
        assert!(p.contact.contact);
        for (j, f) in p.frames.iter().enumerate() {
            assert!((f.travel_mm - 0.25 * j as f64).abs() < 1e-12);
            let expected = (p.search_steps + j) as f64 * 0.25 - 0.1;
            assert!((f.approach_mm - expected).abs() < 1e-12);
            assert_eq!(f.seed, frame_seed(7, p.search_steps + j));
        }
        // Deeper frames press harder.
        assert!(p.frames.windows(2).all(|w| w[1].force_n > w[0].force_n));
    }

    #[test]
    fn a_softer_object_needs_more_travel_before_contact_shows() {
        let hard = press(None, 0.0);
        let soft = press(Some(0.1), 0.0);
        assert!(
            soft.search_steps > hard.search_steps,
            "soft {} vs hard {}",
            soft.search_steps,
            hard.search_steps
        );
    }

    #[test]
    fn the_first_recorded_frame_is_the_frame_the_criterion_fired_on() {
        let spec = TactileSpec::gelsight_mini();
        let optics = SensorOptics::for_spec(&spec);
        let p = press(Some(1.0), 0.2);
        let images = p.render(&mut CpuRenderer, &optics).unwrap();
        assert_eq!(images.len(), 9);
        let flat = GelImageFields::flat(optics.width, optics.height);
        let second = CpuRenderer.render_one(
            &optics,
            &PressFrame {
                fields: &flat,
                seed: frame_seed(7, NOISE_FLOOR_FRAME),
            },
        );
        let test = tactex_core::tactile::contact::ContactTest::with_noise_floor(
            &images[0],
            &second,
            &PressProtocol::default().rule,
            Some(optics.mm_per_px),
        )
        .unwrap();
        assert_eq!(test.evidence(&images[1]).unwrap(), p.contact);
        assert!(p.contact.contact);
    }

    #[test]
    fn frame_seeds_differ_between_frames_and_seeds() {
        let mut seen = std::collections::HashSet::new();
        for seed in 0..50 {
            for k in 0..20 {
                assert!(seen.insert(frame_seed(seed, k)));
            }
        }
    }
}
