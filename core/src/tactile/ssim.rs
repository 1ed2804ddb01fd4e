//! Structural similarity as scikit-image computes it by default (`structural_similarity` with
//! a 7x7 uniform window, sample covariance, K1 = 0.01, K2 = 0.03), on grey levels from
//! skimage's `rgb2gray` weights with a data range of 255, averaged over the interior where the
//! window fits (skimage crops (7 - 1) / 2 pixels from each side).

use image::RgbImage;

const WIN: usize = 7;

pub fn gray(img: &RgbImage) -> Vec<f64> {
    img.pixels()
        .map(|p| 0.2125 * p[0] as f64 + 0.7154 * p[1] as f64 + 0.0721 * p[2] as f64)
        .collect()
}

/// Mean SSIM of two equally sized colour images (on grey levels). None if sizes differ or the
/// image is smaller than the window.
pub fn ssim_rgb(a: &RgbImage, b: &RgbImage) -> Option<f64> {
    if a.dimensions() != b.dimensions() {
        return None;
    }
    ssim(
        &gray(a),
        &gray(b),
        a.width() as usize,
        a.height() as usize,
        255.0,
    )
}

pub fn ssim(a: &[f64], b: &[f64], w: usize, h: usize, data_range: f64) -> Option<f64> {
    let map = ssim_map(a, b, w, h, data_range)?;
    Some(map.iter().sum::<f64>() / map.len() as f64)
}

/// Local SSIM of each 7x7 window (row-major, (w - 6) x (h - 6)): the map skimage averages.
pub fn ssim_map(a: &[f64], b: &[f64], w: usize, h: usize, data_range: f64) -> Option<Vec<f64>> {
    if w < WIN || h < WIN || a.len() != w * h || b.len() != w * h {
        return None;
    }
    // Integral images of x, y, x^2, y^2, xy.
    let stride = w + 1;
    let mut sums = vec![[0.0f64; 5]; stride * (h + 1)];
    for y in 0..h {
        for x in 0..w {
            let (p, q) = (a[y * w + x], b[y * w + x]);
            let v = [p, q, p * p, q * q, p * q];
            for k in 0..5 {
                sums[(y + 1) * stride + x + 1][k] =
                    v[k] + sums[y * stride + x + 1][k] + sums[(y + 1) * stride + x][k]
                        - sums[y * stride + x][k];
            }
        }
    }
    let n = (WIN * WIN) as f64;
    let cov_norm = n / (n - 1.0);
    let c1 = (0.01 * data_range).powi(2);
    let c2 = (0.03 * data_range).powi(2);
    let mut map = Vec::with_capacity((w - WIN + 1) * (h - WIN + 1));
    for y0 in 0..=h - WIN {
        for x0 in 0..=w - WIN {
            let (y1, x1) = (y0 + WIN, x0 + WIN);
            let s: [f64; 5] = std::array::from_fn(|k| {
                sums[y1 * stride + x1][k] - sums[y0 * stride + x1][k] - sums[y1 * stride + x0][k]
                    + sums[y0 * stride + x0][k]
            });
            let (ux, uy) = (s[0] / n, s[1] / n);
            let vx = cov_norm * (s[2] / n - ux * ux);
            let vy = cov_norm * (s[3] / n - uy * uy);
            let vxy = cov_norm * (s[4] / n - ux * uy);
            map.push(
                ((2.0 * ux * uy + c1) * (2.0 * vxy + c2))
                    / ((ux * ux + uy * uy + c1) * (vx + vy + c2)),
            );
        }
    }
    Some(map)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_images_score_one() {
        let a: Vec<f64> = (0..400).map(|i| ((i * 37) % 255) as f64).collect();
        assert!((ssim(&a, &a, 20, 20, 255.0).unwrap() - 1.0).abs() < 1e-12);
    }

    #[test]
    fn matches_scikit_image_reference_values() {
        // skimage.metrics.structural_similarity(a, b, data_range=255), scikit-image 0.24.0:
        // a = np.arange(100).reshape(10, 10) * 2.0, b = a.T -> 0.20338005833552134
        let a: Vec<f64> = (0..100).map(|i| i as f64 * 2.0).collect();
        let b: Vec<f64> = (0..100)
            .map(|i| ((i % 10) * 10 + i / 10) as f64 * 2.0)
            .collect();
        assert!((ssim(&a, &b, 10, 10, 255.0).unwrap() - 0.20338005833552134).abs() < 1e-12);
        // i, j = np.mgrid[0:12, 0:15]; a = (i*7 + j*13) % 251; b = (i*i*3 + j*5) % 239
        // -> 0.2680080611613147; c = a + (i*j) % 5 -> 0.9987080820050751
        let grid = |f: &dyn Fn(usize, usize) -> f64| -> Vec<f64> {
            (0..12)
                .flat_map(|i| (0..15).map(move |j| (i, j)))
                .map(|(i, j)| f(i, j))
                .collect()
        };
        let a = grid(&|i, j| ((i * 7 + j * 13) % 251) as f64);
        let b = grid(&|i, j| ((i * i * 3 + j * 5) % 239) as f64);
        let c = grid(&|i, j| ((i * 7 + j * 13) % 251 + (i * j) % 5) as f64);
        assert!((ssim(&a, &b, 15, 12, 255.0).unwrap() - 0.2680080611613147).abs() < 1e-12);
        assert!((ssim(&a, &c, 15, 12, 255.0).unwrap() - 0.9987080820050751).abs() < 1e-12);
    }
}
