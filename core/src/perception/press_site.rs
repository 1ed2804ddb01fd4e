//! Where on a located object the pad can press: a spot where the pad meets the object before
//! anything else. A small fruit against a tall one can have its crest within a pad's width of
//! the neighbour's flank; lowered there, the pad would push into the neighbour first (on the
//! twin the arm refuses the move at its crush limit). From the depth points, the spot nearest
//! the crest whose pad footprint is clear of everything else is chosen.

use glam::{DVec2, DVec3};

/// The highest depth point in each cell of a square grid on the table.
pub struct HeightMap {
    origin: DVec2,
    cell_m: f64,
    nx: usize,
    ny: usize,
    top: Vec<f64>,
}

impl HeightMap {
    /// The map of `points` in cells of `cell_m`; None when there are none.
    pub fn new(points: &[DVec3], cell_m: f64) -> Option<Self> {
        let lo = points.iter().map(|p| p.truncate()).reduce(DVec2::min)?;
        let hi = points.iter().map(|p| p.truncate()).reduce(DVec2::max)?;
        let nx = ((hi.x - lo.x) / cell_m) as usize + 1;
        let ny = ((hi.y - lo.y) / cell_m) as usize + 1;
        let mut top = vec![f64::NEG_INFINITY; nx * ny];
        for p in points {
            let i = ((p.x - lo.x) / cell_m) as usize;
            let j = ((p.y - lo.y) / cell_m) as usize;
            let t = &mut top[j * nx + i];
            *t = t.max(p.z);
        }
        Some(Self {
            origin: lo,
            cell_m,
            nx,
            ny,
            top,
        })
    }

    /// The cells the rectangle `centre ± half` overlaps, as column and row ranges.
    fn cells_under(
        &self,
        centre: DVec2,
        half: DVec2,
    ) -> Option<(
        std::ops::RangeInclusive<usize>,
        std::ops::RangeInclusive<usize>,
    )> {
        let (lo, hi) = (centre - half, centre + half);
        let last = self.origin + DVec2::new(self.nx as f64, self.ny as f64) * self.cell_m;
        if hi.x < self.origin.x || hi.y < self.origin.y || lo.x >= last.x || lo.y >= last.y {
            return None;
        }
        let index = |v: f64, origin: f64, n: usize| {
            (((v - origin) / self.cell_m).floor().max(0.0) as usize).min(n - 1)
        };
        Some((
            index(lo.x, self.origin.x, self.nx)..=index(hi.x, self.origin.x, self.nx),
            index(lo.y, self.origin.y, self.ny)..=index(hi.y, self.origin.y, self.ny),
        ))
    }

    /// Each occupied cell under the rectangle, with its centre and its highest point.
    fn under(&self, centre: DVec2, half: DVec2) -> impl Iterator<Item = (DVec2, f64)> + '_ {
        self.cells_under(centre, half)
            .into_iter()
            .flat_map(|(columns, rows)| {
                rows.flat_map(move |j| columns.clone().map(move |i| (i, j)))
            })
            .map(|(i, j)| (self.cell_centre(i, j), self.top[j * self.nx + i]))
            .filter(|(_, t)| t.is_finite())
    }

    fn cell_centre(&self, i: usize, j: usize) -> DVec2 {
        self.origin + (DVec2::new(i as f64, j as f64) + 0.5) * self.cell_m
    }

    /// The highest point in the cells the rectangle `centre ± half` overlaps; -inf if none.
    pub fn highest_in(&self, centre: DVec2, half: DVec2) -> f64 {
        self.under(centre, half)
            .map(|(_, t)| t)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Where a flat pad lowered over the rectangle first meets the points: the centre of the
    /// cells within `band` of the highest (depth noise spreads a crest over a few cells).
    fn first_contact(&self, centre: DVec2, half: DVec2, band: f64) -> Option<(DVec2, f64)> {
        let top = self.highest_in(centre, half);
        let (sum, n) = self
            .under(centre, half)
            .filter(|(_, t)| *t >= top - band)
            .fold((DVec2::ZERO, 0.0), |(s, n), (c, _)| (s + c, n + 1.0));
        (n > 0.0).then(|| (sum / n, top))
    }

    /// Centres of the cells that hold a point.
    fn occupied(&self) -> impl Iterator<Item = DVec2> + '_ {
        (0..self.ny)
            .flat_map(move |j| (0..self.nx).map(move |i| (i, j)))
            .filter(|&(i, j)| self.top[j * self.nx + i].is_finite())
            .map(|(i, j)| self.cell_centre(i, j))
    }
}

