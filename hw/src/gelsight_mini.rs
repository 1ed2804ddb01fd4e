//! GelSight Mini frames as the vendor's SDK (gsrobotics/gsmini, `resize_crop_mini`) makes
//! them: the UVC camera streams MJPG at 3280x2464; a border of 1/7 of each side is cut
//! (two more rows at the top), and the rest is resized to 320x240 with OpenCV's bilinear
//! rule. Models trained on the vendor's frames see the same pixels from this code.

use tactex_core::image::{self, Rgb, RgbImage};

/// The frame every consumer of a GelSight Mini works at.
pub const WIDTH: u32 = 320;
pub const HEIGHT: u32 = 240;
/// The sensor's native MJPG stream.
pub const NATIVE_WIDTH: u32 = 3280;
pub const NATIVE_HEIGHT: u32 = 2464;

#[derive(Debug, thiserror::Error)]
pub enum FrameError {
    #[error("MJPG frame does not decode: {0}")]
    Decode(String),
    #[error("frame of {width}x{height} px is too small to crop to the gel")]
    TooSmall { width: u32, height: u32 },
}

/// One MJPG frame from the camera, decoded, cropped to the gel and resized to 320x240.
pub fn frame_from_mjpg(jpeg: &[u8]) -> Result<RgbImage, FrameError> {
    let decoded = tactex_core::image_file::decode(jpeg, image::ImageFormat::Jpeg)
        .map_err(FrameError::Decode)?
        .to_rgb8();
    crop_to_gel(&decoded)
}

/// The vendor's crop (1/7 of each side; rows from border + 2) and resize to 320x240.
pub fn crop_to_gel(frame: &RgbImage) -> Result<RgbImage, FrameError> {
    let (w, h) = frame.dimensions();
    let border_rows = h / 7;
    let border_cols = w / 7;
    if h < 2 * border_rows + 2 + 2 || w < 2 * border_cols + 2 || h < 14 || w < 14 {
        return Err(FrameError::TooSmall {
            width: w,
            height: h,
        });
    }
    let crop = image::imageops::crop_imm(
        frame,
        border_cols,
        border_rows + 2,
        w - 2 * border_cols,
        h - 2 * border_rows - 2,
    )
    .to_image();
    Ok(resize_bilinear_like_opencv(&crop, WIDTH, HEIGHT))
}

/// OpenCV's `INTER_LINEAR`: each output pixel samples the source at
/// ((x + 0.5) * scale - 0.5) between its four neighbours, with no averaging over the
/// footprint when shrinking. The image crate's filters average, which changes the pixels
/// a vendor-trained model expects.
fn resize_bilinear_like_opencv(src: &RgbImage, width: u32, height: u32) -> RgbImage {
    let taps = |dst: u32, src_len: u32| -> Vec<(u32, u32, f32)> {
        let scale = src_len as f64 / dst as f64;
        (0..dst)
            .map(|d| {
                let f = (d as f64 + 0.5) * scale - 0.5;
                let i = f.floor();
                let (mut i0, mut t) = (i as i64, (f - i) as f32);
                if i0 < 0 {
                    (i0, t) = (0, 0.0);
                }
                if i0 >= src_len as i64 - 1 {
                    (i0, t) = (src_len as i64 - 1, 0.0);
                }
                let i0 = i0 as u32;
                (i0, (i0 + 1).min(src_len - 1), t)
            })
            .collect()
    };
    let xs = taps(width, src.width());
    let ys = taps(height, src.height());
    RgbImage::from_fn(width, height, |x, y| {
        let (x0, x1, tx) = xs[x as usize];
        let (y0, y1, ty) = ys[y as usize];
        let p = |xx, yy| src.get_pixel(xx, yy).0.map(f32::from);
        let (a, b, c, d) = (p(x0, y0), p(x1, y0), p(x0, y1), p(x1, y1));
        Rgb(std::array::from_fn(|k| {
            let top = a[k] + (b[k] - a[k]) * tx;
            let bottom = c[k] + (d[k] - c[k]) * tx;
            (top + (bottom - top) * ty).round().clamp(0.0, 255.0) as u8
        }))
    })
}

/// A GelSight Mini on V4L2, behind core's `TactileSensor`.
#[cfg(all(target_os = "linux", feature = "v4l2"))]
pub struct GelSightMini {
    capture: crate::v4l2_capture::V4l2Capture,
    spec: tactex_core::tactile::spec::TactileSpec,
    name: String,
    opened: std::time::Instant,
}

#[cfg(all(target_os = "linux", feature = "v4l2"))]
impl GelSightMini {
    /// Opens the sensor by path or name ("GelSight Mini") at its native MJPG stream; its
    /// frames are read through `profile` (its calibrated table and gel).
    pub fn open(
        spec: &str,
        profile: tactex_core::tactile::spec::TactileSpec,
    ) -> Result<GelSightMini, tactex_core::devices::DeviceError> {
        let capture = crate::v4l2_capture::V4l2Capture::open(
            "gelsight mini",
            spec,
            b"MJPG",
            NATIVE_WIDTH,
            NATIVE_HEIGHT,
            std::time::Duration::from_secs(2),
        )?;
        let name = format!("gelsight mini {}", capture.path().display());
        Ok(GelSightMini {
            capture,
            spec: profile,
            name,
            opened: std::time::Instant::now(),
        })
    }
}

#[cfg(all(target_os = "linux", feature = "v4l2"))]
impl tactex_core::devices::TactileSensor for GelSightMini {
    fn name(&self) -> &str {
        &self.name
    }
    fn spec(&self) -> &tactex_core::tactile::spec::TactileSpec {
        &self.spec
    }
    fn capture(
        &mut self,
    ) -> Result<tactex_core::frames::TactileFrame, tactex_core::devices::DeviceError> {
        let jpeg = self.capture.next_frame()?;
        let image =
            frame_from_mjpg(&jpeg).map_err(|e| tactex_core::devices::DeviceError::Failure {
                device: self.name.clone(),
                message: e.to_string(),
            })?;
        Ok(tactex_core::frames::TactileFrame {
            image,
            timestamp_s: self.opened.elapsed().as_secs_f64(),
        })
    }
}
