//! Telling touching objects apart in a depth blob: a watershed on height with persistence.
//!
//! Two fruits that touch form one connected region above the table, but seen from above each
//! is a hill and the crevice between them is a saddle well below both tops. Flooding from the
//! highest point down, every new local top starts a basin; where two basins meet, the lower
//! one survives as its own object if its top stands at least `prominence_m` above the
//! meeting point. Depth noise makes small false tops on one fruit; they meet their fruit's
//! main basin within a few millimetres and merge. A small fruit leaning under a large one's
//! flank stands only millimetres above the saddle as the camera sees it; it stays apart when
//! both basins are large enough to have a colour and their chromaticities or brightnesses
//! differ (a red strawberry under a dark avocado, a yellow banana lying across an olive one),
//! as two parts of one fruit's surface do not.

/// One pixel of a blob: image coordinates, its height above the table (m) and its colour.
#[derive(Clone, Copy, Debug)]
pub struct HeightPixel {
    pub u: u32,
    pub v: u32,
    pub height_m: f64,
    pub rgb: [u8; 3],
}

/// Basins smaller than this have no colour of their own yet (a noise top, a highlight).
const COLOUR_MIN_PIXELS: usize = 100;
/// Chromaticity distance that tells two surfaces apart: the twin's catalog fruits of one
/// kind spread by about 0.03 (the classical detector's scale), neighbours of different
/// kinds usually differ by 0.1 or more.
const CHROMA_APART: f64 = 0.06;

/// Brightness ratio (ln) that tells two surfaces apart: a yellow overripe banana lying across
/// an olive one differs from it by 0.03 in chromaticity but is 1.4 times as bright where seen
/// (1.6 times in albedo); two basins of one fruit, both round its top, are lit alike.
const BRIGHTNESS_APART_LN: f64 = 0.3;

/// Running colour of a basin: sums of r, g, b and the pixels counted (saturated highlights
/// and near-black pixels left out, as `colour_name::mean_surface_colour` does).
#[derive(Clone, Copy, Default)]
struct ColourSum {
    rgb: [f64; 3],
    n: usize,
}

impl ColourSum {
    fn add(&mut self, rgb: [u8; 3]) {
        let sum: u32 = rgb.iter().map(|c| *c as u32).sum();
        if rgb.iter().any(|c| *c >= 250) || sum <= 30 {
            return;
        }
        for (s, c) in self.rgb.iter_mut().zip(rgb) {
            *s += c as f64;
        }
        self.n += 1;
    }

    fn merge(&mut self, other: ColourSum) {
        for (s, o) in self.rgb.iter_mut().zip(other.rgb) {
            *s += o;
        }
        self.n += other.n;
    }

    fn chromaticity(&self) -> [f64; 2] {
        let s = self.rgb.iter().sum::<f64>().max(1e-9);
        [self.rgb[0] / s, self.rgb[1] / s]
    }

    /// Mean channel sum.
    fn brightness(&self) -> f64 {
        self.rgb.iter().sum::<f64>() / self.n.max(1) as f64
    }

    /// Whether two basins' surfaces are of different colours (false while either is small).
    fn differs(&self, other: &ColourSum) -> bool {
        if self.n < COLOUR_MIN_PIXELS || other.n < COLOUR_MIN_PIXELS {
            return false;
        }
        let (a, b) = (self.chromaticity(), other.chromaticity());
        (a[0] - b[0]).hypot(a[1] - b[1]) > CHROMA_APART
            || (self.brightness() / other.brightness()).ln().abs() > BRIGHTNESS_APART_LN
    }
}