/// The pad and how clear of other things its footprint must be.
#[derive(Clone, Copy, Debug)]
pub struct PadClearance {
    /// Half the pad's extent along the world's x and y (m).
    pub half_m: DVec2,
    /// Added round the pad when looking for other things: the error of the grounding and
    /// of the arm's placement (m).
    pub margin_m: f64,
    /// Everything else under the pad must lie this far below the first contact: the press
    /// goes down the contact search's overshoot and the recorded frames' span (m).
    pub below_m: f64,
}

impl PadClearance {
    /// A pad of `size_mm` (x, y) with the margins the pipeline's press needs.
    pub fn for_pad_mm(size_mm: [f64; 2]) -> Self {
        Self {
            half_m: DVec2::new(size_mm[0], size_mm[1]) * 0.5e-3,
            margin_m: 0.003,
            below_m: 0.004,
        }
    }
}

/// Where and how the pad presses: its centre, and its turn about the vertical (0, or a
/// quarter turn that puts the pad's short side across).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressSite {
    pub at: DVec3,
    pub yaw_rad: f64,
}

/// Where the pad presses the object whose depth points are `own`, with everything else in
/// `others`: `crest` itself when the pad there (straight, else turned a quarter) meets nothing
/// else first; else the nearest spot where it meets nothing else first and first meets the
/// object under its middle half (off the crest, so that the imprint starts in the frame's
/// middle and not at an edge where it would be cut); None when there is none.
pub fn press_site(
    crest: DVec3,
    own: &HeightMap,
    others: &HeightMap,
    pad: &PadClearance,
) -> Option<PressSite> {
    let turns = [
        (0.0, pad.half_m),
        (
            std::f64::consts::FRAC_PI_2,
            DVec2::new(pad.half_m.y, pad.half_m.x),
        ),
    ];
    let clear = |at: DVec2, half: DVec2, first_contact_z: f64| {
        others.highest_in(at, half + DVec2::splat(pad.margin_m)) < first_contact_z - pad.below_m
    };
    for (yaw_rad, half) in turns {
        let top = own.highest_in(crest.truncate(), half);
        if clear(crest.truncate(), half, crest.z.max(top)) {
            return Some(PressSite { at: crest, yaw_rad });
        }
    }
    let mut spots: Vec<DVec2> = own.occupied().collect();
    let from = crest.truncate();
    spots.sort_by(|a, b| a.distance(from).total_cmp(&b.distance(from)));
    spots.into_iter().find_map(|at| {
        turns.iter().find_map(|&(yaw_rad, half)| {
            let (meets, z) = own.first_contact(at, half, CREST_BAND_M)?;
            let off = (meets - at).abs();
            let centred = off.x <= 0.5 * half.x && off.y <= 0.5 * half.y;
            (centred && clear(at, half, z)).then(|| PressSite {
                at: at.extend(z),
                yaw_rad,
            })
        })
    })
}

/// Depth points within this of an object's highest under the pad count as where the pad meets
/// it first: the camera's depth median is good to about a millimetre.
const CREST_BAND_M: f64 = 0.001;

#[cfg(test)]
mod tests {
    use super::*;

    /// Points of a spherical cap of `radius` and `height` centred at `c`, every 1 mm.
    fn dome(c: DVec2, radius: f64, height: f64) -> Vec<DVec3> {
        let mut out = Vec::new();
        let n = (radius / 0.001) as i32;
        for i in -n..=n {
            for j in -n..=n {
                let d = DVec2::new(i as f64, j as f64) * 0.001;
                let r = d.length() / radius;
                if r <= 1.0 {
                    out.push((c + d).extend(height * (1.0 - r * r).sqrt()));
                }
            }
        }
        out
    }

