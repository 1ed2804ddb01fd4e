//! Frames from a V4L2 capture device: the GelSight Mini (a UVC camera) and a RealSense's
//! colour and depth nodes, opened by path (/dev/videoN) or by the name the driver gives
//! the device (as `v4l2-ctl --list-devices` shows it).

use std::path::{Path, PathBuf};
use std::time::Duration;
use tactex_core::devices::DeviceError;
use v4l::buffer::Type;
use v4l::io::mmap::Stream;
use v4l::io::traits::CaptureStream;
use v4l::video::Capture;
use v4l::{Device, FourCC};

/// Where video devices list their names.
const SYSFS: &str = "/sys/class/video4linux";

fn failure(device: &str, message: impl Into<String>) -> DeviceError {
    DeviceError::Failure {
        device: device.into(),
        message: message.into(),
    }
}

/// The device node for `spec`: a path as given, or the first node whose driver-given name
/// contains `spec` (case-insensitive).
pub fn resolve(label: &str, spec: &str) -> Result<PathBuf, DeviceError> {
    if spec.starts_with('/') {
        let path = Path::new(spec);
        if !path.exists() {
            return Err(failure(label, format!("{spec}: no such video device")));
        }
        return Ok(path.to_path_buf());
    }
    let mut seen = Vec::new();
    let mut nodes: Vec<PathBuf> = std::fs::read_dir(SYSFS)
        .map(|d| d.filter_map(|e| e.ok().map(|e| e.path())).collect())
        .unwrap_or_default();
    nodes.sort();
    for node in nodes {
        let Ok(name) = std::fs::read_to_string(node.join("name")) else {
            continue;
        };
        let name = name.trim().to_string();
        if name.to_lowercase().contains(&spec.to_lowercase())
            && let Some(dev) = node.file_name()
        {
            return Ok(Path::new("/dev").join(dev));
        }
        seen.push(name);
    }
    let found = if seen.is_empty() {
        "none".to_string()
    } else {
        seen.join(", ")
    };
    Err(failure(
        label,
        format!("no video device named like '{spec}' (found: {found})"),
    ))
}

/// One capture stream in a fixed format, memory-mapped.
pub struct V4l2Capture {
    label: String,
    path: PathBuf,
    stream: Stream<'static>,
    // The stream holds the device's handle; the device is kept for its lifetime.
    _device: Device,
}

impl V4l2Capture {
    /// Opens `spec` as `label` (for errors) and sets `fourcc` at `width` x `height`;
    /// a device that cannot deliver exactly that is an error naming what it offered.
    pub fn open(
        label: &str,
        spec: &str,
        fourcc: &[u8; 4],
        width: u32,
        height: u32,
        timeout: Duration,
    ) -> Result<V4l2Capture, DeviceError> {
        let path = resolve(label, spec)?;
        let at = |e: std::io::Error| failure(label, format!("{}: {e}", path.display()));
        let device = Device::with_path(&path).map_err(at)?;
        let mut format = device.format().map_err(at)?;
        format.width = width;
        format.height = height;
        format.fourcc = FourCC::new(fourcc);
        let set = device.set_format(&format).map_err(at)?;
        if set.fourcc != format.fourcc || set.width != width || set.height != height {
            return Err(failure(
                label,
                format!(
                    "{}: asked for {} {width}x{height}, the device gives {} {}x{}",
                    path.display(),
                    String::from_utf8_lossy(fourcc),
                    set.fourcc,
                    set.width,
                    set.height
                ),
            ));
        }
        let mut stream = Stream::with_buffers(&device, Type::VideoCapture, 4).map_err(at)?;
        stream.set_timeout(timeout);
        Ok(V4l2Capture {
            label: label.into(),
            path,
            stream,
            _device: device,
        })
    }

    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The next frame's bytes as the driver filled them.
    pub fn next_frame(&mut self) -> Result<Vec<u8>, DeviceError> {
        let (buf, meta) = self
            .stream
            .next()
            .map_err(|e| failure(&self.label, format!("{}: {e}", self.path.display())))?;
        let used = (meta.bytesused as usize).min(buf.len());
        Ok(buf[..used].to_vec())
    }
}
