//! A calibrated shading table read backwards: the gel slope whose colour change is nearest an
//! observed one, as the estimators read a real sensor's frames. The reader walks a frame row
//! by row, so the table is first collapsed to one row's v (each node's quadratic in position
//! becomes a quadratic in u alone); every lookup of the descent then costs half as much.

use crate::tactile::shading_table::{BinPosition, ShadingTable, TERMS, bin_position_at};
use std::f32::consts::TAU;

/// The table at one row of the frame: per node and channel, a0 + u (a1 + u a2).
pub struct ShadingRow<'a> {
    table: &'a ShadingTable,
    poly: Vec<[f32; 3]>,
    /// The ring's slopes, and each one's change as quadratics in u, per channel: a slope's
    /// bin is fixed, so its change along the row is its four nodes' quadratics, weighted.
    ring: Vec<((f32, f32), ChangeAlongRow)>,
    /// The bins of the flat gel and of the four slopes a descent from it differences over
    /// (+h, -h along gx, then gy): every pixel's read looks the flat gel up, so these are
    /// placed once a row.
    at_flat: [BinPosition; 5],
}

/// A slope read from the table, and where it falls among the table's nodes: the next pixel's
/// descent starts from it without placing it again.
#[derive(Clone, Copy, Debug)]
pub struct ReadSlope {
    pub gx: f32,
    pub gy: f32,
    bin: BinPosition,
}

/// A lookup of the descent: the cost, the residual, the change's derivatives along gx and gy,
/// and the slope's bin.
type Local = (f32, [f32; 3], [f32; 3], [f32; 3], BinPosition);

/// A change as quadratics in u, per channel: [a0, a1, a2] for a0 + u (a1 + u a2).
type ChangeAlongRow = [[f32; 3]; 3];

/// Slope magnitudes (as fractions of a 2.5-slope table's range) and directions of the coarse
/// ring a descent left unexplained is searched again from.
const RING_MAGNITUDES: [f32; 5] = [0.1, 0.3, 0.6, 1.0, 1.6];
const RING_DIRECTIONS: usize = 12;

/// The step of the central differences at the flat gel, as a fraction of the table's range.
const FLAT_DIFFERENCE: f32 = 1e-3;

impl ShadingTable {
    /// The table collapsed to normalised row position `v`, for shading a row forwards: each
    /// lookup then costs half the quadratics, and the direction is `direction`'s, not libm's
    /// atan2 (the renderer's table shading was a sixth of a 640 x 480 profile's `ask`).
    pub fn lookup_row(&self, v: f32) -> ShadingRow<'_> {
        let poly = self
            .coefficients
            .chunks_exact(TERMS)
            .map(|t| [t[0] + t[2] * v + t[5] * v * v, t[1] + t[4] * v, t[3]])
            .collect();
        let h = FLAT_DIFFERENCE * self.mag_max;
        let at = |gx: f32, gy: f32| place(self, gx, gy);
        ShadingRow {
            table: self,
            poly,
            ring: Vec::new(),
            at_flat: [
                at(0.0, 0.0),
                at(h, 0.0),
                at(-h, 0.0),
                at(0.0, h),
                at(0.0, -h),
            ],
        }
    }

    /// The table collapsed to normalised row position `v`, for reading a row backwards: the
    /// lookup row and the coarse ring of slopes the inverse searches from.
    pub fn row(&self, v: f32) -> ShadingRow<'_> {
        let mut row = self.lookup_row(v);
        for mag in RING_MAGNITUDES {
            let mag = mag * self.mag_max / 2.5;
            for k in 0..RING_DIRECTIONS {
                let (sin, cos) = (k as f32 * TAU / RING_DIRECTIONS as f32).sin_cos();
                let (gx, gy) = (mag * cos, mag * sin);
                let b = row.bin(gx, gy);
                let weights = [
                    (1.0 - b.tm) * (1.0 - b.td),
                    (1.0 - b.tm) * b.td,
                    b.tm * (1.0 - b.td),
                    b.tm * b.td,
                ];
                let nodes = row.nodes(&b);
                let change = std::array::from_fn(|c| {
                    let mut q = [0.0f32; 3];
                    for (node, w) in nodes.iter().zip(weights) {
                        let p = row.poly[node + c];
                        for (q, p) in q.iter_mut().zip(p) {
                            *q += w * p;
                        }
                    }
                    q
                });
                row.ring.push(((gx, gy), change));
            }
        }
        row
    }
}

