//! Presses of one object along a path the caller drives, one step at a time (a simulator's
//! steps, a learning loop's actions): the object read once, the contact solver's kernels and
//! the sensor's optics kept between steps, each step a pose and a depth solved and rendered
//! as one `press` of the same request would be.

use crate::app::single_press::{PressPose, PressReport, PressRequest, PressShape, SolvedPress};
use anyhow::Result;
use image::RgbImage;
use tactex_sim::contact::{ContactSolution, ContactSolver, GelFields};
use tactex_sim::render::gel::{GelImageFields, GelRenderer, PressFrame, SensorOptics};

/// One object under the pad, pressed step by step.
pub struct PressSteps {
    request: PressRequest,
    optics: SensorOptics,
    solver: Option<ContactSolver>,
    renderer: Box<dyn GelRenderer + Send>,
    reference: RgbImage,
    steps: u32,
}

/// What one step gives, as one `press` reports it: the figures, the gel's fields over the
/// pad, the contact's solution (pressure over the solver grid) and the frame.
pub struct Step {
    pub report: PressReport,
    pub fields: GelFields,
    pub solution: ContactSolution,
    pub frame: RgbImage,
}

impl PressSteps {
    /// The object and physics of `request` (its pose and depth are each step's), rendered by
    /// `renderer`. A mesh file is read here, once. The no-contact frame is drawn now, with
    /// the noise of seed + 1 as `press` draws it.
    pub fn new(
        mut request: PressRequest,
        mut renderer: Box<dyn GelRenderer + Send>,
    ) -> Result<Self> {
        request.check()?;
        if let PressShape::Mesh { path, scale } = &request.shape {
            request.shape = PressShape::Triangles {
                mesh: tactex_sim::mesh::load(path)?,
                scale: *scale,
                name: path.display().to_string(),
            };
        }
        // The object checked now (a mesh with NaN vertices, a flat one), not at every step.
        request.shape.surface(request.pose)?;
        let optics = SensorOptics::for_profile(&request.sensor);
        let flat = GelImageFields::flat(optics.width, optics.height);
        let reference = render_one(
            renderer.as_mut(),
            &optics,
            &flat,
            request.seed.wrapping_add(1),
        )?;
        Ok(Self {
            request,
            optics,
            solver: Some(ContactSolver::new()),
            renderer,
            reference,
            steps: 0,
        })
    }

    /// The no-contact frame every step is read against.
    pub fn reference(&self) -> &RgbImage {
        &self.reference
    }

    /// Steps taken so far.
    pub fn steps(&self) -> u32 {
        self.steps
    }

    /// The object at `pose`, the sensor `depth_mm` past first touch: solved, and its frame
    /// drawn with step k's own camera noise (seed + 2 + k: never the reference's).
    pub fn step(&mut self, pose: PressPose, depth_mm: f64) -> Result<Step> {
        self.request.pose = pose;
        self.request.depth_mm = depth_mm;
        let solver = self.solver.take().unwrap_or_default();
        let mut press = self.request.solve_with(solver)?;
        let fields = press.pad_fields();
        let image = press.image_fields(&self.request.sensor.spec.gel, &self.optics);
        let seed = self.request.seed.wrapping_add(2).wrapping_add(self.steps);
        let frame = render_one(self.renderer.as_mut(), &self.optics, &image, seed)?;
        let SolvedPress {
            report,
            solution,
            solver,
            ..
        } = press;
        // The next step reuses the kernels this one computed.
        self.solver = Some(solver);
        self.steps += 1;
        Ok(Step {
            report,
            fields,
            solution,
            frame,
        })
    }
}

fn render_one(
    renderer: &mut dyn GelRenderer,
    optics: &SensorOptics,
    fields: &GelImageFields,
    seed: u32,
) -> Result<RgbImage> {
    let mut frames = renderer.render_batch(optics, &[PressFrame { fields, seed }])?;
    frames
        .pop()
        .ok_or_else(|| anyhow::anyhow!("the renderer returned no frame"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::app::press_options::PressOptions;
    use std::sync::Arc;
    use tactex_core::tactile::sensor_profile::SensorProfile;
    use tactex_sim::render::gel::CpuRenderer;

    #[test]
    fn each_step_is_the_press_of_its_pose_and_depth_with_its_own_noise() {
        let request = PressOptions {
            radius_mm: Some(5.0),
            hardness: Some("40A".into()),
            fidelity: "halfspace".into(),
            grid_mm: Some(0.2),
            seed: 7,
            ..PressOptions::default()
        }
        .request(Arc::new(SensorProfile::gelsight_mini()))
        .unwrap();
        let mut steps = PressSteps::new(request.clone(), Box::new(CpuRenderer)).unwrap();
        let path = [([0.0, 0.0], 0.3), ([1.5, -1.0], 0.6), ([0.0, 0.0], 0.3)];
        let mut frames = Vec::new();
        for (k, (at_mm, depth_mm)) in path.into_iter().enumerate() {
            let pose = PressPose {
                at_mm,
                yaw_deg: 10.0,
            };
            let step = steps.step(pose, depth_mm).unwrap();
            // The same press alone, with the step's noise: the same figures, the same bytes.
            let alone = PressRequest {
                pose,
                depth_mm,
                seed: 7 + 2 + k as u32,
                ..request.clone()
            };
            let mut solved = alone.solve().unwrap();
            let (frame, reference) = solved.render(&alone, &mut CpuRenderer).unwrap();
            assert_eq!(step.report.force_n, solved.report.force_n, "step {k}");
            assert_eq!(step.solution.pressure_mpa, solved.solution.pressure_mpa);
            assert_eq!(step.fields.normal_mm, solved.pad_fields().normal_mm);
            assert!(
                step.frame == frame,
                "step {k}: the frame differs from the press's"
            );
            assert!(
                reference != *steps.reference(),
                "each frame draws its own noise"
            );
            frames.push(step.frame);
        }
        // A step back to an earlier pose gives its contact again, under new noise.
        assert!(frames[0] != frames[2]);
        assert_eq!(steps.steps(), 3);
        let off = steps.step(
            PressPose {
                at_mm: [50.0, 0.0],
                yaw_deg: 0.0,
            },
            0.3,
        );
        let e = off
            .err()
            .expect("a pose off the pad is refused")
            .to_string();
        assert!(e.starts_with("--at-mm: (50, 0) mm is off the pad"), "{e}");
    }
}
