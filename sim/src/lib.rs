//! tactex-sim: the simulated twin behind tactex-core's device traits.
//!
//! One `SimWorld` (objects settled on the table by rapier3d, the tool pose, the simulated
//! clock) is shared by the sim devices: `SimCamera` renders RGB-D frames of it, `SimArm`
//! moves the GelSight pad through it, and `SimGelSight` renders what the gel sees when the
//! pad presses into an object (elastic contact -> gel fields -> shading and markers).
//!
//! By stage: `devices/` (the sim camera, arm and GelSight, the RealSense depth noise),
//! `contact/` (the elastic contact, one file per fidelity level, and the pad's grid),
//! `render/{gel,scene}/` (GelSight and RGB-D image synthesis, CPU and wgpu paths, and the
//! render device choice), `datagen/` (randomised presses and scenes, and the press protocol
//! on the solver alone). `world` and `mesh` are the table and its bodies.

pub mod arm;
pub mod contact;
pub mod datagen;
pub mod devices;
pub mod mesh;
pub mod perception_error;
pub mod render;
pub mod world;

use contact::Fidelity;
use tactex_core::scene::Scene;
use tactex_core::tactile::sensor_profile::SensorProfile;

/// The three sim devices over one shared world.
pub struct SimDevices {
    pub world: world::SharedWorld,
    pub camera: devices::camera::SimCamera,
    pub tactile: devices::gelsight::SimGelSight,
    pub arm: devices::arm::SimArm,
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
            camera: devices::camera::SimCamera::new(shared.clone(), seed),
            tactile: devices::gelsight::SimGelSight::new(shared.clone(), &sensor, fidelity, seed),
            arm: devices::arm::SimArm::new(shared.clone(), spec),
            world: shared,
        })
    }

    /// Stands the scene camera at `truth` (where it renders from) while it reports `believed`
    /// (where its user thinks it stands): a rig whose camera was placed with an error.
    pub fn place_camera(
        &mut self,
        truth: tactex_core::geometry::Pose,
        believed: tactex_core::geometry::Pose,
    ) {
        self.world.lock().expect("world lock").camera_pose = truth;
        self.camera.believe_pose(believed);
    }
}
