//! Calibrating a tactile sensor's shading from presses of a ball of known radius, as real
//! users do (Taxim, FOTS): inside the annotated contact circle the gel takes the ball's shape,
//! so every pixel there has a known slope; far from the contact the gel is flat. Each such
//! pixel is a `ShadingSample` of its colour change over the no-contact frame.

use crate::tactile::shading_table::{ShadingSample, frame_position};
use image::RgbImage;
use std::path::Path;

/// One annotated press: which image, where the ball touched and how large the contact was.
#[derive(Clone, Debug, PartialEq)]
pub struct BallPress {
    pub image: String,
    /// Contact centre in pixels (x along columns, y along rows).
    pub centre_px: [f64; 2],
    pub contact_radius_px: f64,
}

#[derive(Debug, thiserror::Error)]
pub enum AnnotationError {
    #[error("{path}: {message}")]
    Read { path: String, message: String },
    /// A press the file lists that cannot be used as it is: its image's size, a circle off
    /// the frame or wider than the ball.
    #[error("{path}: {message}")]
    Press { path: String, message: String },
    #[error("{path}:{line}: {message}")]
    Row {
        path: String,
        line: usize,
        message: String,
    },
}

/// Reads `image,center_x_px,center_y_px,contact_radius_px` rows (a header line first).
/// Annotated presses one calibration reads at most: each is an image decoded and fitted
/// (the FOTS set has 30).
pub const MAX_PRESSES: usize = 1000;

pub fn read_annotations(path: &Path) -> Result<Vec<BallPress>, AnnotationError> {
    let shown = path.display().to_string();
    let text = crate::text_file::read_to_string(path).map_err(|e| AnnotationError::Read {
        path: shown.clone(),
        message: e.to_string(),
    })?;
    // Spreadsheets save CSV with a byte-order mark, which would stick to the first column.
    let text = text.strip_prefix('\u{feff}').unwrap_or(&text);
    let mut lines = text.lines().enumerate();
    let expected = ["image", "center_x_px", "center_y_px", "contact_radius_px"];
    match lines.next() {
        Some((_, header))
            if header
                .split(',')
                .map(str::trim)
                .eq(expected.iter().copied()) => {}
        _ => {
            return Err(AnnotationError::Row {
                path: shown,
                line: 1,
                message: format!("header must be {}", expected.join(",")),
            });
        }
    }
    let mut out: Vec<BallPress> = Vec::new();
    let mut first_line = std::collections::HashMap::new();
    for (k, line) in lines {
        if line.trim().is_empty() {
            continue;
        }
        if out.len() == MAX_PRESSES {
            return Err(AnnotationError::Read {
                path: shown,
                message: format!(
                    "more than {MAX_PRESSES} annotated presses, the most one calibration reads"
                ),
            });
        }
        let row = |message: String| AnnotationError::Row {
            path: shown.clone(),
            line: k + 1,
            message,
        };
        let cells: Vec<&str> = line.split(',').map(str::trim).collect();
        if cells.len() != 4 {
            return Err(row(format!("{} fields, expected 4", cells.len())));
        }
        let number = |i: usize| -> Result<f64, AnnotationError> {
            cells[i]
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite() && *v >= 0.0)
                .ok_or_else(|| {
                    row(format!(
                        "{}: '{}' is not a non-negative number",
                        expected[i], cells[i]
                    ))
                })
        };
        let press = BallPress {
            image: cells[0].to_string(),
            centre_px: [number(1)?, number(2)?],
            contact_radius_px: number(3)?,
        };
        if press.contact_radius_px <= 0.0 {
            return Err(row("contact_radius_px must be positive".into()));
        }
        if press.image.is_empty() || press.image.contains(['/', '\\']) {
            return Err(row(
                "image must be a file name in the images directory".into()
            ));
        }
        // A press listed twice would count twice in the fit.
        if let Some(first) = first_line.insert(press.image.clone(), k + 1) {
            return Err(row(format!(
                "image {} is annotated already on line {first}",
                press.image
            )));
        }
        out.push(press);
    }
    if out.is_empty() {
        return Err(AnnotationError::Read {
            path: shown,
            message: "no annotated presses".into(),
        });
    }
    Ok(out)
}

