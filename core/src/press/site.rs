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

    /// Each occupied cell that `pad` overlaps, with its centre and its highest point. A cell
    /// counts when its centre lies within the footprint grown by half the cell's extent
    /// along the footprint's axes, so a cell the footprint only grazes still counts.
    fn under(&self, pad: &Footprint) -> impl Iterator<Item = (DVec2, f64)> + '_ {
        let pad = *pad;
        let (c, s) = (pad.axis.x.abs(), pad.axis.y.abs());
        let grow = 0.5 * self.cell_m * (c + s);
        let half = pad.half + DVec2::splat(grow);
        // The axis-aligned box round the turned footprint.
        let reach = DVec2::new(c * half.x + s * half.y, s * half.x + c * half.y);
        let (lo, hi) = (pad.centre - reach, pad.centre + reach);
        let last = self.origin + DVec2::new(self.nx as f64, self.ny as f64) * self.cell_m;
        let overlaps =
            !(hi.x < self.origin.x || hi.y < self.origin.y || lo.x >= last.x || lo.y >= last.y);
        let index = |v: f64, origin: f64, n: usize| {
            (((v - origin) / self.cell_m).floor().max(0.0) as usize).min(n - 1)
        };
        let (i0, i1) = (
            index(lo.x, self.origin.x, self.nx),
            index(hi.x, self.origin.x, self.nx),
        );
        let (j0, j1) = (
            index(lo.y, self.origin.y, self.ny),
            index(hi.y, self.origin.y, self.ny),
        );
        overlaps
            .then(move || (j0..=j1).flat_map(move |j| (i0..=i1).map(move |i| (i, j))))
            .into_iter()
            .flatten()
            .map(|(i, j)| (self.cell_centre(i, j), self.top[j * self.nx + i]))
            .filter(move |(at, t)| {
                let local = pad.in_pad_frame(*at).abs();
                t.is_finite() && local.x <= half.x && local.y <= half.y
            })
    }

    fn cell_centre(&self, i: usize, j: usize) -> DVec2 {
        self.origin + (DVec2::new(i as f64, j as f64) + 0.5) * self.cell_m
    }

    /// The highest point in the cells `pad` overlaps; -inf if none.
    fn highest_in(&self, pad: &Footprint) -> f64 {
        self.under(pad)
            .map(|(_, t)| t)
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Where a flat pad lowered over `pad` first meets the points: the centre of the cells
    /// within `band` of the highest (depth noise spreads a crest over a few cells).
    fn first_contact(&self, pad: &Footprint, band: f64) -> Option<(DVec2, f64)> {
        let top = self.highest_in(pad);
        let (sum, n) = self
            .under(pad)
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

/// The rectangle a pad covers on the table: centred at `centre`, `half` its half extents
/// along its own axes, its x axis along the unit vector `axis`.
#[derive(Clone, Copy, Debug)]
pub struct Footprint {
    pub centre: DVec2,
    pub half: DVec2,
    pub axis: DVec2,
}

impl Footprint {
    pub fn new(centre: DVec2, half: DVec2, yaw_rad: f64) -> Self {
        Self {
            centre,
            half,
            axis: DVec2::from_angle(yaw_rad),
        }
    }

    /// The same footprint grown by `margin` on every side.
    pub fn grown(self, margin: f64) -> Self {
        Self {
            half: self.half + DVec2::splat(margin),
            ..self
        }
    }

    /// `at` in the pad's frame (its x along `axis`).
    fn in_pad_frame(&self, at: DVec2) -> DVec2 {
        let d = at - self.centre;
        DVec2::new(d.dot(self.axis), d.dot(self.axis.perp()))
    }
}

/// Where and how the pad presses: its centre, and its turn about the vertical.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PressSite {
    pub at: DVec3,
    pub yaw_rad: f64,
    /// Nowhere was clear of everything else by the grounding margin: the site is where
    /// other things reach least far up under the bare pad, for the arm to judge.
    pub crowded: bool,
}

/// Where the pad presses the object whose depth points are `own`, with everything else in
/// `others`: `crest` itself when the pad there (straight, else turned a quarter, else turned
/// a multiple of 15 degrees) meets nothing else first; else the nearest spot where it meets
/// nothing else first and first meets the object under its middle half (off the crest, so
/// that the imprint starts in the frame's middle and not at an edge where it would be cut).
/// Where no site is clear with the margin round the pad, the one where other things reach
/// least far up under the bare pad, marked `crowded`; None only when the object has no
/// points.
pub fn press_site(
    crest: DVec3,
    own: &HeightMap,
    others: &HeightMap,
    pad: &PadClearance,
) -> Option<PressSite> {
    let yaws = PAD_YAWS_DEG.map(f64::to_radians);
    // Every candidate in the order of preference: the crest at each turn, then the spots
    // nearest it whose first contact lies under the pad's middle half.
    let at_crest = yaws.iter().map(|&yaw_rad| {
        let footprint = Footprint::new(crest.truncate(), pad.half_m, yaw_rad);
        let top = own.highest_in(&footprint);
        (footprint, yaw_rad, crest.z.max(top), crest)
    });
    let mut spots: Vec<DVec2> = own.occupied().collect();
    let from = crest.truncate();
    spots.sort_by(|a, b| a.distance(from).total_cmp(&b.distance(from)));
    let off_crest = spots.into_iter().flat_map(|at| {
        yaws.iter().filter_map(move |&yaw_rad| {
            let footprint = Footprint::new(at, pad.half_m, yaw_rad);
            let (meets, z) = own.first_contact(&footprint, CREST_BAND_M)?;
            let off = footprint.in_pad_frame(meets).abs();
            let centred = off.x <= 0.5 * pad.half_m.x && off.y <= 0.5 * pad.half_m.y;
            centred.then_some((footprint, yaw_rad, z, at.extend(z)))
        })
    });
    let candidates: Vec<_> = at_crest.chain(off_crest).collect();
    // How far the highest other thing under the pad reaches above the depth the press may go.
    let intrusion = |footprint: &Footprint, z: f64, margin: f64| {
        others.highest_in(&footprint.grown(margin)) - (z - pad.below_m)
    };
    let site = |&(_, yaw_rad, _, at): &(Footprint, f64, f64, DVec3), crowded| PressSite {
        at,
        yaw_rad,
        crowded,
    };
    if let Some(clear) = candidates
        .iter()
        .find(|(footprint, _, z, _)| intrusion(footprint, *z, pad.margin_m) < 0.0)
    {
        return Some(site(clear, false));
    }
    candidates
        .iter()
        .map(|c| (intrusion(&c.0, c.2, 0.0), c))
        .min_by(|a, b| a.0.total_cmp(&b.0))
        .map(|(_, c)| site(c, true))
}

/// The pad's turns about the vertical, in the order they are tried: straight and a quarter
/// turn first (the imprint's axes along the table's), then every 15 degrees between; the pad
/// is symmetric, so half a turn covers them all. A small fruit between two tall ones often
/// has room only along the valley between them.
const PAD_YAWS_DEG: [f64; 12] = [
    0.0, 90.0, 15.0, 30.0, 45.0, 60.0, 75.0, 105.0, 120.0, 135.0, 150.0, 165.0,
];

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

    /// The pad's footprint at a site, grown by the clearance margin.
    fn footprint_at(s: &PressSite, pad: &PadClearance) -> Footprint {
        Footprint::new(s.at.truncate(), pad.half_m, s.yaw_rad).grown(pad.margin_m)
    }

    #[test]
    fn a_small_fruit_beside_a_tall_one_is_pressed_with_the_pad_turned() {
        // A strawberry (16 mm) with an avocado (35 mm tall) 12 mm off its crest on the +x
        // side: the pad's long side would reach the avocado's flank, its short side does not.
        let own = dome(DVec2::ZERO, 0.015, 0.016);
        let others = dome(DVec2::new(0.042, 0.0), 0.03, 0.035);
        let pad = PadClearance::for_pad_mm([20.3, 15.2]);
        let others_map = HeightMap::new(&others, 0.002).unwrap();
        let crest = Footprint::new(DVec2::ZERO, pad.half_m, 0.0).grown(0.003);
        assert!(others_map.highest_in(&crest) > 0.016 - 0.004);
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
        for yaw_deg in PAD_YAWS_DEG {
            let crest = Footprint::new(DVec2::ZERO, pad.half_m, yaw_deg.to_radians()).grown(0.003);
            assert!(others_map.highest_in(&crest) > 0.016 - 0.004);
        }
        let s = site(&own, &others).unwrap();
        let at = s.at;
        assert!(at.x < -0.002, "moved away from the avocado: {s:?}");
        assert!(
            others_map.highest_in(&footprint_at(&s, &pad)) < at.z - 0.004,
            "{s:?}"
        );
        // Still on the strawberry, near its top.
        assert!(at.truncate().length() < 0.015 && at.z > 0.012, "{s:?}");
    }

    #[test]
    fn a_small_fruit_in_a_diagonal_valley_is_pressed_with_the_pad_along_it() {
        // Two tall fruits on the strawberry's -45 degree diagonal: straight or turned a
        // quarter, a corner of the pad reaches a flank; along the valley (45 degrees) the pad
        // clears both.
        let own = dome(DVec2::ZERO, 0.015, 0.016);
        let mut others = dome(DVec2::new(0.0297, -0.0297), 0.03, 0.035);
        others.extend(dome(DVec2::new(-0.0297, 0.0297), 0.03, 0.035));
        let pad = PadClearance::for_pad_mm([20.3, 15.2]);
        let others_map = HeightMap::new(&others, 0.002).unwrap();
        for yaw_deg in [0.0f64, 90.0] {
            let crest = Footprint::new(DVec2::ZERO, pad.half_m, yaw_deg.to_radians()).grown(0.003);
            assert!(others_map.highest_in(&crest) > 0.016 - 0.004, "{yaw_deg}");
        }
        let s = site(&own, &others).unwrap();
        assert!(
            s.at.truncate().length() < 1e-9,
            "pressed on the crest: {s:?}"
        );
        let yaw_deg = s.yaw_rad.to_degrees();
        assert!((30.0..=60.0).contains(&yaw_deg), "{s:?}");
        assert!(others_map.highest_in(&footprint_at(&s, &pad)) < s.at.z - 0.004);
    }

    #[test]
    fn a_fruit_buried_between_taller_ones_is_pressed_where_they_reach_least_and_marked_crowded() {
        let own = dome(DVec2::ZERO, 0.012, 0.012);
        let mut others = dome(DVec2::new(0.04, 0.0), 0.03, 0.04);
        others.extend(dome(DVec2::new(-0.04, 0.0), 0.03, 0.04));
        others.extend(dome(DVec2::new(0.0, 0.04), 0.03, 0.04));
        others.extend(dome(DVec2::new(0.0, -0.04), 0.03, 0.04));
        let s = site(&own, &others).unwrap();
        assert!(s.crowded, "{s:?}");
        // Still on the fruit, and where the four flanks reach least: straight or a quarter
        // turn on the crest (a turned pad's corners reach into them).
        assert!(s.at.truncate().length() < 0.012 && s.at.z > 0.0, "{s:?}");
        let pad = PadClearance::for_pad_mm([20.3, 15.2]);
        let others_map = HeightMap::new(&others, 0.002).unwrap();
        let reach = |yaw_deg: f64| {
            others_map.highest_in(&Footprint::new(
                DVec2::ZERO,
                pad.half_m,
                yaw_deg.to_radians(),
            ))
        };
        assert!(reach(0.0) < reach(45.0), "{} {}", reach(0.0), reach(45.0));
        assert!(
            s.yaw_rad == 0.0 || s.yaw_rad == std::f64::consts::FRAC_PI_2,
            "{s:?}"
        );
    }
}
