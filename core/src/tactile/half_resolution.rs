//! A frame at half its resolution and back: the reading's first pass (where the imprint is,
//! and the indentation the glow's other terms need) is smooth at that scale, so it is read
//! on a quarter of the pixels and brought back to the frame by bilinear interpolation.

/// A `width` x `height` frame's half: each coarse pixel is the mean of a 2 x 2 block (an odd
/// last row or column is left out of the means and interpolated back).
#[derive(Clone, Copy, Debug)]
pub struct HalfResolution {
    pub width: usize,
    pub height: usize,
}

impl HalfResolution {
    /// The half of a frame, or None where either side would be under 8 pixels.
    pub fn of(width: usize, height: usize) -> Option<Self> {
        (width >= 16 && height >= 16).then_some(Self { width, height })
    }

    pub fn coarse_width(&self) -> usize {
        self.width / 2
    }

    pub fn coarse_height(&self) -> usize {
        self.height / 2
    }

    /// Each 2 x 2 block's mean.
    pub fn down<const N: usize>(&self, fine: &[[f32; N]]) -> Vec<[f32; N]> {
        let (w, cw, ch) = (self.width, self.coarse_width(), self.coarse_height());
        (0..cw * ch)
            .map(|i| {
                let (x, y) = (2 * (i % cw), 2 * (i / cw));
                let at = |xx: usize, yy: usize| fine[yy * w + xx];
                let block = [at(x, y), at(x + 1, y), at(x, y + 1), at(x + 1, y + 1)];
                std::array::from_fn(|c| 0.25 * block.iter().map(|p| p[c]).sum::<f32>())
            })
            .collect()
    }

    /// A block is valid where all four of its pixels are.
    pub fn down_valid(&self, valid: &[bool]) -> Vec<bool> {
        let (w, cw, ch) = (self.width, self.coarse_width(), self.coarse_height());
        (0..cw * ch)
            .map(|i| {
                let (x, y) = (2 * (i % cw), 2 * (i / cw));
                valid[y * w + x]
                    && valid[y * w + x + 1]
                    && valid[(y + 1) * w + x]
                    && valid[(y + 1) * w + x + 1]
            })
            .collect()
    }

    /// A coarse map brought back to every pixel of the frame, bilinearly between the blocks'
    /// centres (held at the edges).
    pub fn up<T: Copy + Into<f64>>(&self, coarse: &[T]) -> Vec<f64> {
        let (cw, ch) = (self.coarse_width(), self.coarse_height());
        let axis = |fine: usize, n: usize| {
            // A fine pixel's centre in coarse pixel units, less the block centre's half.
            let t = ((fine as f64 + 0.5) / 2.0 - 0.5).clamp(0.0, (n - 1) as f64);
            let i0 = (t as usize).min(n.saturating_sub(2));
            (i0, (i0 + 1).min(n - 1), t - i0 as f64)
        };
        let columns: Vec<_> = (0..self.width).map(|x| axis(x, cw)).collect();
        let mut out = Vec::with_capacity(self.width * self.height);
        for y in 0..self.height {
            let (y0, y1, ty) = axis(y, ch);
            for &(x0, x1, tx) in &columns {
                let at = |xx: usize, yy: usize| -> f64 { coarse[yy * cw + xx].into() };
                let top = at(x0, y0) * (1.0 - tx) + at(x1, y0) * tx;
                let bottom = at(x0, y1) * (1.0 - tx) + at(x1, y1) * tx;
                out.push(top * (1.0 - ty) + bottom * ty);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_ramp_comes_back_exactly_away_from_the_edges() {
        // Block means of a plane are the plane at the blocks' centres, and bilinear
        // interpolation between them reproduces it.
        let (w, h) = (20usize, 16usize);
        let half = HalfResolution::of(w, h).expect("large enough");
        let plane = |x: f64, y: f64| 0.3 * x - 0.7 * y + 2.0;
        let fine: Vec<[f32; 1]> = (0..w * h)
            .map(|i| [plane((i % w) as f64, (i / w) as f64) as f32])
            .collect();
        let coarse: Vec<f32> = half.down(&fine).into_iter().map(|[v]| v).collect();
        let back = half.up(&coarse);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let want = plane(x as f64, y as f64);
                assert!((back[y * w + x] - want).abs() < 1e-4, "({x}, {y})");
            }
        }
        assert!(HalfResolution::of(15, 40).is_none());
    }

    #[test]
    fn a_block_with_one_invalid_pixel_is_invalid() {
        let half = HalfResolution::of(16, 16).expect("large enough");
        let mut valid = vec![true; 256];
        valid[17] = false;
        let coarse = half.down_valid(&valid);
        assert!(!coarse[0]);
        assert_eq!(coarse.iter().filter(|v| !**v).count(), 1);
    }
}
