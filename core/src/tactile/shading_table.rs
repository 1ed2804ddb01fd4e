//! The calibrated shading model of a vision-based tactile sensor, as Taxim builds it: the
//! colour change a gel surface slope causes, in bins over slope magnitude and direction, each
//! bin a per-channel quadratic in pixel position (the lights sit at the pad's rim, so the same
//! slope looks different across the frame). Fitted from presses of a ball of known radius,
//! where the slope at every pixel inside the contact circle is known from the geometry.
//!
//! Refinements over Taxim's nearest-bin lookup: values are interpolated bilinearly between
//! bin nodes (no banding), and the fit couples neighbouring nodes with a smoothness penalty so
//! that bins no press reached take values continued from their neighbours.
//!
//! Position (u, v) is normalised to [-1, 1] across the frame; slopes are dw/dx and dw/dy of the
//! gel's indentation in image axes. Evaluation is in f32, the same arithmetic as the shader.

use serde::{Deserialize, Serialize};
use std::f32::consts::TAU;

/// Terms of the per-bin quadratic: 1, u, v, u^2, uv, v^2.
pub const TERMS: usize = 6;

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShadingTable {
    /// Nodes over slope magnitude, from 0 to `mag_max` inclusive.
    pub mag_bins: u32,
    /// Nodes over slope direction, periodic over a full turn.
    pub dir_bins: u32,
    /// Largest slope magnitude the table covers; steeper slopes take its value.
    pub mag_max: f32,
    /// Coefficients, indexed ((m * dir_bins + d) * 3 + channel) * TERMS + term.
    pub coefficients: Vec<f32>,
}

/// One calibration observation: a pixel whose slope is known, and its colour change over the
/// no-contact frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadingSample {
    pub gx: f32,
    pub gy: f32,
    pub u: f32,
    pub v: f32,
    pub change: [f32; 3],
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ShadingTableError {
    #[error("{field}: {message}")]
    Invalid {
        field: &'static str,
        message: String,
    },
}

fn invalid(field: &'static str, message: impl Into<String>) -> ShadingTableError {
    ShadingTableError::Invalid {
        field,
        message: message.into(),
    }
}

/// Where a slope falls among the bin nodes: the lower magnitude node and the two direction
/// nodes around it, with the interpolation fractions.
#[derive(Clone, Copy, Debug)]
pub(super) struct BinPosition {
    pub(super) m0: u32,
    pub(super) d0: u32,
    pub(super) d1: u32,
    pub(super) tm: f32,
    pub(super) td: f32,
}

fn bin_position(mag_bins: u32, dir_bins: u32, mag_max: f32, gx: f32, gy: f32) -> BinPosition {
    bin_position_at(mag_bins, dir_bins, mag_max, gx, gy, gy.atan2(gx))
}

#[inline(always)]
pub(super) fn bin_position_at(
    mag_bins: u32,
    dir_bins: u32,
    mag_max: f32,
    gx: f32,
    gy: f32,
    angle: f32,
) -> BinPosition {
    let mag = (gx * gx + gy * gy).sqrt().min(mag_max);
    let fm = mag / mag_max * (mag_bins - 1) as f32;
    // Truncation is floor for these non-negative positions, without libm's floorf call
    // (a twentieth of a profile's read).
    let m0 = (fm as u32).min(mag_bins - 2);
    let fd = (angle + TAU * 0.5) / TAU * dir_bins as f32;
    let fd0 = (fd as u32) as f32;
    // The angle lies in [-pi, pi], so fd in [0, dir_bins]: one wrap at most, without the
    // integer division of `%` (two per lookup were a tenth of a profile's `ask`).
    let wrap = |d: u32| if d >= dir_bins { d - dir_bins } else { d };
    let d0 = wrap(fd0 as u32);
    BinPosition {
        m0,
        d0,
        d1: wrap(d0 + 1),
        tm: fm - m0 as f32,
        td: fd - fd0,
    }
}

