//! The paper's mask refinement: Canny edges of the mask, dilated 3x3 twice, removed, so that
//! only the object's inner region (away from flying pixels and background bleed) remains.

use image::{GrayImage, Luma};
use imageproc::distance_transform::Norm;

/// The box of a mask's set pixels, [x_min, y_min, x_max, y_max] (inclusive), and their
/// count; None for an empty mask.
pub fn mask_box(mask: &GrayImage) -> Option<([u32; 4], u32)> {
    let mut b = [u32::MAX, u32::MAX, 0, 0];
    let mut n = 0;
    for (x, y, p) in mask.enumerate_pixels() {
        if p[0] > 0 {
            b = [b[0].min(x), b[1].min(y), b[2].max(x), b[3].max(y)];
            n += 1;
        }
    }
    (n > 0).then_some((b, n))
}

/// Binary mask (255 inside) -> inner mask.
pub fn refine_mask(mask: &GrayImage) -> GrayImage {
    let edges = imageproc::edges::canny(mask, 50.0, 100.0);
    let band = imageproc::morphology::dilate(
        &imageproc::morphology::dilate(&edges, Norm::LInf, 1),
        Norm::LInf,
        1,
    );
    let mut inner = mask.clone();
    for (p, b) in inner.pixels_mut().zip(band.pixels()) {
        if b[0] > 0 {
            *p = Luma([0]);
        }
    }
    inner
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mask_box_spans_the_set_pixels_inclusively() {
        let mut m = GrayImage::new(10, 8);
        assert_eq!(mask_box(&m), None);
        m.put_pixel(2, 5, Luma([255]));
        m.put_pixel(7, 1, Luma([1]));
        assert_eq!(mask_box(&m), Some(([2, 1, 7, 5], 2)));
    }

    #[test]
    fn refinement_shrinks_a_disc_by_its_edge_band() {
        let mut mask = GrayImage::new(80, 80);
        for (x, y, p) in mask.enumerate_pixels_mut() {
            if (x as f64 - 40.0).hypot(y as f64 - 40.0) <= 20.0 {
                *p = Luma([255]);
            }
        }
        let inner = refine_mask(&mask);
        let count = |m: &GrayImage| m.pixels().filter(|p| p[0] > 0).count();
        assert!(count(&inner) < count(&mask));
        // The band is a few pixels wide: the inner region stays a disc of radius ~16-18.
        let r_inner = (count(&inner) as f64 / std::f64::consts::PI).sqrt();
        assert!((15.0..19.5).contains(&r_inner), "inner radius {r_inner}");
        assert_eq!(inner.get_pixel(40, 40)[0], 255);
        assert_eq!(inner.get_pixel(40, 21)[0], 0);
    }
}
