//! The `hertz` level: the object's surface near its lowest point is fitted by a quadric and
//! replaced by the sphere of the same Gaussian curvature, sqrt(R1 R2); Hertz theory then
//! gives the pressure, and each body takes its compliance share of the approach. The gel's
//! lateral field is Johnson's half-space solution (eq. 3.41a) under that pressure.

use super::fidelity::Fidelity;
use super::grid::Grid;
use super::influence::half_space_lateral_ratio;
use super::problem::ContactProblem;
use super::solution::{ContactSolution, FieldModel, GelFields};
use glam::DVec2;
use tactex_core::hertz::{Elastic, Hertz};
use tactex_core::tactile::spec::GelSpec;

/// The equivalent sphere of a contact.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EquivalentSphere {
    pub centre_mm: DVec2,
    pub radius_mm: f64,
}

/// Least-squares quadric z = c0 + c1 x + c2 y + c3 x^2 + c4 xy + c5 y^2.
fn fit_quadric(points: &[(DVec2, f64)]) -> Option<[f64; 6]> {
    let mut a = [[0.0f64; 7]; 6];
    for (p, z) in points {
        let row = [1.0, p.x, p.y, p.x * p.x, p.x * p.y, p.y * p.y];
        for i in 0..6 {
            for j in 0..6 {
                a[i][j] += row[i] * row[j];
            }
            a[i][6] += row[i] * z;
        }
    }
    for col in 0..6 {
        let pivot = (col..6).max_by(|&r, &s| a[r][col].abs().total_cmp(&a[s][col].abs()))?;
        if a[pivot][col].abs() < 1e-300 {
            return None;
        }
        a.swap(col, pivot);
        for r in 0..6 {
            if r != col {
                let f = a[r][col] / a[col][col];
                let pivot_row = a[col];
                for (x, p) in a[r].iter_mut().zip(pivot_row).skip(col) {
                    *x -= f * p;
                }
            }
        }
    }
    let c: [f64; 6] = std::array::from_fn(|i| a[i][6] / a[i][i]);
    c.iter().all(|v| v.is_finite()).then_some(c)
}

/// Fits the sphere to the cells of `heights` (relative to first touch) below `level`. On a
/// saddle or a near-cylinder the smaller curvature is capped at 1/20 of the larger.
fn equivalent_sphere(grid: &Grid, heights: &[f64], level: f64) -> Option<EquivalentSphere> {
    let lowest = (0..heights.len()).min_by(|&a, &b| heights[a].total_cmp(&heights[b]))?;
    if !heights[lowest].is_finite() {
        return None;
    }
    let apex = grid.centre(lowest % grid.nx, lowest / grid.nx);
    // Coordinates relative to the apex keep the normal equations well conditioned.
    let scale = grid.cell_mm * grid.nx.max(grid.ny) as f64;
    // The central part of the dip (inside the Hertz contact, h < level / 2, or smaller)
    // where a sphere is still close to its osculating paraboloid, with enough cells to fit.
    let patch = |cut: f64| -> Vec<(DVec2, f64)> {
        heights
            .iter()
            .enumerate()
            .filter(|(_, h)| h.is_finite() && **h <= cut)
            .map(|(k, h)| ((grid.centre(k % grid.nx, k / grid.nx) - apex) / scale, *h))
            .collect()
    };
    let mut points = patch(level / 4.0);
    for cut in [level / 2.0, level] {
        if points.len() >= 24 {
            break;
        }
        points = patch(cut);
    }
    let fallback = EquivalentSphere {
        centre_mm: apex,
        radius_mm: f64::INFINITY,
    };
    if points.len() < 6 {
        return Some(fallback);
    }
    let Some(c) = fit_quadric(&points) else {
        return Some(fallback);
    };
    let s2 = scale * scale;
    let (h11, h12, h22) = (2.0 * c[3] / s2, c[4] / s2, 2.0 * c[5] / s2);
    let mean = (h11 + h22) / 2.0;
    let spread = (((h11 - h22) / 2.0).powi(2) + h12 * h12).sqrt();
    let (k1, k2) = (mean + spread, mean - spread);
    if k1 <= 0.0 {
        return Some(fallback);
    }
    let det = h11 * h22 - h12 * h12;
    let offset = if det > 0.0 {
        let (g1, g2) = (c[1] / scale, c[2] / scale);
        DVec2::new((-g1 * h22 + g2 * h12) / det, (-g2 * h11 + g1 * h12) / det)
    } else {
        DVec2::ZERO
    };
    let centre = (apex + offset).clamp(grid.rect().min, grid.rect().max);
    Some(EquivalentSphere {
        centre_mm: centre,
        radius_mm: 1.0 / (k1 * k2.max(k1 / 20.0)).sqrt(),
    })
}

