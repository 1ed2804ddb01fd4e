//! tactex-sim: the simulated twin behind tactex-core's device traits.
//!
//! One `SimWorld` (objects settled on the table by rapier3d, the tool pose, the simulated
//! clock) is shared by the sim devices: `SimCamera` renders RGB-D frames of it, `SimArm`
//! moves the GelSight pad through it, and `SimGelSight` renders what the gel sees when the
//! pad presses into an object (elastic contact -> gel fields -> shading and markers).

pub mod arm;
pub mod camera;
pub mod depth_noise;
pub mod elastic;
pub mod gel_render;
pub mod gelsight;
pub mod mesh;
pub mod pad_contact;
pub mod perception_error;
pub mod press_protocol;
pub mod render_device;
pub mod scene_random;
pub mod scene_render;
pub mod tactile_sample;
pub mod world;

use elastic::Fidelity;
use tactex_core::scene::Scene;
use tactex_core::tactile::sensor_profile::SensorProfile;

/// The three sim devices over one shared world.
pub struct SimDevices {
    pub world: world::SharedWorld,
    pub camera: camera::SimCamera,
    pub tactile: gelsight::SimGelSight,
    pub arm: arm::SimArm,
}

impl SimDevices {
    /// The devices with the stock GelSight Mini, its contact solved at the `layer` level.
    pub fn from_scene(scene: &Scene, seed: u64) -> Result<Self, world::WorldError> {
        Self::with_sensor(scene, seed, SensorProfile::gelsight_mini(), Fidelity::Layer)
    }

    /// The devices with another tactile sensor than the stock GelSight Mini (a user's
    /// calibrated profile, a softer gel, another marker grid: what-if runs, and sessions
    /// recorded with such a sensor), its contact solved at `fidelity`.
    pub fn with_sensor(
        scene: &Scene,
        seed: u64,
        sensor: SensorProfile,
        fidelity: Fidelity,
    ) -> Result<Self, world::WorldError> {
        let shared = world::SimWorld::from_scene(scene)?.shared();
        let spec = sensor.spec.clone();
        Ok(Self {
            camera: camera::SimCamera::new(shared.clone(), seed),
            tactile: gelsight::SimGelSight::new(shared.clone(), &sensor, fidelity, seed),
            arm: arm::SimArm::new(shared.clone(), spec),
            world: shared,
        })
    }
}
