//! Closing (dilation, then erosion) by a disk or a square, the same operations as imageproc's
//! `grayscale_erode(&grayscale_dilate(img, &Mask::disk(r)), &Mask::disk(r))` and
//! `close(img, Norm::LInf, k)` pixel for pixel, in O(r) work per pixel instead of O(r^2) or a
//! distance transform: the marker detector runs them on every frame of every contact search,
//! where the direct forms were the press stage's largest cost.
//!
//! Both shapes are stacks of centred rows; the reduction over row `dy` is a horizontal window
//! of half-width `hw(dy)`. Horizontal windows of every half-width are built one from the last
//! (`h[k+1](x) = h[k](x-1) ∘ h[k](x) ∘ h[k](x+1)`), then each output pixel reduces 2r + 1
//! of them. Pixels outside the image take no part, as in imageproc.

use image::GrayImage;

/// Half-widths of the disk's rows, `dy` from -r to r: the largest `x` with x² + dy² <= r²
/// (imageproc's `Mask::disk`).
fn half_widths(radius: u8) -> Vec<usize> {
    let r = i32::from(radius);
    (-r..=r)
        .map(|dy| {
            let mut x = 0;
            while (x + 1) * (x + 1) + dy * dy <= r * r {
                x += 1;
            }
            x as usize
        })
        .collect()
}

/// `reduce` (max or min) of `img` over the centred rows of half-widths `widths` (one per
/// `dy`, from -(n-1)/2 down) round each pixel.
fn reduce_rows(
    img: &GrayImage,
    widths: &[usize],
    reduce: impl Fn(u8, u8) -> u8 + Copy,
) -> GrayImage {
    let (w, h) = (img.width() as usize, img.height() as usize);
    if w == 0 || h == 0 {
        return img.clone();
    }
    let above = widths.len() / 2;
    let widest = widths.iter().copied().max().unwrap_or(0);
    // rows[k]: every pixel reduced over a horizontal window of half-width k.
    let mut rows: Vec<Vec<u8>> = Vec::with_capacity(widest + 1);
    rows.push(img.as_raw().clone());
    for k in 0..widest {
        let last = &rows[k];
        let mut next = last.clone();
        for (row, out) in last.chunks_exact(w).zip(next.chunks_exact_mut(w)) {
            if w > 1 {
                out[0] = reduce(row[0], row[1]);
                out[w - 1] = reduce(row[w - 2], row[w - 1]);
            }
            for (o, t) in out[1..].iter_mut().zip(row.windows(3)) {
                *o = reduce(reduce(t[0], t[1]), t[2]);
            }
        }
        rows.push(next);
    }
    let mut out = vec![0u8; w * h];
    for y in 0..h {
        let line = &mut out[y * w..(y + 1) * w];
        let mut first = true;
        for (i, &hw) in widths.iter().enumerate() {
            let sy = y as isize + i as isize - above as isize;
            if sy < 0 || sy >= h as isize {
                continue;
            }
            let src = &rows[hw][sy as usize * w..(sy as usize + 1) * w];
            if first {
                line.copy_from_slice(src);
                first = false;
            } else {
                for (o, &s) in line.iter_mut().zip(src) {
                    *o = reduce(*o, s);
                }
            }
        }
    }
    GrayImage::from_raw(w as u32, h as u32, out).expect("buffer of the image's size")
}

/// Grey-level closing of `img` by a disk of `radius` px.
pub(super) fn close_with_disk(img: &GrayImage, radius: u8) -> GrayImage {
    let widths = half_widths(radius);
    reduce_rows(&reduce_rows(img, &widths, u8::max), &widths, u8::min)
}

/// Closing of a binary image (0 or 255) by the (2k + 1)-pixel square: fills gaps narrower
/// than the square.
pub(super) fn close_binary_with_square(img: &GrayImage, k: u8) -> GrayImage {
    let widths = vec![usize::from(k); 2 * usize::from(k) + 1];
    reduce_rows(&reduce_rows(img, &widths, u8::max), &widths, u8::min)
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Luma;
    use imageproc::distance_transform::Norm;
    use imageproc::morphology::{Mask, close, dilate, grayscale_dilate, grayscale_erode};
    use proptest::prelude::*;

    fn reference(img: &GrayImage, radius: u8) -> GrayImage {
        let disk = Mask::disk(radius);
        grayscale_erode(&grayscale_dilate(img, &disk), &disk)
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(48))]
        #[test]
        fn closing_matches_imageprocs_disk_mask_pixel_for_pixel(
            w in 1u32..40, h in 1u32..40, radius in 0u8..10, seed in any::<u64>(),
        ) {
            // Dark dots on a ramp: the structure the marker detector closes.
            let mut s = seed | 1;
            let img = GrayImage::from_fn(w, h, |x, y| {
                s ^= s << 13; s ^= s >> 7; s ^= s << 17;
                let ramp = (x * 3 + y * 2) as u8;
                Luma([if s % 7 == 0 { (s >> 8) as u8 % 40 } else { ramp.wrapping_add(150) }])
            });
            let closed = close_with_disk(&img, radius);
            let want = reference(&img, radius);
            prop_assert_eq!(closed.as_raw(), want.as_raw());
            // A closing only fills dark holes: it never darkens a pixel.
            prop_assert!(img.pixels().zip(closed.pixels()).all(|(a, b)| b[0] >= a[0]));
        }

        #[test]
        fn binary_closing_matches_imageprocs_linf_closing(
            w in 1u32..40, h in 1u32..40, k in 0u8..5, seed in any::<u64>(),
        ) {
            let mut s = seed | 1;
            let img = GrayImage::from_fn(w, h, |_, _| {
                s ^= s << 13; s ^= s >> 7; s ^= s << 17;
                Luma([if s % 3 == 0 { 0 } else { 255 }])
            });
            // imageproc erodes an image with no background left at all to nothing; a closing
            // leaves it whole. Marker frames always have background.
            prop_assume!(dilate(&img, Norm::LInf, k).pixels().any(|p| p[0] == 0));
            let (got, want) = (close_binary_with_square(&img, k), close(&img, Norm::LInf, k));
            prop_assert_eq!(got.as_raw(), want.as_raw());
        }
    }
}
