//! Annotated ball presses on disk (images directory + annotations CSV), and the fixed split
//! into calibration and evaluation presses: every third press in annotation order (the 3rd,
//! 6th, ...) is held out for evaluation, the others calibrate; and a press rebuilt in the
//! twin (the ball pressed until the solver's contact radius is the annotated one).

use crate::app::load_rgb;
use anyhow::{Result, bail};
use glam::DVec2;
use image::RgbImage;
use std::path::{Path, PathBuf};
use tactex_core::hertz::Elastic;
use tactex_core::tactile::ball_calibration::{AnnotationError, BallPress, read_annotations};
use tactex_core::tactile::spec::GelSpec;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::render::gel::{
    GelImageFields, SensorOptics, image_fields, pad_rect, pixel_centre_mm,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Split {
    /// The presses that are not held out (two of every three).
    Calib,
    /// The held-out presses (every third).
    Eval,
    All,
}

impl Split {
    pub const NAMES: [&'static str; 3] = ["calib", "eval", "all"];

    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    fn keeps(self, index: usize) -> bool {
        let held_out = index % 3 == 2;
        match self {
            Split::Calib => !held_out,
            Split::Eval => held_out,
            Split::All => true,
        }
    }
}

impl std::str::FromStr for Split {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let wanted = s.trim().to_ascii_lowercase();
        [Split::Calib, Split::Eval, Split::All]
            .into_iter()
            .find(|k| k.name() == wanted)
            .ok_or_else(|| format!("unknown split {s:?} (calib, eval or all)"))
    }
}

/// The presses of `split`, each with its image, checked against the frame size.
pub fn load(
    images: &Path,
    annotations: &Path,
    split: Split,
    size: (u32, u32),
) -> Result<Vec<(BallPress, RgbImage)>> {
    super::file_input::present(annotations, "")?;
    if annotations.is_dir() {
        bail!(
            "--annotations {}: is a directory; give the CSV of image,center_x_px,center_y_px,contact_radius_px",
            annotations.display()
        );
    }
    if !images.is_dir() {
        bail!(
            "--images {}: not a directory; give the folder the annotations' images are in",
            images.display()
        );
    }
    let presses = read_annotations(annotations)?;
    let mut out = Vec::new();
    for (k, press) in presses.into_iter().enumerate() {
        if !split.keeps(k) {
            continue;
        }
        let path: PathBuf = images.join(&press.image);
        let img = load_rgb(&path)?;
        if img.dimensions() != size {
            return Err(bad_press(
                &path,
                format!(
                    "{} x {} px, the background is {} x {}",
                    img.width(),
                    img.height(),
                    size.0,
                    size.1
                ),
            )
            .into());
        }
        let [x, y] = press.centre_px;
        if x >= size.0 as f64 || y >= size.1 as f64 {
            return Err(bad_press(
                annotations,
                format!(
                    "press {} is centred outside the {} x {} frame",
                    press.image, size.0, size.1
                ),
            )
            .into());
        }
        out.push((press, img));
    }
    if out.is_empty() {
        return Err(bad_press(annotations, format!("no presses in the {split:?} split")).into());
    }
    Ok(out)
}

/// A listed press that cannot be used as it is, in the file that lists it.
fn bad_press(path: &Path, message: String) -> AnnotationError {
    AnnotationError::Press {
        path: path.display().to_string(),
        message,
    }
}

/// Refuses a press whose annotated contact is as wide as the ball (`ball_radius_mm`), at
/// `mm_per_px`: inside the contact the gel takes the ball's shape, which no contact wider
/// than the ball can. `calibrate` and `compare` apply the one rule.
pub fn check_within_ball(
    presses: &[(BallPress, RgbImage)],
    annotations: &Path,
    mm_per_px: f64,
    ball_radius_mm: f64,
) -> Result<()> {
    for (press, _) in presses {
        let radius_mm = press.contact_radius_px * mm_per_px;
        if radius_mm >= ball_radius_mm {
            return Err(bad_press(
                annotations,
                format!(
                    "{} has a contact radius of {radius_mm:.2} mm, not smaller than the ball's {ball_radius_mm} mm",
                    press.image
                ),
            )
            .into());
        }
    }
    Ok(())
}

/// The box of four contact radii around a press, `[x0, y0, x1, y1)`, clipped to the frame:
/// where sim-to-real scores the contact and where `calibrate` fits the glow.
pub fn contact_box(press: &BallPress, width: u32, height: u32) -> [u32; 4] {
    let reach = 2.0 * press.contact_radius_px;
    let [cx, cy] = press.centre_px;
    let clip = |v: f64, hi: u32| v.round().clamp(0.0, hi as f64) as u32;
    [
        clip(cx - reach, width),
        clip(cy - reach, height),
        clip(cx + reach + 1.0, width),
        clip(cy + reach + 1.0, height),
    ]
}

/// The press rebuilt: the travel at which the solver's contact radius is the annotated one
/// (bisection; contact radius grows monotonically with travel), and its gel fields.
pub fn rebuild(
    solver: &mut ContactSolver,
    press: &BallPress,
    ball_radius_mm: f64,
    gel: &GelSpec,
    optics: &SensorOptics,
    fidelity: Fidelity,
) -> Result<(f64, f64, GelImageFields, Vec<String>)> {
    let centre: DVec2 = pixel_centre_mm(optics, press.centre_px[0], press.centre_px[1]);
    let surface = ObjectSurface::Sphere {
        radius_mm: ball_radius_mm,
        centre_mm: centre,
    };
    let target = press.contact_radius_px * optics.mm_per_px;
    let problem = |approach_mm| ContactProblem {
        surface: &surface,
        // Steel: rigid next to the gel.
        object: Elastic {
            modulus_mpa: None,
            poisson: 0.3,
        },
        gel: *gel,
        pad: pad_rect(optics),
        approach_mm,
        cell_mm: None,
    };
    let (mut lo, mut hi) = (0.0, 0.95 * ball_radius_mm);
    let radius_at = |solver: &mut ContactSolver, d: f64| -> Result<f64> {
        Ok(solver.solve(&problem(d), fidelity)?.contact_radius_mm)
    };
    // Hand-marked circles can be wider than any contact the ball can make (up to a = R):
    // such presses are taken at the deepest travel modelled, and say so.
    let mut warnings = Vec::new();
    let deepest = radius_at(solver, hi)?;
    if deepest < target {
        warnings.push(format!(
            "annotated contact radius {target:.2} mm is beyond the {deepest:.2} mm the model reaches at {hi:.2} mm travel; pressed to that travel"
        ));
        lo = hi;
    }
    for _ in 0..30 {
        let mid = 0.5 * (lo + hi);
        if radius_at(solver, mid)? < target {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo < 1e-4 * ball_radius_mm {
            break;
        }
    }
    let depth = 0.5 * (lo + hi);
    let solution = solver.solve(&problem(depth), fidelity)?;
    let fields = image_fields(solver, &solution, gel, optics);
    Ok((depth, solution.force_n, fields, warnings))
}
