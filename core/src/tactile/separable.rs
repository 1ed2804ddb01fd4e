//! Separable blurs of multi-channel f32 images held as rows of `[f32; N]`: rows first, then
//! columns, each edge extended, every output summed over its taps in one fixed order from
//! zero. The glow's blurs and the contact outline's smoothing share it; the order is what
//! makes the CPU's sums the same bits as the shaders' and as imageproc's `gaussian_blur_f32`.

/// `src` (`width` x `height`, row-major) convolved with `k` (odd length, centred) along
/// rows and then columns, the frame's edge pixels extended past it.
pub fn separable_blur<const N: usize>(
    src: &[[f32; N]],
    width: usize,
    height: usize,
    k: &[f32],
) -> Vec<[f32; N]> {
    let r = k.len() / 2;
    let mut rows = vec![[0.0f32; N]; src.len()];
    let mut padded = vec![[0.0f32; N]; width + 2 * r];
    for (row_in, row_out) in src.chunks_exact(width).zip(rows.chunks_exact_mut(width)) {
        padded[..r].fill(row_in[0]);
        padded[r..r + width].copy_from_slice(row_in);
        padded[r + width..].fill(row_in[width - 1]);
        let taps: Vec<&[f32]> = (0..k.len())
            .map(|i| padded[i..i + width].as_flattened())
            .collect();
        weighted_sum(row_out.as_flattened_mut(), &taps, k);
    }
    let mut out = vec![[0.0f32; N]; src.len()];
    let mut taps: Vec<&[f32]> = Vec::with_capacity(k.len());
    for (y, row_out) in out.chunks_exact_mut(width).enumerate() {
        taps.clear();
        taps.extend((0..k.len()).map(|i| {
            let yy = (y + i).saturating_sub(r).min(height - 1);
            rows[yy * width..][..width].as_flattened()
        }));
        weighted_sum(row_out.as_flattened_mut(), &taps, k);
    }
    out
}

/// imageproc's Gaussian taps (`gaussian_blur_f32`): radius ceil(2 sigma), each the normal
/// density at its offset, normalised by their sum, so `separable_blur` with them gives
/// imageproc's blur to the bit.
pub fn imageproc_gaussian_taps(sigma_px: f32) -> Vec<f32> {
    let radius = (2.0 * sigma_px).ceil() as usize;
    let density = |x: f32| {
        ((2.0 * std::f32::consts::PI).sqrt() * sigma_px).recip()
            * (-x.powi(2) / (2.0 * sigma_px.powi(2))).exp()
    };
    let mut taps = vec![0.0f32; 2 * radius + 1];
    for i in 0..=radius {
        taps[radius + i] = density(i as f32);
        taps[radius - i] = density(i as f32);
    }
    let sum: f32 = taps.iter().sum();
    taps.iter_mut().for_each(|t| *t /= sum);
    taps
}

/// `out[j] = k[0] taps[0][j] + k[1] taps[1][j] + ...`, summed in that order from zero (so
/// every renderer's sum of a sample's taps from -r to r gives the same bits), a block of
/// outputs at a time with its sums held in registers across the taps.
fn weighted_sum(out: &mut [f32], taps: &[&[f32]], k: &[f32]) {
    const BLOCK: usize = 32;
    let n = out.len();
    let whole = n - n % BLOCK;
    for start in (0..whole).step_by(BLOCK) {
        let mut sum = [0.0f32; BLOCK];
        for (tap, w) in taps.iter().zip(k) {
            for (s, v) in sum.iter_mut().zip(&tap[start..start + BLOCK]) {
                *s += w * v;
            }
        }
        out[start..start + BLOCK].copy_from_slice(&sum);
    }
    for (j, o) in out.iter_mut().enumerate().skip(whole) {
        let mut sum = 0.0f32;
        for (tap, w) in taps.iter().zip(k) {
            sum += w * tap[j];
        }
        *o = sum;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::{ImageBuffer, Luma, Rgb};

    /// The outline's smoothing moved off imageproc must not move a single outline: every
    /// output bit equal, across odd sizes, edges and frames narrower than the kernel.
    #[test]
    fn imageproc_gaussian_blur_to_the_bit() {
        for (w, h, sigma) in [
            (37usize, 23usize, 1.5f32),
            (5, 4, 1.5),
            (64, 9, 8.0),
            (3, 40, 0.7),
        ] {
            let value = |x: usize, y: usize, c: usize| {
                (((x * 7919 + y * 104_729 + c * 31) % 1009) as f32 - 504.0) * 0.37
            };
            let src: Vec<[f32; 3]> = (0..w * h)
                .map(|i| std::array::from_fn(|c| value(i % w, i / w, c)))
                .collect();
            let ours = separable_blur(&src, w, h, &imageproc_gaussian_taps(sigma));
            let rgb: ImageBuffer<Rgb<f32>, Vec<f32>> =
                ImageBuffer::from_fn(w as u32, h as u32, |x, y| {
                    Rgb(src[y as usize * w + x as usize])
                });
            let theirs = imageproc::filter::gaussian_blur_f32(&rgb, sigma);
            for (i, o) in ours.iter().enumerate() {
                let t = theirs.get_pixel((i % w) as u32, (i / w) as u32).0;
                assert_eq!(
                    o.map(f32::to_bits),
                    t.map(f32::to_bits),
                    "{w}x{h} sigma {sigma} px {i}"
                );
            }
            let one: Vec<[f32; 1]> = src.iter().map(|p| [p[0]]).collect();
            let grey: ImageBuffer<Luma<f32>, Vec<f32>> =
                ImageBuffer::from_fn(w as u32, h as u32, |x, y| {
                    Luma(one[y as usize * w + x as usize])
                });
            let theirs = imageproc::filter::gaussian_blur_f32(&grey, sigma);
            let ours = separable_blur(&one, w, h, &imageproc_gaussian_taps(sigma));
            for (o, t) in ours.iter().zip(theirs.pixels()) {
                assert_eq!(o[0].to_bits(), t[0].to_bits());
            }
        }
    }
}
