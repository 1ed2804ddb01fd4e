//! The simulated GelSight Mini: the pad's contact with the object it presses, solved by the
//! elastic solver at the chosen fidelity on the world's meshes (`contact::pad`) -> the
//! GelSight renderer (`render::gel`, CPU reference path: one frame at a time gains nothing
//! from a dispatch) -> a seeded tactile frame.

use crate::contact::pad::{PressGrid, Spot, deepest_touch};
use crate::contact::{ContactProblem, ContactSolver, Fidelity};
use crate::render::gel::{
    CpuRenderer, GelImageFields, PressFrame, SensorOptics, image_fields, pad_rect,
};
use crate::world::SharedWorld;
use tactex_core::devices::{DeviceError, TactileSensor};
use tactex_core::frames::TactileFrame;
use tactex_core::hertz::Elastic;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_core::tactile::spec::TactileSpec;

pub struct SimGelSight {
    world: SharedWorld,
    spec: TactileSpec,
    /// Background, shading, markers, vignetting and camera noise of the rendered frames.
    pub optics: SensorOptics,
    fidelity: Fidelity,
    solver: ContactSolver,
    press: PressGrid,
    seed: u32,
    frames: u32,
}

impl SimGelSight {
    pub fn new(world: SharedWorld, sensor: &SensorProfile, fidelity: Fidelity, seed: u64) -> Self {
        Self {
            world,
            spec: sensor.spec.clone(),
            optics: SensorOptics::for_profile(sensor),
            fidelity,
            solver: ContactSolver::new(),
            press: PressGrid::default(),
            seed: (seed ^ (seed >> 32) ^ 0x6e15_5157) as u32,
            frames: 0,
        }
    }

    pub fn fidelity(&self) -> Fidelity {
        self.fidelity
    }

    fn failure(&self, message: String) -> DeviceError {
        DeviceError::Failure {
            device: self.name().into(),
            message,
        }
    }
}

impl TactileSensor for SimGelSight {
    fn name(&self) -> &str {
        "sim-gelsight-mini"
    }

    fn spec(&self) -> &TactileSpec {
        &self.spec
    }

    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        let world = self.world.clone();
        let mut world = world
            .lock()
            .map_err(|_| self.failure("the simulated world's lock is poisoned".into()))?;
        let pad = pad_rect(&self.optics);
        let tool = world.tool;
        let fields = match deepest_touch(&world, &tool, &pad) {
            Some(touch) => {
                let object = &world.objects[touch.object];
                let problem = ContactProblem {
                    surface: &touch.surface,
                    object: Elastic {
                        modulus_mpa: object.hardness.modulus_mpa(),
                        poisson: object.poisson,
                    },
                    gel: self.spec.gel,
                    pad,
                    approach_mm: touch.approach_mm,
                    cell_mm: None,
                };
                let solution = self
                    .press
                    .solve(
                        &mut self.solver,
                        &problem,
                        self.fidelity,
                        Spot::of(touch.object, &tool),
                    )
                    .map_err(|e| self.failure(format!("contact with the {}: {e}", object.label)))?;
                image_fields(&mut self.solver, &solution, &self.spec.gel, &self.optics)
            }
            None => GelImageFields::flat(self.spec.width_px, self.spec.height_px),
        };
        // Each frame its own noise: frame counter mixed into the device's seed.
        let seed = self
            .seed
            .wrapping_add(self.frames.wrapping_mul(0x9e37_79b9));
        self.frames += 1;
        let image = CpuRenderer.render_one(
            &self.optics,
            &PressFrame {
                fields: &fields,
                seed,
            },
        );
        world.time_s += 1.0 / self.spec.frame_rate_hz;
        Ok(TactileFrame {
            image,
            timestamp_s: world.time_s,
        })
    }
}