    fn site(own: &[DVec3], others: &[DVec3]) -> Option<PressSite> {
        let crest = *own.iter().max_by(|a, b| a.z.total_cmp(&b.z)).unwrap();
        press_site(
            crest,
            &HeightMap::new(own, 0.002).unwrap(),
            &HeightMap::new(others, 0.002).unwrap(),
            &PadClearance::for_pad_mm([20.3, 15.2]),
        )
    }

    #[test]
    fn a_fruit_with_room_round_it_is_pressed_on_its_crest() {
        let own = dome(DVec2::ZERO, 0.03, 0.05);
        let others = dome(DVec2::new(0.08, 0.0), 0.03, 0.05);
        let s = site(&own, &others).unwrap();
        assert!(s.at.truncate().length() < 1e-9 && s.yaw_rad == 0.0, "{s:?}");
    }

    /// The pad's half extents under a site's turn.
    fn half_under(s: &PressSite, pad: &PadClearance) -> DVec2 {
        if s.yaw_rad == 0.0 {
            pad.half_m
        } else {
            DVec2::new(pad.half_m.y, pad.half_m.x)
        }
    }

    #[test]
    fn a_small_fruit_beside_a_tall_one_is_pressed_with_the_pad_turned() {
        // A strawberry (16 mm) with an avocado (35 mm tall) 12 mm off its crest on the +x
        // side: the pad's long side would reach the avocado's flank, its short side does not.
        let own = dome(DVec2::ZERO, 0.015, 0.016);
        let others = dome(DVec2::new(0.042, 0.0), 0.03, 0.035);
        let pad = PadClearance::for_pad_mm([20.3, 15.2]);
        let others_map = HeightMap::new(&others, 0.002).unwrap();
        assert!(others_map.highest_in(DVec2::ZERO, pad.half_m + 0.003) > 0.016 - 0.004);
        let s = site(&own, &others).unwrap();
        assert!(s.at.truncate().length() < 1e-9, "{s:?}");
        assert_eq!(s.yaw_rad, std::f64::consts::FRAC_PI_2);
    }

    #[test]
    fn a_small_fruit_against_a_tall_one_is_pressed_on_its_far_side() {
        // The avocado 8 mm off the crest: even the turned pad meets its flank there.
        let own = dome(DVec2::ZERO, 0.015, 0.016);
        let others = dome(DVec2::new(0.038, 0.0), 0.03, 0.035);
        let pad = PadClearance::for_pad_mm([20.3, 15.2]);
        let others_map = HeightMap::new(&others, 0.002).unwrap();
        for half in [pad.half_m, DVec2::new(pad.half_m.y, pad.half_m.x)] {
            assert!(others_map.highest_in(DVec2::ZERO, half + 0.003) > 0.016 - 0.004);
        }
        let s = site(&own, &others).unwrap();
        let at = s.at;
        assert!(at.x < -0.002, "moved away from the avocado: {s:?}");
        assert!(
            others_map.highest_in(at.truncate(), half_under(&s, &pad) + 0.003) < at.z - 0.004,
            "{s:?}"
        );
        // Still on the strawberry, near its top.
        assert!(at.truncate().length() < 0.015 && at.z > 0.012, "{s:?}");
    }

    #[test]
    fn a_fruit_buried_between_taller_ones_has_no_site() {
        let own = dome(DVec2::ZERO, 0.012, 0.012);
        let mut others = dome(DVec2::new(0.04, 0.0), 0.03, 0.04);
        others.extend(dome(DVec2::new(-0.04, 0.0), 0.03, 0.04));
        others.extend(dome(DVec2::new(0.0, 0.04), 0.03, 0.04));
        others.extend(dome(DVec2::new(0.0, -0.04), 0.03, 0.04));
        assert!(site(&own, &others).is_none());
    }
}