/// Where slope (gx, gy) falls among the table's nodes.
fn place(t: &ShadingTable, gx: f32, gy: f32) -> BinPosition {
    bin_position_at(t.mag_bins, t.dir_bins, t.mag_max, gx, gy, direction(gy, gx))
}

/// Many slopes' bins, a field at a time (so that placing them vectorises).
struct Places {
    m0: Vec<u32>,
    d0: Vec<u32>,
    d1: Vec<u32>,
    tm: Vec<f32>,
    td: Vec<f32>,
}

impl Places {
    fn new(n: usize) -> Self {
        Places {
            m0: vec![0; n],
            d0: vec![0; n],
            d1: vec![0; n],
            tm: vec![0.0; n],
            td: vec![0.0; n],
        }
    }

    fn at(&self, i: usize) -> BinPosition {
        BinPosition {
            m0: self.m0[i],
            d0: self.d0[i],
            d1: self.d1[i],
            tm: self.tm[i],
            td: self.td[i],
        }
    }
}

/// Every slope's bin, as `ShadingRow::bin` places it, with AVX2 where the CPU has it (the
/// same operations, so the same bits).
#[multiversion::multiversion(targets("x86_64+avx2"))]
fn place_all(mag_bins: u32, dir_bins: u32, mag_max: f32, slopes: &[[f32; 2]], out: &mut Places) {
    let n = slopes.len();
    let (m0, d0, d1, tm, td) = (
        &mut out.m0[..n],
        &mut out.d0[..n],
        &mut out.d1[..n],
        &mut out.tm[..n],
        &mut out.td[..n],
    );
    for i in 0..n {
        let [gx, gy] = slopes[i];
        let b = bin_position_at(mag_bins, dir_bins, mag_max, gx, gy, direction(gy, gx));
        m0[i] = b.m0;
        d0[i] = b.d0;
        d1[i] = b.d1;
        tm[i] = b.tm;
        td[i] = b.td;
    }
}

/// atan2 to within 1e-5 rad (a 5th-order minimax fit of atan on [0, 1], folded into the
/// octants): libm's was a fifth of the inverse's time, and an error of 1e-5 rad moves a
/// lookup by 4e-5 of a 24-bin direction step, far below a grey level.
#[inline(always)]
fn direction(gy: f32, gx: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (gx.abs(), gy.abs());
    let (num, den) = if ax >= ay { (ay, ax) } else { (ax, ay) };
    if den == 0.0 {
        return 0.0;
    }
    let z = num / den;
    let z2 = z * z;
    let mut a = z
        * (0.999_977_3
            + z2 * (-0.332_623_5
                + z2 * (0.193_543_5
                    + z2 * (-0.116_432_9 + z2 * (0.052_653_3 + z2 * -0.011_721_2)))));
    if ay > ax {
        a = FRAC_PI_2 - a;
    }
    if gx < 0.0 {
        a = PI - a;
    }
    if gy < 0.0 { -a } else { a }
}

