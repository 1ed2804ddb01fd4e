//! Which device renders, for both renderers (GelSight frames and RGB-D scenes): `auto` takes a
//! hardware GPU adapter when there is one and otherwise the CPU path (software Vulkan is no
//! faster than plain Rust on the same CPU); `gpu` takes any Vulkan adapter, software ones
//! included, and is an error naming what is missing when there is none; `cpu` is the reference
//! path.

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

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RenderError {
    #[error("{field}: {message}")]
    Invalid { field: String, message: String },
    #[error(
        "--device gpu: no Vulkan adapter found ({found}); install a GPU driver, or Debian's mesa-vulkan-drivers and libvulkan1 for software Vulkan, or use --device cpu"
    )]
    NoAdapter { found: String },
    #[error("GPU device {adapter}: {message}")]
    Device { adapter: String, message: String },
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

/// The adapter a choice names (None: render on the CPU path), and why when that is worth
/// telling the user.
pub struct AdapterPick {
    pub adapter: Option<wgpu::Adapter>,
    pub note: Option<String>,
}

pub fn pick_adapter(choice: DeviceChoice) -> Result<AdapterPick, RenderError> {
    match choice {
        DeviceChoice::Cpu => Ok(AdapterPick {
            adapter: None,
            note: None,
        }),
        DeviceChoice::Gpu => {
            let adapter = adapters()
                .into_iter()
                .next()
                .ok_or_else(|| RenderError::NoAdapter {
                    found: "the Vulkan loader lists no adapter".into(),
                })?;
            Ok(AdapterPick {
                adapter: Some(adapter),
                note: None,
            })
        }
        DeviceChoice::Auto => {
            let found = adapters();
            let names: Vec<String> = found.iter().map(|a| a.get_info().name).collect();
            match found.into_iter().find(|a| is_hardware(&a.get_info())) {
                Some(adapter) => Ok(AdapterPick {
                    adapter: Some(adapter),
                    note: None,
                }),
                None => Ok(AdapterPick {
                    adapter: None,
                    note: Some(if names.is_empty() {
                        "no GPU adapter: rendering on the CPU path".into()
                    } else {
                        format!(
                            "no hardware GPU adapter (only {}): rendering on the CPU path",
                            names.join(", ")
                        )
                    }),
                }),
            }
        }
    }
}