/// The blob's pixels grouped into objects (each group in the order given), largest first.
pub fn split_by_height(pixels: &[HeightPixel], prominence_m: f64) -> Vec<Vec<HeightPixel>> {
    if pixels.is_empty() {
        return Vec::new();
    }
    let (u0, v0) = pixels
        .iter()
        .fold((u32::MAX, u32::MAX), |(a, b), p| (a.min(p.u), b.min(p.v)));
    let w = pixels.iter().map(|p| p.u - u0).max().unwrap_or(0) as usize + 1;
    let h = pixels.iter().map(|p| p.v - v0).max().unwrap_or(0) as usize + 1;
    let mut grid: Vec<Option<usize>> = vec![None; w * h];
    for (i, p) in pixels.iter().enumerate() {
        grid[(p.v - v0) as usize * w + (p.u - u0) as usize] = Some(i);
    }
    let smooth = smoothed_heights(pixels, &grid, w, h, u0, v0);

    let mut order: Vec<usize> = (0..pixels.len()).collect();
    // Ties broken by index, so the same blob always splits the same way.
    order.sort_by(|&a, &b| smooth[b].total_cmp(&smooth[a]).then(a.cmp(&b)));
    let mut parent: Vec<usize> = (0..pixels.len()).collect();
    let mut peak: Vec<f64> = smooth.clone();
    let mut colour: Vec<ColourSum> = vec![ColourSum::default(); pixels.len()];
    let mut done = vec![false; pixels.len()];
    for &i in &order {
        let (x, y) = ((pixels[i].u - u0) as i64, (pixels[i].v - v0) as i64);
        let mut roots: Vec<usize> = Vec::new();
        for (dx, dy) in NEIGHBOURS {
            let (nx, ny) = (x + dx, y + dy);
            if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                continue;
            }
            if let Some(j) = grid[ny as usize * w + nx as usize]
                && done[j]
            {
                let r = find(&mut parent, j);
                if !roots.contains(&r) {
                    roots.push(r);
                }
            }
        }
        done[i] = true;
        // Highest top first: it absorbs the others that are not prominent enough.
        roots.sort_by(|&a, &b| peak[b].total_cmp(&peak[a]).then(a.cmp(&b)));
        let Some(&main) = roots.first() else {
            colour[i].add(pixels[i].rgb);
            continue; // a new top: its own basin for now
        };
        for &other in &roots[1..] {
            let low = peak[other] - smooth[i] < prominence_m;
            if low && !colour[other].differs(&colour[main]) {
                parent[other] = main;
                let c = colour[other];
                colour[main].merge(c);
            }
        }
        parent[i] = main;
        peak[main] = peak[main].max(smooth[i]);
        colour[main].add(pixels[i].rgb);
    }
    let mut groups: Vec<(usize, Vec<HeightPixel>)> = Vec::new();
    for (i, p) in pixels.iter().enumerate() {
        let r = find(&mut parent, i);
        match groups.iter_mut().find(|(root, _)| *root == r) {
            Some((_, g)) => g.push(*p),
            None => groups.push((r, vec![*p])),
        }
    }
    groups.sort_by(|a, b| b.1.len().cmp(&a.1.len()).then(a.0.cmp(&b.0)));
    groups.into_iter().map(|(_, g)| g).collect()
}

const NEIGHBOURS: [(i64, i64); 8] = [
    (-1, -1),
    (0, -1),
    (1, -1),
    (-1, 0),
    (1, 0),
    (-1, 1),
    (0, 1),
    (1, 1),
];

fn find(parent: &mut [usize], mut i: usize) -> usize {
    while parent[i] != i {
        parent[i] = parent[parent[i]];
        i = parent[i];
    }
    i
}

