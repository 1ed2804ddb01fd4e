//! From a detection's mask to where the arm should go: the paper's centroid (median of the
//! back-projected points of the refined inner mask over the depth median), the object's
//! centre, and the touch point on its crest.

use crate::frames::DepthImage;
use crate::geometry::{CameraIntrinsics, Pose};
use crate::perception::centroid::{back_project_mask, median_point};
use crate::perception::mask::refine_mask;
use glam::DVec3;
use image::GrayImage;

/// Where a detected object is, in the world frame (m).
#[derive(Clone, Debug)]
pub struct Located {
    /// The paper's centroid: median of the mask's back-projected surface points.
    pub surface: DVec3,
    /// x, y of the centroid; z half the top height (the object rests on the table).
    pub centre: DVec3,
    /// Where the gel presses: the crest near the centroid (the median of the highest tenth of
    /// the mask points within 15 mm of it).
    pub touch: DVec3,
    /// The mask used: the inner mask, or the full one where the inner had too few points.
    pub mask: GrayImage,
}

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
    // A curved fruit's centroid can fall beside it: press the crest near the centroid. The
    // single highest point is the depth noise's largest draw and can lie a centimetre from
    // the crest; the median of the highest tenth lies on it.
    let near = |p: &&DVec3| p.truncate().distance(surface.truncate());
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
        centre: DVec3::new(surface.x, surface.y, top / 2.0),
        touch,
        mask: used,
    })
}
