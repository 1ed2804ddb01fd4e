//! Intel RealSense frames as V4L2 delivers them (librealsense is not packaged for Debian):
//! depth as Z16 (little-endian u16 in units of the device's depth scale, 0 invalid) and
//! colour as YUYV 4:2:2, converted with librealsense's own BT.601 integer formula
//! (`unpack_yuy2`).

use tactex_core::frames::DepthImage;
use tactex_core::image::{Luma, Rgb, RgbImage};

#[derive(Debug, thiserror::Error)]
pub enum RawFrameError {
    #[error("{format} frame of {got} bytes; {width}x{height} needs {want}")]
    Size {
        format: &'static str,
        got: usize,
        want: usize,
        width: u32,
        height: u32,
    },
    #[error("YUYV needs an even width, got {0}")]
    OddWidth(u32),
}

fn check(format: &'static str, bytes: &[u8], width: u32, height: u32) -> Result<(), RawFrameError> {
    let want = width as usize * height as usize * 2;
    if bytes.len() != want {
        return Err(RawFrameError::Size {
            format,
            got: bytes.len(),
            want,
            width,
            height,
        });
    }
    Ok(())
}

/// Z16 depth in metres: raw x `depth_scale_m` (a D405 reports 1e-4, a D435 1e-3).
pub fn depth_from_z16(
    bytes: &[u8],
    width: u32,
    height: u32,
    depth_scale_m: f64,
) -> Result<DepthImage, RawFrameError> {
    check("Z16", bytes, width, height)?;
    let raw: Vec<f32> = bytes
        .chunks_exact(2)
        .map(|c| (f64::from(u16::from_le_bytes([c[0], c[1]])) * depth_scale_m) as f32)
        .collect();
    Ok(DepthImage::from_fn(width, height, |x, y| {
        Luma([raw[(y * width + x) as usize]])
    }))
}

/// YUYV (Y0 U Y1 V per two pixels) to RGB, BT.601 limited range as librealsense does it.
pub fn rgb_from_yuyv(bytes: &[u8], width: u32, height: u32) -> Result<RgbImage, RawFrameError> {
    if !width.is_multiple_of(2) {
        return Err(RawFrameError::OddWidth(width));
    }
    check("YUYV", bytes, width, height)?;
    let mut out = RgbImage::new(width, height);
    for (i, quad) in bytes.chunks_exact(4).enumerate() {
        let (u, v) = (i32::from(quad[1]) - 128, i32::from(quad[3]) - 128);
        for (k, y) in [quad[0], quad[2]].into_iter().enumerate() {
            let c = 298 * (i32::from(y) - 16);
            let px = |n: i32| ((n + 128) >> 8).clamp(0, 255) as u8;
            let p = 2 * i + k;
            out.put_pixel(
                (p % width as usize) as u32,
                (p / width as usize) as u32,
                Rgb([px(c + 409 * v), px(c - 100 * u - 208 * v), px(c + 516 * u)]),
            );
        }
    }
    Ok(out)
}

/// A RealSense's colour (YUYV) and depth (Z16) V4L2 nodes behind core's `RgbdCamera`.
/// The two streams are read one after the other, not hardware-synchronised; on a D405
/// colour and depth come from the same imager, so they are aligned pixel for pixel. Other
/// models need librealsense's alignment, which this backend does not do.
#[cfg(all(target_os = "linux", feature = "v4l2"))]
pub struct RealSense {
    color: crate::v4l2_capture::V4l2Capture,
    depth: crate::v4l2_capture::V4l2Capture,
    intrinsics: tactex_core::geometry::CameraIntrinsics,
    pose: tactex_core::geometry::Pose,
    depth_scale_m: f64,
    name: String,
    opened: std::time::Instant,
}

#[cfg(all(target_os = "linux", feature = "v4l2"))]
impl RealSense {
    pub fn open(
        color: &str,
        depth: &str,
        intrinsics: tactex_core::geometry::CameraIntrinsics,
        pose: tactex_core::geometry::Pose,
        depth_scale_m: f64,
    ) -> Result<RealSense, tactex_core::devices::DeviceError> {
        let timeout = std::time::Duration::from_secs(2);
        let (w, h) = (intrinsics.width, intrinsics.height);
        let color = crate::v4l2_capture::V4l2Capture::open(
            "realsense colour",
            color,
            b"YUYV",
            w,
            h,
            timeout,
        )?;
        let depth = crate::v4l2_capture::V4l2Capture::open(
            "realsense depth",
            depth,
            b"Z16 ",
            w,
            h,
            timeout,
        )?;
        let name = format!("realsense {}", color.path().display());
        Ok(RealSense {
            color,
            depth,
            intrinsics,
            pose,
            depth_scale_m,
            name,
            opened: std::time::Instant::now(),
        })
    }

    fn failure(&self, e: RawFrameError) -> tactex_core::devices::DeviceError {
        tactex_core::devices::DeviceError::Failure {
            device: self.name.clone(),
            message: e.to_string(),
        }
    }
}

#[cfg(all(target_os = "linux", feature = "v4l2"))]
impl tactex_core::devices::RgbdCamera for RealSense {
    fn name(&self) -> &str {
        &self.name
    }
    fn intrinsics(&self) -> tactex_core::geometry::CameraIntrinsics {
        self.intrinsics
    }
    fn pose(&self) -> tactex_core::geometry::Pose {
        self.pose
    }
    fn capture(
        &mut self,
    ) -> Result<tactex_core::frames::RgbdFrame, tactex_core::devices::DeviceError> {
        let (w, h) = (self.intrinsics.width, self.intrinsics.height);
        let color = self.color.next_frame()?;
        let depth = self.depth.next_frame()?;
        Ok(tactex_core::frames::RgbdFrame {
            color: rgb_from_yuyv(&color, w, h).map_err(|e| self.failure(e))?,
            depth_m: depth_from_z16(&depth, w, h, self.depth_scale_m)
                .map_err(|e| self.failure(e))?,
            timestamp_s: self.opened.elapsed().as_secs_f64(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn z16_is_little_endian_times_the_depth_scale() {
        // 0x1388 = 5000 units of 0.1 mm = 0.5 m; 0 stays invalid.
        let d = depth_from_z16(&[0x88, 0x13, 0, 0], 2, 1, 1e-4).unwrap();
        assert!((d.get_pixel(0, 0)[0] - 0.5).abs() < 1e-7);
        assert_eq!(d.get_pixel(1, 0)[0], 0.0);
        assert!(depth_from_z16(&[0; 3], 2, 1, 1e-4).is_err());
    }

    #[test]
    fn yuyv_white_black_and_primaries_come_out_as_bt601_says() {
        // BT.601 limited range: white Y 235, black Y 16; red (81, 90, 240), blue (41, 240, 110).
        let frame = [235, 128, 16, 128, 81, 90, 81, 240, 41, 240, 41, 110];
        let rgb = rgb_from_yuyv(&frame, 2, 3).unwrap();
        assert_eq!(rgb.get_pixel(0, 0).0, [255, 255, 255]);
        assert_eq!(rgb.get_pixel(1, 0).0, [0, 0, 0]);
        let red = rgb.get_pixel(0, 1).0;
        assert!(red[0] >= 250 && red[1] <= 5 && red[2] <= 5, "{red:?}");
        let blue = rgb.get_pixel(0, 2).0;
        assert!(blue[2] >= 250 && blue[0] <= 5 && blue[1] <= 5, "{blue:?}");
        assert!(matches!(
            rgb_from_yuyv(&frame, 3, 2),
            Err(RawFrameError::OddWidth(3))
        ));
    }
}
