//! Per-pixel depth median over frames and the 3D centroid of a mask: the median of the
//! mask's back-projected points (camera intrinsics + extrinsics), as in the TactEx paper.

use crate::frames::DepthImage;
use crate::geometry::{CameraIntrinsics, Pose};
use glam::DVec3;
use image::GrayImage;

/// Per-pixel median of the valid (non-zero) depths; 0 where no frame has one.
pub fn median_depth(frames: &[&DepthImage]) -> Option<DepthImage> {
    let first = frames.first()?;
    let (w, h) = first.dimensions();
    if frames.iter().any(|f| f.dimensions() != (w, h)) {
        return None;
    }
    let mut out = DepthImage::new(w, h);
    let mut samples = Vec::with_capacity(frames.len());
    for (i, px) in out.iter_mut().enumerate() {
        samples.clear();
        samples.extend(
            frames
                .iter()
                .map(|f| f.as_raw()[i])
                .filter(|d| *d > 0.0 && d.is_finite()),
        );
        if !samples.is_empty() {
            *px = median_f32(&mut samples);
        }
    }
    Some(out)
}

fn median_f32(v: &mut [f32]) -> f32 {
    v.sort_by(f32::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// World points of the mask's pixels with valid depth.
pub fn back_project_mask(
    mask: &GrayImage,
    depth: &DepthImage,
    k: &CameraIntrinsics,
    camera: &Pose,
) -> Vec<DVec3> {
    mask.enumerate_pixels()
        .filter(|(_, _, m)| m[0] > 0)
        .filter_map(|(u, v, _)| {
            let z = depth.get_pixel(u, v)[0] as f64;
            (z > 0.0 && z.is_finite())
                .then(|| camera.transform_point(k.back_project(u as f64, v as f64, z)))
        })
        .collect()
}

/// Component-wise median of points.
pub fn median_point(points: &[DVec3]) -> Option<DVec3> {
    let axis =
        |f: fn(&DVec3) -> f64| crate::stats::median(&mut points.iter().map(f).collect::<Vec<_>>());
    Some(DVec3::new(axis(|p| p.x)?, axis(|p| p.y)?, axis(|p| p.z)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Luma;

    #[test]
    fn median_depth_ignores_invalid_pixels_and_outliers() {
        let mk = |v: f32| DepthImage::from_pixel(2, 1, Luma([v]));
        let frames = [mk(0.5), mk(0.0), mk(0.52), mk(9.0), mk(0.51)];
        let refs: Vec<_> = frames.iter().collect();
        let m = median_depth(&refs).unwrap();
        assert!((m.get_pixel(0, 0)[0] - 0.515).abs() < 1e-6);
    }

    #[test]
    fn centroid_of_a_flat_patch_below_the_camera() {
        let k = CameraIntrinsics::default();
        let cam = Pose::camera_looking_at(DVec3::new(0.0, 0.0, 0.7), DVec3::ZERO).unwrap();
        let mut mask = GrayImage::new(k.width, k.height);
        let depth = DepthImage::from_pixel(k.width, k.height, Luma([0.6]));
        for v in 200..230 {
            for u in 300..320 {
                mask.put_pixel(u, v, Luma([255]));
            }
        }
        let c = median_point(&back_project_mask(&mask, &depth, &k, &cam)).unwrap();
        // Pixel (309.5, 214.5) back-projects to about (0.0001, -0.0007) at 0.1 m above the table.
        assert!((c.z - 0.1).abs() < 1e-6, "f32 depth");
        assert!(c.x.abs() < 2e-3 && c.y.abs() < 2e-3, "{c}");
    }
}