impl ShadingRow<'_> {
    fn bin(&self, gx: f32, gy: f32) -> BinPosition {
        place(self.table, gx, gy)
    }

    /// The table's change at the slope placed at `b`, position u along the row.
    fn change_in(&self, b: &BinPosition, u: f32) -> [f32; 3] {
        let n = self.corners(b, u);
        let mut out = [0.0f32; 3];
        for (o, [n00, n01, n10, n11]) in out.iter_mut().zip(n) {
            let lo = n00 * (1.0 - b.td) + n01 * b.td;
            let hi = n10 * (1.0 - b.td) + n11 * b.td;
            *o = lo * (1.0 - b.tm) + hi * b.tm;
        }
        out
    }

    /// The four nodes around `b` (n00, n01, n10, n11), as indices of their channel 0 in `poly`.
    fn nodes(&self, b: &BinPosition) -> [usize; 4] {
        let dir_bins = self.table.dir_bins;
        let at = |m: u32, d: u32| (m * dir_bins + d) as usize * 3;
        [
            at(b.m0, b.d0),
            at(b.m0, b.d1),
            at(b.m0 + 1, b.d0),
            at(b.m0 + 1, b.d1),
        ]
    }

    /// The four nodes around `b`, each channel's value at u: [n00, n01, n10, n11] per channel.
    fn corners(&self, b: &BinPosition, u: f32) -> [[f32; 4]; 3] {
        let nodes = self.nodes(b);
        let mut out = [[0.0f32; 4]; 3];
        for (c, channel) in out.iter_mut().enumerate() {
            for (value, node) in channel.iter_mut().zip(nodes) {
                let p = self.poly[node + c];
                *value = p[0] + u * (p[1] + u * p[2]);
            }
        }
        out
    }

    /// The table's change at each slope of a row of pixels at positions `us` along it, into
    /// `out`: the same values as `change` of each, with the slopes placed among the nodes all
    /// at once first (a loop without branches, which vectorises: placing a slope was half a
    /// lookup, and a 640 x 480 profile's frame shades 300 000).
    pub fn changes(&self, slopes: &[[f32; 2]], us: &[f32], out: &mut [[f32; 3]]) {
        let n = slopes.len().min(us.len()).min(out.len());
        let mut placed = Places::new(n);
        let t = self.table;
        place_all(t.mag_bins, t.dir_bins, t.mag_max, &slopes[..n], &mut placed);
        for (i, o) in out[..n].iter_mut().enumerate() {
            *o = self.change_in(&placed.at(i), us[i]);
        }
    }

    /// The table's change at slope (gx, gy) and position u along the row.
    pub fn change(&self, gx: f32, gy: f32, u: f32) -> [f32; 3] {
        self.change_in(&self.bin(gx, gy), u)
    }

    /// `change` and its derivatives along gx and gy, from one lookup of the four nodes (the
    /// inverse's Gauss-Newton needs all three at every step). Away from the flat gel only:
    /// at gx = gy = 0 the direction, and so the derivative, is undefined.
    #[cfg(test)]
    fn change_with_derivatives(&self, gx: f32, gy: f32, u: f32) -> ([f32; 3], [f32; 3], [f32; 3]) {
        self.change_with_derivatives_in(&self.bin(gx, gy), gx, gy, u)
    }

    /// `change_with_derivatives` at a slope already placed at `b`.
    fn change_with_derivatives_in(
        &self,
        b: &BinPosition,
        gx: f32,
        gy: f32,
        u: f32,
    ) -> ([f32; 3], [f32; 3], [f32; 3]) {
        let t = self.table;
        let mag2 = gx * gx + gy * gy;
        let mag = mag2.sqrt();
        // d tm / d g and d td / d g: magnitude is clamped at mag_max, direction wraps.
        let dtm = if mag < t.mag_max {
            (t.mag_bins - 1) as f32 / t.mag_max / mag
        } else {
            0.0
        };
        let dtd = t.dir_bins as f32 / TAU / mag2;
        let (mut c, mut jx, mut jy) = ([0.0f32; 3], [0.0f32; 3], [0.0f32; 3]);
        for (k, [n00, n01, n10, n11]) in self.corners(b, u).into_iter().enumerate() {
            let lo = n00 * (1.0 - b.td) + n01 * b.td;
            let hi = n10 * (1.0 - b.td) + n11 * b.td;
            c[k] = lo * (1.0 - b.tm) + hi * b.tm;
            let by_tm = (hi - lo) * dtm;
            let by_td = ((n01 - n00) * (1.0 - b.tm) + (n11 - n10) * b.tm) * dtd;
            jx[k] = by_tm * gx - by_td * gy;
            jy[k] = by_tm * gy + by_td * gx;
        }
        (c, jx, jy)
    }

    /// The slope (gx, gy) whose colour change at u along this row is nearest `change` (least
    /// squares over the three channels, plus `prior` grey levels^2 per unit slope^2 of
    /// |g|^2). A real table can colour a steep slope almost like the flat gel (its steep
    /// nodes are fitted from few pixels), so without the prior the camera's noise on a flat
    /// pixel can pick a steep slope. A damped Gauss-Newton descent starts from the better of
    /// the flat gel and `near` (a neighbouring pixel's slope: the gel's surface is
    /// continuous); only a change that descent leaves unexplained, by more than a few grey
    /// levels, is searched again from the best of a coarse ring of slopes. None where no
    /// slope comes within `max_rms` grey levels (saturation, dust, a marker's edge).
    pub fn slope_for_change(
        &self,
        change: [f32; 3],
        u: f32,
        prior: f32,
        max_rms: f32,
        near: Option<ReadSlope>,
    ) -> Option<ReadSlope> {
        let mag_max = self.table.mag_max;
        let residual_in = |b: &BinPosition| {
            let c = self.change_in(b, u);
            [c[0] - change[0], c[1] - change[1], c[2] - change[2]]
        };
        let residual = |gx: f32, gy: f32| residual_in(&self.bin(gx, gy));
        let norm2 = |r: [f32; 3]| r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
        let [at_flat, at_xp, at_xm, at_yp, at_ym] = &self.at_flat;
        let flat_change = self.change_in(at_flat, u);
        let flat_residual: [f32; 3] = std::array::from_fn(|c| flat_change[c] - change[c]);
        let flat = norm2(flat_residual) + prior * (0.0f32 * 0.0 + 0.0f32 * 0.0);
        // A flat gel shows no change: most of a stock-sensor press frame ends here.
        if flat <= 3.0 * 0.25 {
            return Some(ReadSlope {
                gx: 0.0,
                gy: 0.0,
                bin: *at_flat,
            });
        }
        let h = FLAT_DIFFERENCE * mag_max;
        // The change, the cost and the change's derivatives at a slope (placed at `placed`
        // when known): analytic derivatives of the bilinear lookup, except at the flat gel,
        // where the table is a cone with no gradient: there central differences average the
        // directions, which is what lets the descent leave the apex.
        let local = |gx: f32, gy: f32, placed: Option<&BinPosition>| -> Local {
            let (c, jx, jy, b) = if gx * gx + gy * gy > h * h {
                let b = placed.copied().unwrap_or_else(|| self.bin(gx, gy));
                let (c, jx, jy) = self.change_with_derivatives_in(&b, gx, gy, u);
                (c, jx, jy, b)
            } else {
                // At the flat gel itself the five slopes are the row's, already placed.
                let (c, dx, dxm, dy, dym, b) = if gx == 0.0 && gy == 0.0 {
                    (
                        flat_change,
                        residual_in(at_xp),
                        residual_in(at_xm),
                        residual_in(at_yp),
                        residual_in(at_ym),
                        *at_flat,
                    )
                } else {
                    let b = self.bin(gx, gy);
                    (
                        self.change_in(&b, u),
                        residual(gx + h, gy),
                        residual(gx - h, gy),
                        residual(gx, gy + h),
                        residual(gx, gy - h),
                        b,
                    )
                };
                (
                    c,
                    std::array::from_fn(|c| (dx[c] - dxm[c]) / (2.0 * h)),
                    std::array::from_fn(|c| (dy[c] - dym[c]) / (2.0 * h)),
                    b,
                )
            };
            let r: [f32; 3] = [c[0] - change[0], c[1] - change[1], c[2] - change[2]];
            (norm2(r) + prior * (gx * gx + gy * gy), r, jx, jy, b)
        };
        // From a start and its lookup to the slope, its cost, its residual (which the final
        // check reuses: every lookup is kept, none made twice) and its bin.
        let descend = |(mut gx, mut gy): (f32, f32), at_start: Local| {
            let mut damping = 1e-2f32;
            let (mut err, mut r, mut jx, mut jy, mut bin) = at_start;
            for _ in 0..20 {
                let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
                let (a, b, d) = (dot(jx, jx) + prior, dot(jx, jy), dot(jy, jy) + prior);
                let (ex, ey) = (-dot(jx, r) - prior * gx, -dot(jy, r) - prior * gy);
                let mut stepped = false;
                for _ in 0..6 {
                    let (a2, d2) = (a * (1.0 + damping) + 1e-6, d * (1.0 + damping) + 1e-6);
                    let det = a2 * d2 - b * b;
                    if det.abs() < 1e-12 {
                        damping *= 4.0;
                        continue;
                    }
                    let (sx, sy) = ((d2 * ex - b * ey) / det, (a2 * ey - b * ex) / det);
                    // The trial's derivatives come with its lookup, ready for the next step.
                    let trial = local(gx + sx, gy + sy, None);
                    if trial.0 < err {
                        gx += sx;
                        gy += sy;
                        // A thousandth of a unit of slope is a fortieth of a grey level.
                        let converged =
                            (sx * sx + sy * sy).sqrt() < 1e-3 || err - trial.0 < 1e-4 * err;
                        (err, r, jx, jy, bin) = trial;
                        damping = (damping / 3.0).max(1e-6);
                        stepped = !converged;
                        break;
                    }
                    damping *= 4.0;
                }
                if !stepped {
                    break;
                }
            }
            (gx, gy, err, r, bin)
        };
        // The better start of the flat gel and `near`, whose lookup the descent begins with.
        let from_near = near.map(|n| ((n.gx, n.gy), local(n.gx, n.gy, Some(&n.bin))));
        let mut best = match from_near {
            Some((g, at)) if at.0 < flat => descend(g, at),
            _ => descend((0.0, 0.0), local(0.0, 0.0, None)),
        };
        // Left over after the descent: more than a camera's noise (4 grey levels a channel)
        // may be a local minimum, so the ring's global start gets its chance.
        if best.2 > 3.0 * 4.0 * 4.0 {
            let mut ring = (0.0f32, 0.0f32, f32::INFINITY);
            for &((gx, gy), q) in &self.ring {
                let mut e = prior * (gx * gx + gy * gy);
                for (q, o) in q.iter().zip(change) {
                    let r = q[0] + u * (q[1] + u * q[2]) - o;
                    e += r * r;
                }
                if e < ring.2 {
                    ring = (gx, gy, e);
                }
            }
            if ring.2 < best.2 {
                let again = descend((ring.0, ring.1), local(ring.0, ring.1, None));
                if again.2 < best.2 {
                    best = again;
                }
            }
        }
        let (gx, gy, _, r, bin) = best;
        ((norm2(r) / 3.0).sqrt() <= max_rms).then_some(ReadSlope { gx, gy, bin })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tactile::shading_table::tests::lights_table;

    #[test]
    fn a_row_gives_the_tables_change_at_every_slope_and_place_and_on_its_ring() {
        let table = lights_table();
        for v in [-0.9f32, 0.0, 0.35] {
            let row = table.row(v);
            for (gx, gy, u) in [
                (0.0f32, 0.0f32, -1.0f32),
                (0.3, -0.2, 0.1),
                (-1.4, 0.9, 0.8),
            ] {
                let (a, b) = (table.change(gx, gy, u, v), row.change(gx, gy, u));
                assert!((0..3).all(|c| (a[c] - b[c]).abs() < 1e-3), "{a:?} {b:?}");
            }
            assert_eq!(row.ring.len(), RING_MAGNITUDES.len() * RING_DIRECTIONS);
            for &((gx, gy), q) in &row.ring {
                for u in [-1.0f32, 0.2, 0.9] {
                    let a = table.change(gx, gy, u, v);
                    let b: [f32; 3] =
                        std::array::from_fn(|c| q[c][0] + u * (q[c][1] + u * q[c][2]));
                    assert!((0..3).all(|c| (a[c] - b[c]).abs() < 1e-3), "{a:?} {b:?}");
                }
            }
        }
    }

    #[test]
    fn read_backwards_the_table_gives_the_slope_that_made_the_colour() {
        let table = lights_table();
        for (gx, gy) in [
            (0.0f32, 0.0f32),
            (0.05, -0.02),
            (0.3, 0.1),
            (-0.6, 0.4),
            (1.2, -0.9),
            (0.0, 1.8),
        ] {
            for (u, v) in [(0.0f32, 0.0f32), (0.5, -0.3)] {
                let change = table.change(gx, gy, u, v);
                let (rx, ry) = table
                    .row(v)
                    .slope_for_change(change, u, 0.0, 1.0, None)
                    .map(|s| (s.gx, s.gy))
                    .unwrap();
                let tol = 0.02 + 0.03 * (gx * gx + gy * gy).sqrt();
                assert!(
                    (rx - gx).abs() < tol && (ry - gy).abs() < tol,
                    "({gx}, {gy}) at ({u}, {v}) read back as ({rx}, {ry})"
                );
            }
        }
        // No slope makes every channel 80 grey levels brighter.
        assert!(
            table
                .row(0.0)
                .slope_for_change([80.0; 3], 0.0, 0.0, 6.0, None)
                .is_none()
        );
    }

    #[test]
    fn the_lookups_derivatives_are_its_slopes_between_nodes() {
        let table = lights_table();
        let h = 1e-3f32;
        for (gx, gy) in [
            (0.13f32, 0.07f32),
            (-0.61, 0.42),
            (1.17, -0.93),
            (0.02, 1.71),
        ] {
            let (u, v) = (0.4f32, -0.2f32);
            let (c, jx, jy) = table.row(v).change_with_derivatives(gx, gy, u);
            let exact = table.change(gx, gy, u, v);
            assert!(
                (0..3).all(|k| (c[k] - exact[k]).abs() < 1e-3),
                "{c:?} {exact:?}"
            );
            let (px, mx) = (
                table.change(gx + h, gy, u, v),
                table.change(gx - h, gy, u, v),
            );
            let (py, my) = (
                table.change(gx, gy + h, u, v),
                table.change(gx, gy - h, u, v),
            );
            for k in 0..3 {
                let (nx, ny) = ((px[k] - mx[k]) / (2.0 * h), (py[k] - my[k]) / (2.0 * h));
                let tol = 0.02 * (nx.abs() + ny.abs()) + 0.5;
                assert!(
                    (jx[k] - nx).abs() < tol && (jy[k] - ny).abs() < tol,
                    "({gx}, {gy}) channel {k}: analytic ({}, {}) numeric ({nx}, {ny})",
                    jx[k],
                    jy[k]
                );
            }
        }
    }

    #[test]
    fn the_inverses_direction_is_atan2_within_1e_5_rad() {
        let mut worst = 0.0f32;
        for k in 0..20_000 {
            let a = k as f32 / 20_000.0 * TAU - TAU / 2.0;
            for r in [1e-4f32, 0.3, 2.5] {
                let (gx, gy) = (r * a.cos(), r * a.sin());
                worst = worst.max((direction(gy, gx) - gy.atan2(gx)).abs());
            }
        }
        assert!(worst < 1e-5, "{worst}");
        assert_eq!(direction(0.0, 0.0), 0.0);
    }
}