/// Which pixels a press contributes and how.
#[derive(Clone, Copy, Debug)]
pub struct SampleRule {
    /// Pixels inside this fraction of the contact radius carry the ball's slope (the
    /// annotated rim is uncertain by a pixel or two).
    pub inside_fraction: f64,
    /// Pixels beyond this many contact radii are taken as flat gel.
    pub flat_beyond: f64,
    /// Every n-th flat pixel along each axis (they are many and alike).
    pub flat_stride: u32,
}

impl Default for SampleRule {
    fn default() -> Self {
        Self {
            inside_fraction: 0.92,
            flat_beyond: 3.0,
            flat_stride: 3,
        }
    }
}

/// Slope of the gel's indentation (dw/dx, dw/dy) at offset (dx, dy) mm from the centre of a
/// ball of radius `r`: the gel takes the sphere's shape, deepest at the centre.
fn ball_slope(dx: f64, dy: f64, r: f64) -> Option<(f64, f64)> {
    let rho2 = dx * dx + dy * dy;
    (rho2 < r * r).then(|| {
        let s = (r * r - rho2).sqrt();
        (-dx / s, -dy / s)
    })
}

/// Calibration samples from one press. Position (u, v) is normalised to [-1, 1].
pub fn samples_from_ball_press(
    image: &RgbImage,
    background: &RgbImage,
    press: &BallPress,
    ball_radius_mm: f64,
    mm_per_px: f64,
    rule: &SampleRule,
) -> Vec<ShadingSample> {
    let (w, h) = image.dimensions();
    let [cx, cy] = press.centre_px;
    let a = press.contact_radius_px;
    let mut out = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let (dx, dy) = (x as f64 - cx, y as f64 - cy);
            let r = dx.hypot(dy);
            let slope = if r < rule.inside_fraction * a {
                ball_slope(dx * mm_per_px, dy * mm_per_px, ball_radius_mm)
            } else if r > rule.flat_beyond * a
                && x % rule.flat_stride == 0
                && y % rule.flat_stride == 0
            {
                Some((0.0, 0.0))
            } else {
                None
            };
            let Some((gx, gy)) = slope else { continue };
            let (p, b) = (image.get_pixel(x, y), background.get_pixel(x, y));
            let (u, v) = frame_position(x, y, w, h);
            out.push(ShadingSample {
                gx: gx as f32,
                gy: gy as f32,
                u,
                v,
                change: std::array::from_fn(|c| p[c] as f32 - b[c] as f32),
            });
        }
    }
    out
}

