//! The GelSight renderer a device choice (`render_device`) opens.

use super::{CpuRenderer, GelRenderer, GpuRenderer, RenderError};
use crate::render::device::{DeviceChoice, pick_adapter};

/// The renderer picked, and why when that is worth telling the user.
pub struct RendererChoice {
    pub renderer: Box<dyn GelRenderer + Send>,
    pub note: Option<String>,
}

pub fn open_renderer(choice: DeviceChoice) -> Result<RendererChoice, RenderError> {
    let pick = pick_adapter(choice)?;
    let renderer: Box<dyn GelRenderer + Send> = match &pick.adapter {
        Some(adapter) => Box::new(GpuRenderer::new(adapter)?),
        None => Box::new(CpuRenderer),
    };
    Ok(RendererChoice {
        renderer,
        note: pick.note,
    })
}