/// The gel's radial displacement at r under the Hertz pressure (Johnson eq. 3.41a), for a
/// gel of compliance `gel_compliance` and half-space lateral ratio `t_inf`.
fn gel_radial_mm(hertz: &Hertz, r: f64, gel_compliance: f64, t_inf: f64) -> f64 {
    let a = hertz.contact_radius_mm();
    if a <= 0.0 || r <= 0.0 {
        return 0.0;
    }
    let p0 = hertz.max_pressure_mpa();
    let shape = if r < a {
        1.0 - (1.0 - (r / a).powi(2)).powf(1.5)
    } else {
        1.0
    };
    2.0 / 3.0 * t_inf * gel_compliance * p0 * a * a / r * shape
}

pub(super) fn solve(
    problem: &ContactProblem,
    grid: Grid,
    separation: &[f64],
    warnings: &mut Vec<String>,
) -> ContactSolution {
    let heights: Vec<f64> = separation.iter().map(|s| s + problem.approach_mm).collect();
    let sphere = equivalent_sphere(&grid, &heights, problem.approach_mm);
    let mut sphere = sphere.unwrap_or(EquivalentSphere {
        centre_mm: grid.centre(grid.nx / 2, grid.ny / 2),
        radius_mm: f64::INFINITY,
    });
    if sphere.radius_mm.is_nan() || sphere.radius_mm >= 1e3 {
        warnings.push(
            "hertz assumes a locally spherical contact, but this surface is flat there: radius capped at 1 m"
                .into(),
        );
        sphere.radius_mm = 1e3;
    }
    let gel = Elastic {
        modulus_mpa: Some(problem.gel.modulus_mpa),
        poisson: problem.gel.poisson,
    };
    let hertz = Hertz {
        radius_mm: sphere.radius_mm,
        approach_mm: problem.approach_mm,
        contact_modulus_mpa: tactex_core::hertz::contact_modulus_mpa(gel, problem.object),
    };
    let gel_share = tactex_core::hertz::gel_share(gel, problem.object);
    let model = FieldModel::Hertz {
        hertz,
        centre_mm: sphere.centre_mm,
        gel_share,
    };
    let fields = hertz_fields(&grid, &hertz, sphere.centre_mm, gel_share, &problem.gel);
    let pressure = (0..grid.len())
        .map(|k| {
            let r = (grid.centre(k % grid.nx, k / grid.nx) - sphere.centre_mm).length();
            hertz.pressure_mpa(r)
        })
        .collect();
    let mut s = ContactSolution::assemble(problem, Fidelity::Hertz, grid, pressure, fields, model);
    // The level's answer is the analytic one, not the grid sums.
    let a = hertz.contact_radius_mm();
    s.force_n = hertz.force_n();
    s.contact_radius_mm = a;
    s.contact_area_mm2 = std::f64::consts::PI * a * a;
    s.max_pressure_mpa = hertz.max_pressure_mpa();
    s.gel_max_indentation_mm = gel_share * problem.approach_mm;
    s.object_max_indentation_mm = (1.0 - gel_share) * problem.approach_mm;
    s
}

/// The gel's fields under a Hertz contact centred at `centre`.
pub(super) fn hertz_fields(
    grid: &Grid,
    hertz: &Hertz,
    centre: DVec2,
    gel_share: f64,
    gel: &GelSpec,
) -> GelFields {
    let gel_c = (1.0 - gel.poisson * gel.poisson) / gel.modulus_mpa;
    let t_inf = half_space_lateral_ratio(gel.poisson);
    let n = grid.len();
    let (mut normal, mut lx, mut ly) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    for q in 0..n {
        let d = grid.centre(q % grid.nx, q / grid.nx) - centre;
        let r = d.length();
        normal[q] = gel_share * hertz.total_displacement_mm(r);
        if r > 0.0 {
            let ur = gel_radial_mm(hertz, r, gel_c, t_inf);
            lx[q] = ur * d.x / r;
            ly[q] = ur * d.y / r;
        }
    }
    GelFields {
        grid: *grid,
        normal_mm: normal,
        lateral_x_mm: lx,
        lateral_y_mm: ly,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::grid::Rect;
    use crate::contact::surface::ObjectSurface;

    #[test]
    fn recovers_an_ellipsoids_gaussian_curvature_radius() {
        let surface = ObjectSurface::Ellipsoid {
            semi_axes_mm: glam::DVec3::new(30.0, 20.0, 25.0),
            centre_mm: DVec2::new(0.5, -0.3),
            yaw_rad: 0.0,
        };
        let grid = Grid::covering(&Rect::centred(DVec2::splat(3.0)), 0.1);
        let heights = surface.heights(&grid);
        let s = equivalent_sphere(&grid, &heights, 0.05).unwrap();
        // Principal radii a^2 / c and b^2 / c at the pole.
        let expected = (900.0 / 25.0 * 400.0 / 25.0f64).sqrt();
        assert!((s.radius_mm - expected).abs() / expected < 0.01, "{s:?}");
        assert!((s.centre_mm - DVec2::new(0.5, -0.3)).length() < 0.01);
    }
}