/// The camera's noise (grey levels, 1 sigma per channel, all channels pooled) from one press
/// frame and the no-contact frame, away from the contact (beyond `rule.flat_beyond` contact
/// radii): neighbouring pixels' differences of the frame-to-background change cancel the
/// smooth shading drift between shots and keep the two frames' independent noise, four times
/// its variance; the odd edge or dust speck (beyond five robust deviations) is left out.
pub fn camera_noise_sigma(
    image: &RgbImage,
    background: &RgbImage,
    press: &BallPress,
    rule: &SampleRule,
) -> Option<f64> {
    let (w, h) = image.dimensions();
    if background.dimensions() != (w, h) || w < 2 {
        return None;
    }
    let [cx, cy] = press.centre_px;
    let far = rule.flat_beyond * press.contact_radius_px;
    let change = |x: u32, y: u32, c: usize| {
        f64::from(image.get_pixel(x, y)[c]) - f64::from(background.get_pixel(x, y)[c])
    };
    let mut steps = Vec::new();
    for y in 0..h {
        for x in 0..w - 1 {
            if (x as f64 - cx).hypot(y as f64 - cy) <= far {
                continue;
            }
            for c in 0..3 {
                steps.push(change(x + 1, y, c) - change(x, y, c));
            }
        }
    }
    if steps.len() < 100 {
        return None;
    }
    // Whole grey levels make the median absolute deviation jump in steps: it only sets the
    // cut for the odd outlier; the spread is the standard deviation of what stays.
    let mid = crate::stats::median(&mut steps.clone())?;
    let mut dev: Vec<f64> = steps.iter().map(|e| (e - mid).abs()).collect();
    let cut = 5.0 * (1.4826 * crate::stats::median(&mut dev)?).max(1.0);
    let kept: Vec<f64> = steps
        .into_iter()
        .filter(|e| (e - mid).abs() <= cut)
        .collect();
    let mean = kept.iter().sum::<f64>() / kept.len() as f64;
    let var = kept.iter().map(|e| (e - mean).powi(2)).sum::<f64>() / (kept.len() - 1) as f64;
    Some(var.sqrt() / 2.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ball_slope_points_inward_and_steepens_to_the_rim() {
        let (gx, gy) = ball_slope(1.0, 0.0, 2.0).unwrap();
        assert!((gx + 1.0 / 3f64.sqrt()).abs() < 1e-12 && gy == 0.0);
        assert!(ball_slope(0.0, 0.0, 2.0).unwrap() == (0.0, 0.0));
        assert!(ball_slope(2.0, 0.1, 2.0).is_none());
    }

    #[test]
    fn camera_noise_is_read_through_a_smooth_drift() {
        use rand::SeedableRng;
        use rand_distr::{Distribution, Normal};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        let sigma = 2.0;
        let noise = Normal::new(0.0, sigma).unwrap();
        let mut frame = |drift: f64| {
            RgbImage::from_fn(160, 120, |x, y| {
                image::Rgb(std::array::from_fn(|c| {
                    let v = 120.0 + 20.0 * c as f64 + drift * (x + y) as f64 / 280.0;
                    (v + noise.sample(&mut rng)).round().clamp(0.0, 255.0) as u8
                }))
            })
        };
        let (bg, img) = (frame(0.0), frame(25.0));
        let press = BallPress {
            image: "p".into(),
            centre_px: [80.0, 60.0],
            contact_radius_px: 10.0,
        };
        let got = camera_noise_sigma(&img, &bg, &press, &SampleRule::default()).unwrap();
        // Rounding to whole grey levels adds 1/12 of a level squared.
        let want = (sigma * sigma + 1.0 / 12.0).sqrt();
        assert!((got - want).abs() < 0.1 * want, "{got} vs {want}");
    }

    #[test]
    fn annotations_errors_name_file_line_and_field() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("a.csv");
        std::fs::write(
            &p,
            "image,center_x_px,center_y_px,contact_radius_px\n0001.png,76,x,38\n",
        )
        .unwrap();
        let e = read_annotations(&p).unwrap_err().to_string();
        assert!(e.contains("a.csv:2") && e.contains("center_y_px"), "{e}");
        // A spreadsheet's byte-order mark is not part of the header.
        std::fs::write(
            &p,
            "\u{feff}image,center_x_px,center_y_px,contact_radius_px\n0001.png,76,182,38\n",
        )
        .unwrap();
        assert_eq!(read_annotations(&p).unwrap().len(), 1);
        std::fs::write(&p, "img,x\n").unwrap();
        assert!(
            read_annotations(&p)
                .unwrap_err()
                .to_string()
                .contains("header")
        );
        std::fs::write(
            &p,
            "image,center_x_px,center_y_px,contact_radius_px\n0001.png,76,182,38\n",
        )
        .unwrap();
        assert_eq!(read_annotations(&p).unwrap()[0].contact_radius_px, 38.0);
    }
}
