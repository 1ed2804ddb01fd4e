//! Which device renders: `auto` takes a hardware GPU adapter when there is one and otherwise
//! the CPU path (software Vulkan is no faster than plain Rust on the same CPU); `gpu` takes
//! any Vulkan adapter, software ones included, and is an error naming what is missing when
//! there is none; `cpu` is the reference path.

use super::{CpuRenderer, GelRenderer, GpuRenderer, RenderError};
use std::str::FromStr;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DeviceChoice {
    #[default]
    Auto,
    Gpu,
    Cpu,
}

impl FromStr for DeviceChoice {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.to_ascii_lowercase().as_str() {
            "auto" => Ok(Self::Auto),
            "gpu" => Ok(Self::Gpu),
            "cpu" => Ok(Self::Cpu),
            other => Err(format!("unknown device '{other}' (auto, gpu or cpu)")),
        }
    }
}

/// The renderer picked, and why when that is worth telling the user.
pub struct RendererChoice {
    pub renderer: Box<dyn GelRenderer + Send>,
    pub note: Option<String>,
}

fn is_hardware(info: &wgpu::AdapterInfo) -> bool {
    matches!(
        info.device_type,
        wgpu::DeviceType::DiscreteGpu
            | wgpu::DeviceType::IntegratedGpu
            | wgpu::DeviceType::VirtualGpu
    )
}

/// Vulkan adapters on this machine, hardware ones first (discrete before integrated).
pub fn adapters() -> Vec<wgpu::Adapter> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor {
        backends: wgpu::Backends::VULKAN,
        ..wgpu::InstanceDescriptor::new_without_display_handle()
    });
    let mut found = pollster::block_on(instance.enumerate_adapters(wgpu::Backends::VULKAN));
    found.sort_by_key(|a| match a.get_info().device_type {
        wgpu::DeviceType::DiscreteGpu => 0,
        wgpu::DeviceType::IntegratedGpu => 1,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 3,
        wgpu::DeviceType::Other => 4,
    });
    found
}

pub fn open_renderer(choice: DeviceChoice) -> Result<RendererChoice, RenderError> {
    let cpu = || RendererChoice {
        renderer: Box::new(CpuRenderer),
        note: None,
    };
    match choice {
        DeviceChoice::Cpu => Ok(cpu()),
        DeviceChoice::Gpu => {
            let found = adapters();
            let adapter = found.first().ok_or_else(|| RenderError::NoAdapter {
                found: "the Vulkan loader lists no adapter".into(),
            })?;
            Ok(RendererChoice {
                renderer: Box::new(GpuRenderer::new(adapter)?),
                note: None,
            })
        }
        DeviceChoice::Auto => {
            let found = adapters();
            match found.iter().find(|a| is_hardware(&a.get_info())) {
                Some(adapter) => Ok(RendererChoice {
                    renderer: Box::new(GpuRenderer::new(adapter)?),
                    note: None,
                }),
                None => {
                    let names: Vec<String> = found.iter().map(|a| a.get_info().name).collect();
                    Ok(RendererChoice {
                        note: Some(if names.is_empty() {
                            "no GPU adapter: rendering on the CPU path".into()
                        } else {
                            format!(
                                "no hardware GPU adapter (only {}): rendering on the CPU path",
                                names.join(", ")
                            )
                        }),
                        ..cpu()
                    })
                }
            }
        }
    }
}