/// Bin nodes and bilinear weights for a slope: [(node index, weight); 4].
fn nodes(mag_bins: u32, dir_bins: u32, mag_max: f32, gx: f32, gy: f32) -> [(u32, f32); 4] {
    let b = bin_position(mag_bins, dir_bins, mag_max, gx, gy);
    let at = |m: u32, d: u32| m * dir_bins + d;
    [
        (at(b.m0, b.d0), (1.0 - b.tm) * (1.0 - b.td)),
        (at(b.m0, b.d1), (1.0 - b.tm) * b.td),
        (at(b.m0 + 1, b.d0), b.tm * (1.0 - b.td)),
        (at(b.m0 + 1, b.d1), b.tm * b.td),
    ]
}

/// Pixel (x, y)'s centre as the table's position (u, v), each in [-1, 1] across a w x h frame.
pub fn frame_position(x: u32, y: u32, w: u32, h: u32) -> (f32, f32) {
    (
        2.0 * ((x as f32 + 0.5) / w as f32 - 0.5),
        2.0 * ((y as f32 + 0.5) / h as f32 - 0.5),
    )
}

fn basis(u: f32, v: f32) -> [f32; TERMS] {
    [1.0, u, v, u * u, u * v, v * v]
}

impl ShadingTable {
    pub fn validate(&self) -> Result<(), ShadingTableError> {
        if self.mag_bins < 2 || self.mag_bins > 256 {
            return Err(invalid("mag_bins", "must be in 2..=256"));
        }
        if self.dir_bins < 1 || self.dir_bins > 256 {
            return Err(invalid("dir_bins", "must be in 1..=256"));
        }
        if !(self.mag_max.is_finite() && self.mag_max > 0.0) {
            return Err(invalid("mag_max", "must be a positive finite slope"));
        }
        let want = (self.mag_bins * self.dir_bins * 3) as usize * TERMS;
        if self.coefficients.len() != want {
            return Err(invalid(
                "coefficients",
                format!(
                    "has {} values; {} x {} bins need {want}",
                    self.coefficients.len(),
                    self.mag_bins,
                    self.dir_bins
                ),
            ));
        }
        if self.coefficients.iter().any(|c| !c.is_finite()) {
            return Err(invalid("coefficients", "must all be finite"));
        }
        Ok(())
    }

    fn node_value(&self, node: u32, c: usize, u: f32, v: f32) -> f32 {
        let k = (node as usize * 3 + c) * TERMS;
        let t = &self.coefficients[k..k + TERMS];
        t[0] + t[1] * u + t[2] * v + t[3] * u * u + t[4] * u * v + t[5] * v * v
    }

    /// Colour change (grey levels per channel) of a pixel at normalised position (u, v) whose
    /// gel surface has slope (gx, gy). Same operations, in the same order, as the shader.
    pub fn change(&self, gx: f32, gy: f32, u: f32, v: f32) -> [f32; 3] {
        let b = bin_position(self.mag_bins, self.dir_bins, self.mag_max, gx, gy);
        self.lookup(b, u, v)
    }

    fn lookup(&self, b: BinPosition, u: f32, v: f32) -> [f32; 3] {
        let at = |m: u32, d: u32| m * self.dir_bins + d;
        std::array::from_fn(|c| {
            let lo = self.node_value(at(b.m0, b.d0), c, u, v) * (1.0 - b.td)
                + self.node_value(at(b.m0, b.d1), c, u, v) * b.td;
            let hi = self.node_value(at(b.m0 + 1, b.d0), c, u, v) * (1.0 - b.td)
                + self.node_value(at(b.m0 + 1, b.d1), c, u, v) * b.td;
            lo * (1.0 - b.tm) + hi * b.tm
        })
    }

    /// The colour change of the flat gel at normalised position (u, v): zero for a sensor whose
    /// no-contact frame is its background. Calibration presses taken some time after the
    /// background show a smooth drift here, which `split_flat` moves into the background.
    pub fn flat_change(&self, u: f32, v: f32) -> [f32; 3] {
        self.change(0.0, 0.0, u, v)
    }

