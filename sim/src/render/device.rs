//! Which device renders, for both renderers (GelSight frames and RGB-D scenes): `auto` takes a
//! hardware GPU adapter when there is one and otherwise the CPU path (software Vulkan is no
//! faster than plain Rust on the same CPU); `gpu` takes any Vulkan adapter, software ones
//! included, and is an error naming what is missing when there is none; `cpu` is the reference
//! path.

use std::str::FromStr;
use std::sync::{Arc, Mutex};

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

/// A wgpu device on one adapter whose validation errors come back as `RenderError`s, never
/// as panics.
pub struct GpuDevice {
    /// The adapter's name, type and backend, as errors and reports show it.
    pub name: String,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
    pub limits: wgpu::Limits,
    errors: Arc<Mutex<Vec<String>>>,
}

impl GpuDevice {
    pub fn open(adapter: &wgpu::Adapter, label: &str) -> Result<Self, RenderError> {
        let info = adapter.get_info();
        let name = format!("{} ({:?}, {:?})", info.name, info.device_type, info.backend);
        let limits = adapter.limits();
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some(label),
            required_features: wgpu::Features::empty(),
            required_limits: limits.clone(),
            ..Default::default()
        }))
        .map_err(|e| RenderError::Device {
            adapter: name.clone(),
            message: e.to_string(),
        })?;
        let errors = Arc::new(Mutex::new(Vec::new()));
        let sink = errors.clone();
        device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
            sink.lock().expect("error sink").push(e.to_string());
        }));
        Ok(Self {
            name,
            device,
            queue,
            limits,
            errors,
        })
    }

    pub fn error(&self, message: impl ToString) -> RenderError {
        RenderError::Device {
            adapter: self.name.clone(),
            message: message.to_string(),
        }
    }

    /// The validation errors raised since the last call, as one error.
    pub fn take_errors(&self) -> Result<(), RenderError> {
        let mut errors = self.errors.lock().expect("error sink");
        if errors.is_empty() {
            return Ok(());
        }
        let message = errors.join("; ");
        errors.clear();
        Err(self.error(message))
    }

    /// Submits the commands, waits for them, and hands the mapped `readback` buffer to `read`.
    pub fn submit_and_read<T>(
        &self,
        encoder: wgpu::CommandEncoder,
        readback: &wgpu::Buffer,
        read: impl FnOnce(&[u8]) -> T,
    ) -> Result<T, RenderError> {
        self.queue.submit([encoder.finish()]);
        let (tx, rx) = std::sync::mpsc::channel();
        readback.map_async(wgpu::MapMode::Read, .., move |r| {
            let _ = tx.send(r);
        });
        self.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| self.error(e))?;
        self.take_errors()?;
        rx.recv()
            .map_err(|e| self.error(e))?
            .map_err(|e| self.error(e))?;
        let view = readback.get_mapped_range(..).map_err(|e| self.error(e))?;
        let out = read(&view);
        drop(view);
        readback.unmap();
        Ok(out)
    }
}

/// Shader checks shared by both renderers' unit tests.
#[cfg(test)]
pub(crate) mod shader_checks {
    use wgpu::naga;

    /// Parses and validates WGSL with naga, panicking with the located message.
    pub(crate) fn validated(label: &str, source: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(source)
            .unwrap_or_else(|e| panic!("{label}: {}", e.emit_to_string(source)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{label}: {}", e.emit_to_string(source)));
        module
    }

    /// The size in bytes of the WGSL struct `name`, laid out as the shader sees it.
    pub(crate) fn struct_size(source: &str, name: &str) -> usize {
        let module = naga::front::wgsl::parse_str(source).unwrap();
        let ty = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name}"))
            .0;
        let mut layouter = naga::proc::Layouter::default();
        layouter.update(module.to_ctx()).unwrap();
        layouter[ty].size as usize
    }
}