/// Mean height over the blob's pixels in a 3 x 3 window: the depth median's noise of about a
/// millimetre would otherwise make a top on every other pixel. A wider window raises the
/// saddle where a fruit leans under a larger one's flank and hides the smaller one's top.
fn smoothed_heights(
    pixels: &[HeightPixel],
    grid: &[Option<usize>],
    w: usize,
    h: usize,
    u0: u32,
    v0: u32,
) -> Vec<f64> {
    pixels
        .iter()
        .map(|p| {
            let (x, y) = ((p.u - u0) as usize, (p.v - v0) as usize);
            let (mut sum, mut n) = (0.0, 0usize);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    if let Some(j) = grid[yy * w + xx] {
                        sum += pixels[j].height_m;
                        n += 1;
                    }
                }
            }
            sum / n as f64
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Caps of spheres (centre u, v in pixels, radius in pixels, 1 px = 1 mm) seen from above,
    /// with a deterministic ripple of `noise_m` standing in for depth noise.
    fn hills(spheres: &[(f64, f64, f64)], noise_m: f64) -> Vec<HeightPixel> {
        let mut out = Vec::new();
        for v in 0..200u32 {
            for u in 0..300u32 {
                let top = spheres
                    .iter()
                    .filter_map(|&(cu, cv, r)| {
                        let d2 = (u as f64 - cu).powi(2) + (v as f64 - cv).powi(2);
                        (d2 < r * r).then(|| (r + (r * r - d2).sqrt()) * 1e-3)
                    })
                    .fold(0.0f64, f64::max);
                let ripple = noise_m * ((u * 7919 + v * 104_729) % 13) as f64 / 6.0 - noise_m;
                if top > 0.006 {
                    out.push(HeightPixel {
                        u,
                        v,
                        height_m: top + ripple,
                        rgb: [200, 120, 40],
                    });
                }
            }
        }
        out
    }

    #[test]
    fn two_touching_fruits_become_two_objects_of_their_own_sizes() {
        // A 70 mm and a 50 mm fruit touching side by side: one connected blob from above.
        let pixels = hills(&[(100.0, 100.0, 35.0), (158.0, 100.0, 25.0)], 0.002);
        let groups = split_by_height(&pixels, 0.005);
        assert_eq!(
            groups.len(),
            2,
            "sizes {:?}",
            groups.iter().map(Vec::len).collect::<Vec<_>>()
        );
        let centre = |g: &[HeightPixel]| g.iter().map(|p| p.u as f64).sum::<f64>() / g.len() as f64;
        assert!(
            (centre(&groups[0]) - 100.0).abs() < 2.0,
            "{}",
            centre(&groups[0])
        );
        assert!(
            (centre(&groups[1]) - 158.0).abs() < 2.0,
            "{}",
            centre(&groups[1])
        );
    }

    #[test]
    fn a_small_fruit_under_a_large_ones_flank_stays_apart_by_its_colour_or_brightness() {
        // A 28 mm fruit whose top stands 3 mm above the saddle, against a 64 mm one: by
        // height alone they are one; a red one against a dark green one are two.
        let mut pixels = hills(&[(100.0, 100.0, 32.0)], 0.0);
        for p in &mut pixels {
            p.rgb = [50, 60, 25];
        }
        for v in 60..100u32 {
            for u in 140..175u32 {
                let d = ((u as f64 - 157.0).powi(2) + (v as f64 - 80.0).powi(2)).sqrt();
                if d < 17.0 {
                    // The saddle where it meets the flank is 25 mm high, its top 28 mm.
                    let h = 0.025 + 0.003 * (1.0 - d / 17.0);
                    pixels.push(HeightPixel {
                        u,
                        v,
                        height_m: h,
                        rgb: [210, 30, 35],
                    });
                }
            }
        }
        // A bridge of flank joins them.
        for u in 120..150u32 {
            if !pixels.iter().any(|p| (p.u, p.v) == (u, 85)) {
                pixels.push(HeightPixel {
                    u,
                    v: 85,
                    height_m: 0.025,
                    rgb: [50, 60, 25],
                });
            }
        }
        assert_eq!(split_by_height(&pixels, 0.005).len(), 2);
        // Of one hue but 1.6 times as bright (a yellow banana lying across an olive one):
        // two as well.
        for p in &mut pixels {
            if p.rgb == [210, 30, 35] {
                p.rgb = [80, 96, 40];
            }
        }
        assert_eq!(split_by_height(&pixels, 0.005).len(), 2);
        for p in &mut pixels {
            p.rgb = [50, 60, 25];
        }
        assert_eq!(split_by_height(&pixels, 0.005).len(), 1);
    }

    #[test]
    fn one_noisy_fruit_stays_one_object() {
        let pixels = hills(&[(150.0, 100.0, 40.0)], 0.003);
        assert_eq!(split_by_height(&pixels, 0.005).len(), 1);
    }

    #[test]
    fn a_row_of_three_touching_fruits_splits_into_three() {
        let pixels = hills(
            &[
                (60.0, 100.0, 30.0),
                (118.0, 100.0, 30.0),
                (176.0, 100.0, 30.0),
            ],
            0.002,
        );
        assert_eq!(split_by_height(&pixels, 0.005).len(), 3);
    }
}
