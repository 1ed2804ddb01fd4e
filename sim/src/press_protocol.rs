//! The paper's press protocol on the contact solver alone (no world, no arm): lower the pad in
//! steps until the contact criterion fires on the rendered frame, then record a fixed number of
//! frames at the same step. Data generation and the hardness evaluations run it directly; the
//! pipeline runs the same protocol through the device traits.
//!
//! Search frames are rendered on the CPU reference path so that where contact fires never
//! depends on the device; the recorded frames come back as gel fields and noise seeds, for any
//! renderer to draw in batches. Frame k of the descent has noise seed `frame_seed(seed, k)`,
//! so the recorded first frame is the very frame the criterion fired on.

use crate::elastic::{
    ContactError, ContactProblem, ContactSolution, ContactSolver, Fidelity, Grid, ObjectSurface,
};
use crate::gel_render::{
    CpuRenderer, GelImageFields, GelRenderer, PressFrame, RenderError, SensorOptics, image_fields,
    pad_rect,
};
use image::RgbImage;
use tactex_core::estimate::PressSequence;
use tactex_core::frames::TactileFrame;
use tactex_core::hertz::Elastic;
use tactex_core::perception::contact::{ContactEvidence, ContactRule, ContactTest};
use tactex_core::tactile_spec::GelSpec;

/// How the press is run: the paper's 0.25 mm steps and 8 frames by default.
#[derive(Clone, Copy, Debug)]
pub struct PressProtocol {
    pub step_mm: f64,
    /// Frames recorded from the first contact frame on.
    pub frames: usize,
    /// The search gives up after this many steps past the first touch.
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
pub fn frame_seed(seed: u32, k: usize) -> u32 {
    let mut z = (seed as u64) << 32 | k as u64;
    z = z.wrapping_add(0x9e37_79b9_7f4a_7c15);
    z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
    (z ^ (z >> 31)) as u32
}

/// One frame of the descent: the solve on `grid` (warm-started from the previous frame of
/// the same grid) and the gel fields at the frame's pixels.
struct SolvedFrame {
    fields: GelImageFields,
    solution: Option<ContactSolution>,
}

impl SolvedFrame {
    fn facts(&self) -> (f64, f64, f64) {
        self.solution.as_ref().map_or((0.0, 0.0, 0.0), |s| {
            (s.force_n, s.contact_radius_mm, s.gel_max_indentation_mm)
        })
    }
}

fn problem_at<'a>(setup: &PressSetup<'a>, approach_mm: f64) -> ContactProblem<'a> {
    ContactProblem {
        surface: setup.surface,
        object: setup.object,
        gel: setup.gel,
        pad: pad_rect(setup.optics),
        approach_mm,
        cell_mm: setup.cell_mm,
    }
}

fn solve_frame(
    solver: &mut ContactSolver,
    setup: &PressSetup,
    approach_mm: f64,
    grid: Option<Grid>,
    warm: Option<&ContactSolution>,
) -> Result<SolvedFrame, PressError> {
    let optics = setup.optics;
    if approach_mm <= 0.0 {
        return Ok(SolvedFrame {
            fields: GelImageFields::flat(optics.width, optics.height),
            solution: None,
        });
    }
    let solution = solver.solve_on(&problem_at(setup, approach_mm), setup.fidelity, grid, warm)?;
    let fields = image_fields(solver, &solution, &setup.gel, optics);
    Ok(SolvedFrame {
        fields,
        solution: Some(solution),
    })
}

/// Runs the search and records the press (see the module docs).
pub fn plan_press(
    solver: &mut ContactSolver,
    setup: &PressSetup,
    protocol: &PressProtocol,
) -> Result<PlannedPress, PressError> {
    let step = protocol.step_mm;
    if !(step.is_finite() && step > 0.0) {
        return Err(PressError::Invalid(format!(
            "step_mm must be positive, got {step}"
        )));
    }
    if protocol.frames == 0 {
        return Err(PressError::Invalid("frames must be at least 1".into()));
    }
    if !(setup.phase_mm.is_finite() && (0.0..step).contains(&setup.phase_mm)) {
        return Err(PressError::Invalid(format!(
            "phase_mm must be in [0, {step}), got {}",
            setup.phase_mm
        )));
    }
    setup.optics.validate()?;
    let approach = |k: usize| k as f64 * step - setup.phase_mm;
    let reference_seed = frame_seed(setup.seed, 0);
    let flat = GelImageFields::flat(setup.optics.width, setup.optics.height);
    let reference = CpuRenderer.render_one(
        setup.optics,
        &PressFrame {
            fields: &flat,
            seed: reference_seed,
        },
    );

    // A second no-contact frame gives the sensor's noise floor (see `ContactTest`).
    let second = CpuRenderer.render_one(
        setup.optics,
        &PressFrame {
            fields: &flat,
            seed: frame_seed(setup.seed, NOISE_FLOOR_FRAME),
        },
    );
    let test = ContactTest::with_noise_floor(&reference, &second, &protocol.rule)
        .ok_or_else(|| PressError::Invalid("frame smaller than one SSIM tile".into()))?;

    // Each search step solves on the grid its deepest recorded frame would need, so that
    // once contact fires the recorded frames share one grid (and its kernels) with warm starts.
    let deepest = (protocol.frames - 1) as f64 * step;
    let mut found = None;
    for k in 1..=protocol.max_search_steps {
        let a = approach(k);
        if a <= 0.0 {
            continue;
        }
        let grid = solver.plan_grid(&problem_at(setup, a), setup.fidelity, a + deepest)?;
        let frame = solve_frame(solver, setup, a, grid, None)?;
        let seed = frame_seed(setup.seed, k);
        let image = CpuRenderer.render_one(
            setup.optics,
            &PressFrame {
                fields: &frame.fields,
                seed,
            },
        );
        let evidence = test
            .evidence(&image)
            .expect("frames of one optics have one size");
        if evidence.contact {
            found = Some((k, evidence, grid, frame));
            break;
        }
    }
    let Some((first_step, contact, grid, first)) = found else {
        return Err(PressError::NoContact {
            travel_mm: approach(protocol.max_search_steps),
        });
    };
    let mut warnings: Vec<String> = Vec::new();
    let mut frames = Vec::with_capacity(protocol.frames);
    let mut first = Some(first);
    let mut previous: Option<ContactSolution> = None;
    for j in 0..protocol.frames {
        let k = first_step + j;
        let a = approach(k);
        let frame = match first.take() {
            Some(f) => f,
            None => solve_frame(solver, setup, a, grid, previous.as_ref())?,
        };
        let (force_n, contact_radius_mm, gel_max_indentation_mm) = frame.facts();
        for w in frame.solution.iter().flat_map(|s| &s.warnings) {
            if !warnings.contains(w) {
                warnings.push(w.clone());
            }
        }
        frames.push(PressedFrame {
            fields: frame.fields,
            seed: frame_seed(setup.seed, k),
            approach_mm: a,
            travel_mm: j as f64 * step,
            force_n,
            contact_radius_mm,
            gel_max_indentation_mm,
        });
        previous = frame.solution;
    }
    Ok(PlannedPress {
        reference_seed,
        frames,
        search_steps: first_step,
        contact,
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
    use tactex_core::tactile_spec::TactileSpec;

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
        let test =
            ContactTest::with_noise_floor(&images[0], &second, &PressProtocol::default().rule)
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
