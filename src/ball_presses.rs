//! Annotated ball presses on disk (images directory + annotations CSV), and the fixed split
//! into calibration and evaluation presses: every third press in annotation order (the 3rd,
//! 6th, ...) is held out for evaluation, the others calibrate.

use anyhow::{Context, Result, bail};
use clap::ValueEnum;
use image::RgbImage;
use std::path::{Path, PathBuf};
use tactex_core::ball_calibration::{BallPress, read_annotations};

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Split {
    /// The presses that are not held out (two of every three).
    Calib,
    /// The held-out presses (every third).
    Eval,
    All,
}

impl Split {
    fn keeps(self, index: usize) -> bool {
        let held_out = index % 3 == 2;
        match self {
            Split::Calib => !held_out,
            Split::Eval => held_out,
            Split::All => true,
        }
    }
}

pub fn load_rgb(path: &Path) -> Result<RgbImage> {
    Ok(image::open(path)
        .with_context(|| format!("{}: cannot read the image", path.display()))?
        .to_rgb8())
}

/// The presses of `split`, each with its image, checked against the frame size.
pub fn load(
    images: &Path,
    annotations: &Path,
    split: Split,
    size: (u32, u32),
) -> Result<Vec<(BallPress, RgbImage)>> {
    let presses = read_annotations(annotations)?;
    let mut out = Vec::new();
    for (k, press) in presses.into_iter().enumerate() {
        if !split.keeps(k) {
            continue;
        }
        let path: PathBuf = images.join(&press.image);
        let img = load_rgb(&path)?;
        if img.dimensions() != size {
            bail!(
                "{}: {} x {} px, the background is {} x {}",
                path.display(),
                img.width(),
                img.height(),
                size.0,
                size.1
            );
        }
        let [x, y] = press.centre_px;
        if x >= size.0 as f64 || y >= size.1 as f64 {
            bail!(
                "{}: press {} is centred outside the {} x {} frame",
                annotations.display(),
                press.image,
                size.0,
                size.1
            );
        }
        out.push((press, img));
    }
    if out.is_empty() {
        bail!(
            "{}: no presses in the {split:?} split",
            annotations.display()
        );
    }
    Ok(out)
}
