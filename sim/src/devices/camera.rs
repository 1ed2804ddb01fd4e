//! The simulated RGB-D camera: a clean render of the world (`render::scene`, CPU or GPU) at the
//! scene's intrinsics and pose, then per frame seeded colour noise and the RealSense D435
//! depth noise model (`depth_noise`).

use crate::devices::depth_noise::{CleanDepth, RealSenseNoise};
use crate::render::board_view::SheetInCamera;
use crate::render::device::RenderError;
use crate::render::scene::{CleanRender, CpuSceneRenderer, SceneGeometry, SceneRenderer};
use crate::world::{HeldBoard, SharedWorld};
use image::{Luma, Rgb, RgbImage};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use std::sync::Arc;
use tactex_core::devices::{DeviceError, RgbdCamera};
use tactex_core::frames::{DepthImage, RgbdFrame};
use tactex_core::geometry::{CameraIntrinsics, Pose};

pub use crate::render::scene::InstanceImage;

/// The mask (255 inside) of one instance id.
pub fn instance_mask(instances: &InstanceImage, id: u16) -> image::GrayImage {
    let (w, h) = instances.dimensions();
    image::GrayImage::from_fn(w, h, |x, y| {
        Luma([if instances.get_pixel(x, y)[0] == id {
            255
        } else {
            0
        }])
    })
}

/// What a clean render depends on besides the objects: the tool's pose, the camera's, the
/// board the arm holds.
type RenderKey = (Pose, Pose, Option<HeldBoard>);

pub struct SimCamera {
    world: SharedWorld,
    intrinsics: CameraIntrinsics,
    pose: Pose,
    renderer: Arc<dyn SceneRenderer>,
    /// The objects do not move while they are watched: one clean render serves every frame
    /// until the arm's pad moves (the arm is in the picture once it enters the view) or the
    /// board it holds changes (or the camera is moved).
    clean: Option<(RenderKey, CleanRender)>,
    rng: ChaCha8Rng,
    /// Colour noise (grey levels, 1 sigma).
    pub color_noise: f64,
    pub depth_noise: RealSenseNoise,
    pub frame_rate_hz: f64,
}

impl SimCamera {
    pub fn new(world: SharedWorld, seed: u64) -> Self {
        let (intrinsics, pose) = {
            let w = world.lock().expect("world lock");
            (w.intrinsics, w.camera_pose)
        };
        Self {
            world,
            intrinsics,
            pose,
            renderer: Arc::new(CpuSceneRenderer),
            clean: None,
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x00ca_3e7a),
            color_noise: 2.0,
            depth_noise: RealSenseNoise::default(),
            frame_rate_hz: 30.0,
        }
    }

    /// Reports `pose` from now on (what its user measured by hand or calibrated) while it
    /// renders from where the world has it: a camera misplaced against its belief.
    pub fn believe_pose(&mut self, pose: Pose) {
        self.pose = pose;
    }

    /// Renders through `renderer` from now on (the CPU reference by default).
    pub fn set_renderer(&mut self, renderer: Arc<dyn SceneRenderer>) {
        self.renderer = renderer;
        self.clean = None;
    }

    /// The scene without noise, with instance ids (the ground truth); rendered again only
    /// when the pad has moved since the last render.
    pub fn clean(&mut self) -> Result<&CleanRender, RenderError> {
        let world = self.world.lock().expect("world lock");
        let key = (world.tool, world.camera_pose, world.held_board.clone());
        if self.clean.as_ref().is_none_or(|(seen, _)| *seen != key) {
            let geometry = SceneGeometry::of_world(&world);
            let mut render = self.renderer.render(&geometry)?;
            if let Some(held) = &world.held_board {
                let (tool, camera) = (world.tool, world.camera_pose);
                draw_held_board(held, &tool, &camera, &self.intrinsics, &mut render);
            }
            self.clean = Some((key, render));
        }
        drop(world);
        Ok(&self.clean.as_ref().expect("rendered").1)
    }
}

/// The board the arm holds drawn into the scene's render, behind whatever is nearer; it
/// carries the arm's instance id (0), as the rest of the arm's end does.
fn draw_held_board(
    held: &HeldBoard,
    tool: &Pose,
    camera: &Pose,
    intrinsics: &CameraIntrinsics,
    render: &mut CleanRender,
) {
    let face = held.board.face();
    let board_in_camera = camera.inverse().compose(&tool.compose(&held.board_in_tool));
    SheetInCamera::new(&face, &board_in_camera, &held.look).over_render(
        intrinsics,
        &mut render.color,
        &mut render.depth_m,
        &mut render.specular,
        &mut render.instances,
        0,
    );
}

impl RgbdCamera for SimCamera {
    fn name(&self) -> &str {
        "sim-rgbd"
    }

    fn intrinsics(&self) -> CameraIntrinsics {
        self.intrinsics
    }

    fn pose(&self) -> Pose {
        self.pose
    }

    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        let noise = self.color_noise;
        let depth_noise = self.depth_noise.clone();
        self.clean().map_err(|e| DeviceError::Failure {
            device: "sim-rgbd".into(),
            message: e.to_string(),
        })?;
        let clean = &self.clean.as_ref().expect("rendered").1;
        let k = self.intrinsics;
        let unit = Normal::new(0.0, 1.0).expect("valid");
        let rng = &mut self.rng;
        let mut color = RgbImage::new(k.width, k.height);
        for (p, c) in color.pixels_mut().zip(&clean.color) {
            *p = Rgb(std::array::from_fn(|i| {
                (c[i] * 255.0 + noise * unit.sample(rng))
                    .round()
                    .clamp(0.0, 255.0) as u8
            }));
        }
        let depth = depth_noise.apply(
            &CleanDepth {
                width: k.width as usize,
                height: k.height as usize,
                depth_m: &clean.depth_m,
                color: &clean.color,
                specular: &clean.specular,
                fx: k.fx,
            },
            rng,
        );
        let mut world = self.world.lock().expect("world lock");
        world.time_s += 1.0 / self.frame_rate_hz;
        Ok(RgbdFrame {
            color,
            depth_m: DepthImage::from_raw(k.width, k.height, depth).expect("sized"),
            timestamp_s: world.time_s,
        })
    }
}
