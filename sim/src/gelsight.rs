//! The simulated GelSight Mini: gel fields from the contact model at the pad's pose ->
//! the GelSight renderer (`gel_render`, CPU reference path: one frame at a time gains nothing
//! from a dispatch) -> a seeded tactile frame.

use crate::contact::gel_fields;
use crate::gel_render::{CpuRenderer, GelImageFields, PressFrame, SensorOptics};
use crate::world::SharedWorld;
use tactex_core::devices::{DeviceError, TactileSensor};
use tactex_core::frames::TactileFrame;
use tactex_core::tactile_spec::TactileSpec;

pub struct SimGelSight {
    world: SharedWorld,
    spec: TactileSpec,
    /// Background, shading, markers, vignetting and camera noise of the rendered frames.
    pub optics: SensorOptics,
    seed: u32,
    frames: u32,
}

impl SimGelSight {
    pub fn new(world: SharedWorld, spec: TactileSpec, seed: u64) -> Self {
        let optics = SensorOptics::for_spec(&spec);
        Self {
            world,
            spec,
            optics,
            seed: (seed ^ (seed >> 32) ^ 0x6e15_5157) as u32,
            frames: 0,
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
        let mut world = self.world.lock().map_err(|_| DeviceError::Failure {
            device: "sim-gelsight-mini".into(),
            message: "the simulated world's lock is poisoned".into(),
        })?;
        let fields = match gel_fields(&world, &world.tool, &self.spec) {
            Some(f) => GelImageFields {
                width: self.spec.width_px,
                height: self.spec.height_px,
                normal_mm: f.normal_mm.iter().map(|v| *v as f32).collect(),
                lateral_x_mm: f.lateral_x_mm.iter().map(|v| *v as f32).collect(),
                lateral_y_mm: f.lateral_y_mm.iter().map(|v| *v as f32).collect(),
            },
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
