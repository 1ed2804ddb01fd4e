//! The scene renderer a device choice (`render_device`) opens.

use super::{CpuSceneRenderer, GpuSceneRenderer, SceneRenderer};
use crate::render::device::{DeviceChoice, RenderError, pick_adapter};
use std::sync::Arc;

/// The renderer picked, and why when that is worth telling the user.
pub struct SceneRendererChoice {
    pub renderer: Arc<dyn SceneRenderer>,
    pub note: Option<String>,
}

pub fn open_scene_renderer(choice: DeviceChoice) -> Result<SceneRendererChoice, RenderError> {
    let pick = pick_adapter(choice)?;
    let renderer: Arc<dyn SceneRenderer> = match &pick.adapter {
        Some(adapter) => Arc::new(GpuSceneRenderer::new(adapter)?),
        None => Arc::new(CpuSceneRenderer),
    };
    Ok(SceneRendererChoice {
        renderer,
        note: pick.note,
    })
}
