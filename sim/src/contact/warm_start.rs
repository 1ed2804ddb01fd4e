//! The first guess of a press frame's pressure from the frame before it. Under a smooth
//! indenter a contact grows self-similarly (Hertz: radius and peak pressure both as the
//! square root of the approach), so the previous pressure, stretched about its centre by
//! that ratio and scaled by it, starts the solver near the answer.

use super::grid::Grid;

/// `previous` on `grid` grown by the approach ratio `ratio` (new over old): resampled
/// bilinearly at positions pulled towards the pressure's centroid by sqrt(ratio) and
/// multiplied by sqrt(ratio), so the total force goes as ratio^1.5. None when there is
/// nothing to grow (no pressure, or no meaningful ratio).
pub(crate) fn hertz_grown(grid: &Grid, previous: &[f64], ratio: f64) -> Option<Vec<f64>> {
    let (nx, ny) = (grid.nx, grid.ny);
    let total: f64 = previous.iter().sum();
    if total <= 0.0 || !ratio.is_finite() || ratio <= 0.0 {
        return None;
    }
    let (mut cx, mut cy) = (0.0, 0.0);
    for (q, p) in previous.iter().enumerate() {
        cx += (q % nx) as f64 * p;
        cy += (q / nx) as f64 * p;
    }
    let (cx, cy) = (cx / total, cy / total);
    let stretch = ratio.sqrt();
    let at = |i: isize, j: isize| -> f64 {
        if i < 0 || j < 0 || i as usize >= nx || j as usize >= ny {
            0.0
        } else {
            previous[j as usize * nx + i as usize]
        }
    };
    let grown = (0..nx * ny)
        .map(|q| {
            let x = cx + ((q % nx) as f64 - cx) / stretch;
            let y = cy + ((q / nx) as f64 - cy) / stretch;
            let (i, j) = (x.floor(), y.floor());
            let (fx, fy) = (x - i, y - j);
            let (i, j) = (i as isize, j as isize);
            let p = (at(i, j) * (1.0 - fx) + at(i + 1, j) * fx) * (1.0 - fy)
                + (at(i, j + 1) * (1.0 - fx) + at(i + 1, j + 1) * fx) * fy;
            p * stretch
        })
        .collect();
    Some(grown)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec2;

    /// Hertz pressure p0 sqrt(1 - r^2/a^2) on a grid of unit cells centred at (cx, cy).
    fn hertz(grid: &Grid, centre: (f64, f64), a: f64, p0: f64) -> Vec<f64> {
        (0..grid.len())
            .map(|q| {
                let (x, y) = (
                    (q % grid.nx) as f64 - centre.0,
                    (q / grid.nx) as f64 - centre.1,
                );
                p0 * (1.0 - (x * x + y * y) / (a * a)).max(0.0).sqrt()
            })
            .collect()
    }

    #[test]
    fn a_hertz_pressure_grown_by_the_approach_ratio_is_the_deeper_hertz_pressure() {
        let grid = Grid {
            origin_mm: DVec2::ZERO,
            cell_mm: 1.0,
            nx: 61,
            ny: 57,
        };
        let centre = (31.3, 27.6);
        // Hertz: a and p0 both grow as the square root of the approach.
        let (a1, p1) = (9.0, 0.2);
        let ratio = 2.25;
        let grown = hertz_grown(&grid, &hertz(&grid, centre, a1, p1), ratio).unwrap();
        let expected = hertz(&grid, centre, a1 * 1.5, p1 * 1.5);
        let force = |p: &[f64]| p.iter().sum::<f64>();
        // The centroid of a sampled disc is off its centre by a fraction of a cell, and
        // bilinear resampling blurs the square-root edge: the force within 2%, the cells
        // within 5% of the peak pressure in rms. (Stretching by the ratio itself instead of
        // its root puts the force 2.4x too high.)
        let rel = force(&grown) / force(&expected) - 1.0;
        assert!(rel.abs() < 0.02, "force off by {rel}");
        let inside = expected.iter().filter(|e| **e > 0.0).count() as f64;
        let rms = (grown
            .iter()
            .zip(&expected)
            .map(|(g, e)| (g - e).powi(2))
            .sum::<f64>()
            / inside)
            .sqrt();
        assert!(rms < 0.05 * p1 * 1.5, "rms off by {rms}");
        // Total force as the approach to the power 1.5.
        let f_ratio = force(&grown) / force(&hertz(&grid, centre, a1, p1));
        assert!((f_ratio / ratio.powf(1.5) - 1.0).abs() < 0.02, "{f_ratio}");
    }

    #[test]
    fn no_previous_pressure_gives_nothing_to_grow() {
        let grid = Grid {
            origin_mm: DVec2::ZERO,
            cell_mm: 1.0,
            nx: 4,
            ny: 3,
        };
        assert_eq!(hertz_grown(&grid, &[0.0; 12], 2.0), None);
        assert_eq!(hertz_grown(&grid, &[1.0; 12], f64::NAN), None);
    }
}