    /// The table less its flat change, and that change: every node's quadratic less the
    /// magnitude-0 node's, so that, the interpolation weights summing to one, the new table
    /// gives exactly `change - flat_change` at every slope and place.
    pub fn split_flat(&self) -> ShadingTable {
        let per_node = 3 * TERMS;
        let flat: Vec<f32> = self.coefficients[..per_node].to_vec();
        let coefficients = self
            .coefficients
            .chunks(per_node)
            .flat_map(|node| node.iter().zip(&flat).map(|(c, f)| c - f))
            .collect();
        ShadingTable {
            coefficients,
            ..self.clone()
        }
    }

    /// Least-squares fit of the table to `samples`. Each sample constrains the four nodes
    /// around its slope with its bilinear weights; `smoothness` (grey levels^2 per unit
    /// difference) ties neighbouring nodes together and fills nodes without data. The
    /// magnitude-0 nodes are one node in every direction (a flat gel has no direction).
    pub fn fit(
        samples: &[ShadingSample],
        mag_bins: u32,
        dir_bins: u32,
        mag_max: f32,
        smoothness: f64,
    ) -> Result<Self, ShadingTableError> {
        let shell = ShadingTable {
            mag_bins,
            dir_bins,
            mag_max,
            coefficients: vec![0.0; (mag_bins * dir_bins * 3) as usize * TERMS],
        };
        shell.validate()?;
        if samples.len() < 4 * TERMS {
            return Err(invalid(
                "samples",
                format!("{} calibration pixels are too few", samples.len()),
            ));
        }
        if !(smoothness.is_finite() && smoothness >= 0.0) {
            return Err(invalid("smoothness", "must be a non-negative number"));
        }
        // Unknown nodes: one shared at magnitude 0, then (m >= 1, d).
        let unknown = |node: u32| -> usize {
            let (m, d) = (node / dir_bins, node % dir_bins);
            if m == 0 {
                0
            } else {
                1 + ((m - 1) * dir_bins + d) as usize
            }
        };
        let nodes_n = 1 + ((mag_bins - 1) * dir_bins) as usize;
        let n = nodes_n * TERMS;
        let mut normal = vec![0.0f64; n * n];
        let mut rhs = vec![[0.0f64; 3]; n];
        for s in samples {
            let b = basis(s.u, s.v);
            let mut row: Vec<(usize, f64)> = Vec::with_capacity(4 * TERMS);
            for (node, w) in nodes(mag_bins, dir_bins, mag_max, s.gx, s.gy) {
                if w == 0.0 {
                    continue;
                }
                let base = unknown(node) * TERMS;
                for (t, bt) in b.iter().enumerate() {
                    row.push((base + t, w as f64 * *bt as f64));
                }
            }
            for &(i, a) in &row {
                for &(j, b) in &row {
                    normal[i * n + j] += a * b;
                }
                for (r, change) in rhs[i].iter_mut().zip(s.change) {
                    *r += a * change as f64;
                }
            }
        }
        // Smoothness between neighbours in magnitude and in direction, on every term.
        let mut tie = |a: usize, b: usize, weight: f64| {
            for t in 0..TERMS {
                let (i, j) = (a * TERMS + t, b * TERMS + t);
                normal[i * n + i] += weight;
                normal[j * n + j] += weight;
                normal[i * n + j] -= weight;
                normal[j * n + i] -= weight;
            }
        };
        for m in 1..mag_bins {
            for d in 0..dir_bins {
                let here = unknown(m * dir_bins + d);
                tie(here, unknown((m - 1) * dir_bins + d), smoothness);
                if dir_bins > 1 {
                    tie(here, unknown(m * dir_bins + (d + 1) % dir_bins), smoothness);
                }
            }
        }
        // A small ridge keeps the system definite where neither data nor ties reach a term.
        let trace = (0..n).map(|i| normal[i * n + i]).sum::<f64>() / n as f64;
        for i in 0..n {
            normal[i * n + i] += 1e-9 * trace.max(1e-12) + 1e-12;
        }
        let solution = solve_spd(&mut normal, n, &rhs)
            .ok_or_else(|| invalid("samples", "calibration system is singular"))?;
        let mut coefficients = shell.coefficients;
        for node in 0..mag_bins * dir_bins {
            let base = unknown(node) * TERMS;
            for c in 0..3 {
                for t in 0..TERMS {
                    coefficients[(node as usize * 3 + c) * TERMS + t] =
                        solution[base + t][c] as f32;
                }
            }
        }
        let table = ShadingTable {
            coefficients,
            ..shell
        };
        table.validate()?;
        Ok(table)
    }
}

