//! RGB-D scene synthesis without noise: colour (ambient plus a directional light, soft
//! Blinn-Phong highlights on fruit skins), camera-frame depth and instance ids, at the
//! camera's intrinsics and pose. The noise of a real capture is added by `SimCamera`.
//!
//! One contract, two implementations: `CpuSceneRenderer` (the reference: a z-buffer
//! rasterizer in f64) and `GpuSceneRenderer` (a wgpu raster pipeline, `shaders/scene_raster.wgsl`).
//! Both read one `SceneGeometry`, so they draw the same triangles under the same light.

mod cpu;
mod device;
mod geometry;
mod gpu;
mod tool_body;

pub use cpu::CpuSceneRenderer;
pub use device::{SceneRendererChoice, open_scene_renderer};
pub use geometry::{SceneGeometry, SceneTriangle};
pub use gpu::{GpuSceneRenderer, SCENE_SHADER};

use crate::render::device::RenderError;
use glam::DVec3;
use image::{ImageBuffer, Luma};

/// Instance ids per pixel: 0 for the table, the floor and the arm, i + 1 for object i.
pub type InstanceImage = ImageBuffer<Luma<u16>, Vec<u16>>;

/// A noise-free render with ground truth, row-major at the camera's resolution.
#[derive(Clone)]
pub struct CleanRender {
    /// Linear colour in [0, 1].
    pub color: Vec<[f64; 3]>,
    /// The specular part of `color` (grey level in [0, 1]); specular spots lose depth.
    pub specular: Vec<f64>,
    /// Camera-frame z in metres; 0 where no surface is seen.
    pub depth_m: Vec<f64>,
    pub instances: InstanceImage,
}

/// The scene's light, the same for both renderers.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Lighting {
    /// Unit direction towards the light, world frame.
    pub light: DVec3,
    pub ambient: f64,
    pub diffuse: f64,
    /// Peak of the Blinn-Phong highlight on objects (the table is matte).
    pub specular: f64,
    pub shininess: f64,
}

impl Default for Lighting {
    fn default() -> Self {
        Self {
            light: DVec3::new(0.25, 0.35, 0.9).normalize(),
            ambient: 0.38,
            diffuse: 0.62,
            specular: 0.35,
            shininess: 60.0,
        }
    }
}

/// Renders clean RGB-D frames with ground truth. `&self`: one renderer serves many threads.
pub trait SceneRenderer: Send + Sync {
    /// What renders: "cpu" or the GPU adapter's name.
    fn name(&self) -> String;
    fn render(&self, scene: &SceneGeometry) -> Result<CleanRender, RenderError>;
}
