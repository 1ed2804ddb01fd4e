//! From a detection's mask to where the arm should go: the paper's centroid (median of the
//! back-projected points of the refined inner mask over the depth median), the object's
//! centre, and the touch point on its crest.

use crate::frames::DepthImage;
use crate::geometry::{CameraIntrinsics, Pose};
use crate::ground::centroid::{back_project_mask, median_point};
use crate::ground::mask::refine_mask;
use glam::DVec3;
use image::GrayImage;

/// Where a detected object is, in the world frame (m).
#[derive(Clone, Debug)]
pub struct Located {
    /// The paper's centroid: median of the mask's back-projected surface points.
    pub surface: DVec3,
    /// x, y: the mean of the points near the object's top; z half the top height (the object
    /// rests on the table).
    pub centre: DVec3,
    /// Where the gel presses: the crest nearest the centre (the median of the highest tenth
    /// of the mask points within 15 mm of the top band's point nearest the centre).
    pub touch: DVec3,
    /// The mask used: the inner mask, or the full one where the inner had too few points.
    pub mask: GrayImage,
}

/// The least depth of the top band the centre is taken from: about twice the depth median's
/// noise at the camera's distance.
const TOP_BAND_MIN_M: f64 = 0.004;

/// Locates an object from its mask. With `refine` the mask's edge band is removed first
/// (Canny edges dilated 3x3 twice), as in the paper.
pub fn locate(
    mask: &GrayImage,
    refine: bool,
    depth: &DepthImage,
    k: &CameraIntrinsics,
    pose: &Pose,
) -> Option<Located> {
    let mut used = if refine {
        refine_mask(mask)
    } else {
        mask.clone()
    };
    let mut points = back_project_mask(&used, depth, k, pose);
    if points.len() < 20 && refine {
        used = mask.clone();
        points = back_project_mask(&used, depth, k, pose);
    }
    let surface = median_point(&points)?;
    let mut heights: Vec<f64> = points.iter().map(|p| p.z).collect();
    heights.sort_by(f64::total_cmp);
    let top = heights[((heights.len() - 1) as f64 * 0.98).round() as usize];
    // A camera off to one side sees the near flank and not the far one, so the surface
    // centroid leans towards it by up to a centimetre. A resting fruit's top band is centred
    // over its outline (and over a curved banana's, as a band along its ridge is).
    let band = (0.15 * top).max(TOP_BAND_MIN_M);
    let crown: Vec<DVec3> = points
        .iter()
        .filter(|p| p.z >= top - band)
        .copied()
        .collect();
    let n = crown.len().max(1) as f64;
    let (cx, cy) = crown
        .iter()
        .fold((0.0, 0.0), |(x, y), p| (x + p.x / n, y + p.y / n));
    let (cx, cy) = if crown.is_empty() {
        (surface.x, surface.y)
    } else {
        (cx, cy)
    };
    // Press the crest nearest the centre: a curved banana's centre lies off its ridge, its
    // crown point nearest the centre on it. The single highest point near there is the depth
    // noise's largest draw and can lie a centimetre off; the median of the highest tenth
    // within 15 mm lies on the crest.
    let to_centre = |p: &DVec3| (p.x - cx).hypot(p.y - cy);
    let anchor = crown
        .iter()
        .min_by(|a, b| to_centre(a).total_cmp(&to_centre(b)))
        .copied()
        .unwrap_or(surface);
    let near = |p: &&DVec3| p.truncate().distance(anchor.truncate());
    let mut close: Vec<DVec3> = points
        .iter()
        .filter(|p| near(p) <= 0.015)
        .copied()
        .collect();
    if close.is_empty() {
        close.push(*points.iter().min_by(|a, b| near(a).total_cmp(&near(b)))?);
    }
    close.sort_by(|a, b| b.z.total_cmp(&a.z));
    close.truncate(close.len().div_ceil(10));
    let touch = median_point(&close)?;
    Some(Located {
        surface,
        centre: DVec3::new(cx, cy, top / 2.0),
        touch,
        mask: used,
    })
}