/// Solves A x = b for a symmetric positive definite A (row-major, overwritten by its Cholesky
/// factor) and three right-hand sides.
pub(crate) fn solve_spd(a: &mut [f64], n: usize, b: &[[f64; 3]]) -> Option<Vec<[f64; 3]>> {
    for j in 0..n {
        let mut d = a[j * n + j];
        for k in 0..j {
            d -= a[j * n + k] * a[j * n + k];
        }
        if d.is_nan() || d <= 0.0 {
            return None;
        }
        let d = d.sqrt();
        a[j * n + j] = d;
        for i in j + 1..n {
            let mut s = a[i * n + j];
            for k in 0..j {
                s -= a[i * n + k] * a[j * n + k];
            }
            a[i * n + j] = s / d;
        }
    }
    let mut x = b.to_vec();
    // Forward then backward substitution, three right-hand sides at once.
    for i in 0..n {
        let mut s = x[i];
        for k in 0..i {
            for c in 0..3 {
                s[c] -= a[i * n + k] * x[k][c];
            }
        }
        x[i] = s.map(|v| v / a[i * n + i]);
    }
    for i in (0..n).rev() {
        let mut s = x[i];
        for k in i + 1..n {
            for c in 0..3 {
                s[c] -= a[k * n + i] * x[k][c];
            }
        }
        x[i] = s.map(|v| v / a[i * n + i]);
    }
    Some(x)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A table fitted to the analytic lights over a flat grey background: its changes are
    /// the lights' gains times the background, less the background.
    pub(crate) fn lights_table() -> ShadingTable {
        let lights = crate::tactile::photometric::PhotometricModel::default();
        let bg = 140.0f32;
        let mut samples = Vec::new();
        for i in 0..=40 {
            for j in 0..=40 {
                let (gx, gy) = (i as f32 * 0.1 - 2.0, j as f32 * 0.1 - 2.0);
                for (u, v) in [(-0.8f32, -0.6f32), (0.0, 0.0), (0.7, 0.5), (-0.4, 0.9)] {
                    let g = lights.gain_for_slope(gx as f64, gy as f64);
                    samples.push(ShadingSample {
                        gx,
                        gy,
                        u,
                        v,
                        change: std::array::from_fn(|c| bg * (g[c] as f32 - 1.0)),
                    });
                }
            }
        }
        ShadingTable::fit(&samples, 12, 24, 2.5, 1.0).unwrap()
    }

    #[test]
    fn splitting_off_the_flat_change_keeps_every_change_less_it() {
        let table = ShadingTable {
            mag_bins: 4,
            dir_bins: 6,
            mag_max: 2.0,
            coefficients: (0..4 * 6 * 3 * TERMS)
                .map(|k| ((k * 37 % 101) as f32 - 50.0) * 0.1)
                .collect(),
        };
        // A fitted table's magnitude-0 nodes are one node; make this one's so too.
        let mut table = table;
        let first: Vec<f32> = table.coefficients[..3 * TERMS].to_vec();
        for d in 0..6 {
            table.coefficients[d * 3 * TERMS..(d + 1) * 3 * TERMS].copy_from_slice(&first);
        }
        let split = table.split_flat();
        for (gx, gy, u, v) in [
            (0.0, 0.0, 0.3, -0.7),
            (0.4, -1.1, -0.9, 0.2),
            (3.0, 0.5, 0.0, 1.0),
        ] {
            let (a, f, b) = (
                table.change(gx, gy, u, v),
                table.flat_change(u, v),
                split.change(gx, gy, u, v),
            );
            for c in 0..3 {
                assert!((a[c] - f[c] - b[c]).abs() < 1e-4, "{a:?} - {f:?} vs {b:?}");
            }
        }
        assert!(split.flat_change(0.5, 0.5).iter().all(|c| c.abs() < 1e-5));
    }

    /// A shading law the table can represent only approximately: smooth in slope and in
    /// position, like coloured lights at the rim.
    fn law(gx: f32, gy: f32, u: f32, v: f32) -> [f32; 3] {
        [
            40.0 * gx + 10.0 * u * gx,
            -30.0 * gy + 5.0 * v,
            20.0 * (gx * gx + gy * gy) - 8.0 * u * v,
        ]
    }

    #[test]
    fn fit_recovers_a_smooth_shading_law() {
        let mut samples = Vec::new();
        for k in 0..20000u32 {
            let t = k as f32;
            let (gx, gy) = (
                (t * 0.618).fract() * 2.0 - 1.0,
                (t * 0.414).fract() * 2.0 - 1.0,
            );
            let (u, v) = (
                (t * 0.303).fract() * 2.0 - 1.0,
                (t * 0.777).fract() * 2.0 - 1.0,
            );
            samples.push(ShadingSample {
                gx,
                gy,
                u,
                v,
                change: law(gx, gy, u, v),
            });
        }
        let table = ShadingTable::fit(&samples, 8, 16, 1.5, 1e-3).unwrap();
        let mut worst = 0.0f32;
        for &(gx, gy, u, v) in &[
            (0.0, 0.0, 0.0, 0.0),
            (0.5, -0.2, 0.3, -0.6),
            (-0.4, 0.4, -0.9, 0.2),
        ] {
            let got = table.change(gx, gy, u, v);
            let want = law(gx, gy, u, v);
            for c in 0..3 {
                worst = worst.max((got[c] - want[c]).abs());
            }
        }
        // Bilinear interpolation in slope over bins 0.21 wide: well under a grey level.
        assert!(worst < 1.0, "worst error {worst}");
    }

    #[test]
    fn empty_bins_are_filled_from_neighbours() {
        // Only slopes pointing right are observed; the table must stay finite and flat-gel
        // value must hold everywhere.
        let samples: Vec<ShadingSample> = (0..500)
            .map(|k| {
                let gx = k as f32 / 500.0;
                ShadingSample {
                    gx,
                    gy: 0.0,
                    u: 0.0,
                    v: 0.0,
                    change: [10.0 * gx, 0.0, 0.0],
                }
            })
            .collect();
        let table = ShadingTable::fit(&samples, 6, 12, 1.0, 0.01).unwrap();
        assert!(table.coefficients.iter().all(|c| c.is_finite()));
        assert!(table.change(0.0, 0.0, 0.0, 0.0)[0].abs() < 0.1);
        let got = table.change(0.5, 0.0, 0.0, 0.0)[0];
        assert!((got - 5.0).abs() < 0.5, "{got}");
    }

    #[test]
    fn rejects_bad_dimensions_and_lengths() {
        let t = ShadingTable {
            mag_bins: 4,
            dir_bins: 4,
            mag_max: 1.0,
            coefficients: vec![0.0; 5],
        };
        assert!(
            t.validate()
                .unwrap_err()
                .to_string()
                .starts_with("coefficients")
        );
        assert!(ShadingTable::fit(&[], 1, 4, 1.0, 0.1).is_err());
    }
}
