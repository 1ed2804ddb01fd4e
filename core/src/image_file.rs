//! Images read from files and devices with their work bounded before decoding: a small PNG
//! can claim 10000 x 10000 pixels, and decoding it whole would take gigabytes. Every image
//! tactex reads (frames, backgrounds, recorded sessions, camera JPEGs) comes through here.

use image::{DynamicImage, ImageFormat, ImageReader, Limits};
use std::io::Cursor;
use std::path::Path;

/// The widest or tallest image read: above any camera or GelSight frame tactex handles
/// (the D435's 1920 x 1080, the GelSight Mini's 3280 x 2464).
pub const MAX_SIDE_PX: u32 = 4096;

fn limits() -> Limits {
    let mut limits = Limits::default();
    limits.max_image_width = Some(MAX_SIDE_PX);
    limits.max_image_height = Some(MAX_SIDE_PX);
    // A 4096 x 4096 16-bit RGBA image, with room for the decoder's own buffers.
    limits.max_alloc = Some(256 << 20);
    limits
}

fn say(e: image::ImageError) -> String {
    match e {
        image::ImageError::Limits(_) => {
            format!("larger than {MAX_SIDE_PX} x {MAX_SIDE_PX} px, the most tactex reads")
        }
        e => e.to_string(),
    }
}

/// The width and height the image at `path` declares, read from its header alone (a file
/// that is not an image in a known format fails here, before anything waits on it).
pub fn dimensions(path: &Path) -> Result<(u32, u32), String> {
    reader(path)?.into_dimensions().map_err(say)
}

/// A reader of the regular file at `path`, its format guessed from its first bytes.
fn reader(path: &Path) -> Result<ImageReader<std::io::BufReader<std::fs::File>>, String> {
    crate::text_file::regular(path).map_err(|e| e.to_string())?;
    ImageReader::open(path)
        .map_err(|e| e.to_string())?
        .with_guessed_format()
        .map_err(|e| e.to_string())
}

/// The image at `path`, its format from its contents. The error is the reason alone; the
/// caller names the file and what it was for.
pub fn open(path: &Path) -> Result<DynamicImage, String> {
    let mut reader = reader(path)?;
    reader.limits(limits());
    reader.decode().map_err(say)
}

/// An image in memory in the given format (a camera's MJPG frame).
pub fn decode(bytes: &[u8], format: ImageFormat) -> Result<DynamicImage, String> {
    let mut reader = ImageReader::with_format(Cursor::new(bytes), format);
    reader.limits(limits());
    reader.decode().map_err(say)
}

/// Why a decoded image cannot be a tactile frame, if it cannot: a greyscale image (the
/// shading is read from three channels) or one more than half saturated (it carries no
/// shading). The frames read, the no-contact references and profiles' backgrounds.
pub fn tactile_frame_fault(decoded: &DynamicImage) -> Option<String> {
    if !decoded.color().has_color() {
        return Some(
            "a greyscale image; a tactile frame is colour (its shading is read from three channels)"
                .into(),
        );
    }
    rgb_frame_fault(&decoded.to_rgb8())
}

/// Why a colour frame (a file's, or a sensor's as captured) carries no shading to read, if it
/// carries none: more than half saturated, or featureless (a blank frame, the LEDs off).
pub fn rgb_frame_fault(frame: &image::RgbImage) -> Option<String> {
    // One pass over the pixels: the press checks every frame it looks at.
    let mut histograms = [[0usize; 256]; 3];
    let mut saturated = 0usize;
    for p in frame.as_raw().chunks_exact(3) {
        for (histogram, v) in histograms.iter_mut().zip(p) {
            histogram[*v as usize] += 1;
        }
        saturated += usize::from(p.contains(&255));
    }
    let n = frame.pixels().len();
    if 2 * saturated > n {
        return Some(format!(
            "{:.0}% of its pixels are saturated (255); a tactile frame this blown out carries no shading",
            100.0 * saturated as f64 / n as f64
        ));
    }
    let spread = spread_grey(&histograms, n);
    (spread < MIN_SPREAD_GREY).then(|| {
        format!(
            "featureless (98% of its pixels within {spread} grey levels in every channel); a tactile frame shows its gel's shading and markers"
        )
    })
}

/// The dimmest, lowest-contrast sensor made (the synthetic dim-tinted profile's background)
/// spans 16 grey levels between its 1st and 99th percentiles; a blank frame spans a camera's
/// noise. A reading of a blank frame against a reference finds a deep imprint everywhere.
const MIN_SPREAD_GREY: u8 = 4;

/// The largest, over the three channels' histograms of `n` pixels, of the span between the
/// 1st and 99th percentile.
fn spread_grey(histograms: &[[usize; 256]; 3], n: usize) -> u8 {
    histograms
        .iter()
        .map(|histogram| {
            let level = |share: f64| {
                let want = (share * n as f64) as usize;
                let mut seen = 0;
                histogram
                    .iter()
                    .position(|&k| {
                        seen += k;
                        seen > want
                    })
                    .unwrap_or(255) as u8
            };
            level(0.99) - level(0.01)
        })
        .max()
        .unwrap_or(0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_blank_frame_is_not_a_tactile_frame() {
        let blank = DynamicImage::ImageRgb8(image::RgbImage::from_pixel(
            64,
            48,
            image::Rgb([140, 120, 100]),
        ));
        let fault = tactile_frame_fault(&blank).unwrap();
        assert!(fault.starts_with("featureless"), "{fault}");
        // A dim, low-contrast gel (a 12-level vignette) is a frame.
        let dim = image::RgbImage::from_fn(64, 48, |x, _| {
            let v = 60 + (x * 12 / 63) as u8;
            image::Rgb([v, v + 3, v + 6])
        });
        assert_eq!(tactile_frame_fault(&DynamicImage::ImageRgb8(dim)), None);
    }

    #[test]
    fn an_image_claiming_more_pixels_than_any_sensor_is_refused_before_decoding() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("big.png");
        image::GrayImage::new(MAX_SIDE_PX + 1, 8)
            .save(&path)
            .unwrap();
        let e = open(&path).unwrap_err();
        assert!(e.contains("larger than 4096 x 4096 px"), "{e}");
        let ok = tmp.path().join("ok.png");
        image::RgbImage::new(320, 240).save(&ok).unwrap();
        assert_eq!(open(&ok).unwrap().width(), 320);
        let e = open(&tmp.path().join("none.png")).unwrap_err();
        assert!(e.contains("No such file"), "{e}");
    }
}
