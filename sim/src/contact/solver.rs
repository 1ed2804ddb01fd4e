//! The solver: plans the grid a press needs (only where the object dips below the gel, plus
//! a margin), validates the problem, dispatches to the fidelity level, and extends the gel's
//! fields over any part of the pad. It caches kernel spectra between the frames of a press.

use super::fidelity::Fidelity;
use super::grid::{Grid, Rect};
use super::influence::LayerCorrection;
use super::kernels::{GridKernels, KernelKey};
use super::problem::{ContactError, ContactProblem, invalid, validate};
use super::rigid::RIGID_SMOOTHING_MM;
use super::solution::{ContactSolution, FieldModel, GelFields};
use super::{elastic, hertz, polonsky_keer, rigid};
use glam::DVec2;
use std::collections::HashMap;
use tactex_core::hertz::Elastic;
use tactex_core::tactile::spec::GelSpec;

/// Default solver cells across the narrower side of the region the object dips into.
pub const DEFAULT_CELLS_ACROSS: f64 = 40.0;
/// The default grid never exceeds this many cells per side (it coarsens instead).
pub const DEFAULT_MAX_CELLS: usize = 256;
/// A user-chosen cell may not give more than this many cells per side.
pub const MAX_CELLS: usize = 2048;

/// Solves contacts, caching FFT plans and kernel spectra between calls (a press sequence
/// reuses them; the layer tables behind the kernels are shared by the whole process).
#[derive(Default)]
pub struct ContactSolver {
    pub settings: polonsky_keer::Settings,
    kernels: HashMap<KernelKey, GridKernels>,
}

/// The smallest n' >= n with no prime factor above 5.
fn smooth_size(n: usize) -> usize {
    (n.max(1)..)
        .find(|&m| {
            let mut r = m;
            for p in [2, 3, 5] {
                while r % p == 0 {
                    r /= p;
                }
            }
            r == 1
        })
        .expect("smooth numbers are unbounded")
}

impl ContactSolver {
    pub fn new() -> Self {
        Self::default()
    }

    /// The kernel spectra of `grid` for the half-space or (`layer`) the bonded layer.
    pub(super) fn kernels(&mut self, grid: &Grid, gel: &GelSpec, layer: bool) -> &mut GridKernels {
        let thickness = layer.then_some(gel.thickness_mm);
        let key = KernelKey::new(grid, gel.poisson, thickness);
        if !self.kernels.contains_key(&key) {
            let table = layer.then(|| {
                let diagonal = grid.cell_mm * (grid.nx as f64).hypot(grid.ny as f64) + grid.cell_mm;
                LayerCorrection::new(gel.thickness_mm, gel.poisson, diagonal)
            });
            let built = GridKernels::new(grid, gel.poisson, table.as_ref());
            // Keep the cache bounded: a press sequence needs one or two grids.
            if self.kernels.len() >= 8 {
                self.kernels.clear();
            }
            self.kernels.insert(key, built);
        }
        self.kernels.get_mut(&key).expect("inserted above")
    }

    /// The solver grid for `problem` pressed to `approach_mm`: the region where the object
    /// dips below the gel surface, plus a margin, clipped to the pad. None without contact.
    pub fn plan_grid(
        &self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        approach_mm: f64,
    ) -> Result<Option<Grid>, ContactError> {
        validate(problem)?;
        let Some(first) = problem.surface.lowest_over(&problem.pad) else {
            return Ok(None);
        };
        if approach_mm <= 0.0 {
            return Ok(None);
        }
        let Some(dipped) = problem
            .surface
            .below_level_bounds(first + approach_mm, &problem.pad)
        else {
            return Ok(None);
        };
        let size = dipped.size();
        let narrow = size.x.min(size.y).max(size.x.max(size.y) * 1e-3).max(1e-9);
        let cell = match problem.cell_mm {
            Some(cell) => cell,
            None => (narrow / DEFAULT_CELLS_ACROSS)
                .max(size.max_element() / (DEFAULT_MAX_CELLS as f64 - 8.0)),
        };
        let mut margin = 0.1 * size.max_element() + 2.0 * cell;
        if fidelity == Fidelity::Rigid {
            margin += 3.0 * RIGID_SMOOTHING_MM;
        }
        let rect = dipped
            .grown(margin)
            .intersect(&problem.pad)
            .unwrap_or(dipped);
        let cells = rect.size().max_element() / cell;
        let cell = match problem.cell_mm {
            Some(_) if cells > MAX_CELLS as f64 => {
                return Err(invalid(
                    "cell_mm",
                    format!(
                        "{cell} mm needs {cells:.0} cells across the solver grid (at most {MAX_CELLS}); use a coarser cell"
                    ),
                ));
            }
            // The smoothing margin of `rigid` can dwarf a tiny contact: coarsen instead.
            None if cells > DEFAULT_MAX_CELLS as f64 => {
                rect.size().max_element() / (DEFAULT_MAX_CELLS as f64 - 2.0)
            }
            _ => cell,
        };
        let mut grid = Grid::covering(&rect, cell);
        // FFTs of 2, 3 and 5-smooth lengths are several times faster than those with large
        // prime factors; the extra cells past the pad are masked off.
        grid.nx = smooth_size(grid.nx);
        grid.ny = smooth_size(grid.ny);
        Ok(Some(grid))
    }

    /// Solves one press on the planned grid, cold.
    pub fn solve(
        &mut self,
        problem: &ContactProblem,
        fidelity: Fidelity,
    ) -> Result<ContactSolution, ContactError> {
        let grid = self.plan_grid(problem, fidelity, problem.approach_mm)?;
        self.solve_on(problem, fidelity, grid, None)
    }

    /// Solves on `grid` (None: no contact), starting from `warm`'s pressure if given.
    pub fn solve_on(
        &mut self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        grid: Option<Grid>,
        warm: Option<&ContactSolution>,
    ) -> Result<ContactSolution, ContactError> {
        validate(problem)?;
        let mut warnings = Vec::new();
        let first = problem.surface.lowest_over(&problem.pad);
        if first.is_none() {
            warnings.push("the object is not over the pad: no contact".to_string());
        }
        let (Some(first), Some(grid)) = (first, grid) else {
            return Ok(ContactSolution::no_contact(problem, fidelity, warnings));
        };
        if problem.approach_mm == 0.0 {
            return Ok(ContactSolution::no_contact(problem, fidelity, warnings));
        }
        let approach = problem.approach_mm;
        if let Some(equator) = problem.surface.equator_height_mm()
            && first + approach > equator
        {
            warnings.push(format!(
                "the press reaches {:.3} mm up the object, past its widest section ({equator:.3} mm up): the gel would wrap its sides, which are not modelled, so the contact stops at its widest",
                first + approach
            ));
        }
        // Cells outside the pad have no gel under them.
        let pad = problem.pad;
        let separation: Vec<f64> = problem
            .surface
            .heights(&grid)
            .into_iter()
            .enumerate()
            .map(|(k, h)| {
                let c = grid.centre(k % grid.nx, k / grid.nx);
                let on_pad = c.cmpge(pad.min).all() && c.cmple(pad.max).all();
                if on_pad {
                    h - first - approach
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        if !separation.iter().any(|s| *s < 0.0) {
            warnings.push(format!(
                "the contact is smaller than one {:.4} mm cell: no pressure resolved",
                grid.cell_mm
            ));
        }
        let unclipped = problem
            .surface
            .below_level_bounds(first + approach, &Rect::centred(DVec2::splat(1e9)));
        if unclipped.is_some_and(|u| !pad.contains(&u)) {
            warnings.push("the object reaches past the pad edge: the contact is cut there".into());
        }
        let mut solution = match fidelity {
            Fidelity::Rigid => rigid::solve(problem, grid, &separation),
            Fidelity::Hertz => hertz::solve(problem, grid, &separation, &mut warnings),
            Fidelity::Halfspace | Fidelity::Layer => elastic::solve(
                self,
                problem,
                fidelity,
                grid,
                &separation,
                warm,
                &mut warnings,
            ),
        };
        if solution.gel_max_indentation_mm > problem.gel.thickness_mm {
            warnings.push(format!(
                "the gel is indented {:.3} mm, more than its {:.3} mm thickness: a real gel would bottom out on the acrylic, so the linear model is outside its range",
                solution.gel_max_indentation_mm, problem.gel.thickness_mm
            ));
        }
        solution.warnings.splice(0..0, warnings);
        Ok(solution)
    }

    /// A press sequence: the planned grid of the deepest frame for all frames, each solve
    /// warm-started from the previous one.
    pub fn press_sequence(
        &mut self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        approaches_mm: &[f64],
    ) -> Result<Vec<ContactSolution>, ContactError> {
        let deepest = approaches_mm.iter().copied().fold(0.0, f64::max);
        let grid = self.plan_grid(problem, fidelity, deepest)?;
        let mut out: Vec<ContactSolution> = Vec::with_capacity(approaches_mm.len());
        for &approach in approaches_mm {
            let frame = ContactProblem {
                approach_mm: approach,
                ..*problem
            };
            let solution = self.solve_on(&frame, fidelity, grid, out.last())?;
            out.push(solution);
        }
        Ok(out)
    }

    /// The gel's displacement over `region` at the solution's cell size: beyond the solver
    /// grid the gel still moves (the layer's bulge, the markers around the contact). A tiny
    /// contact's cell over a whole pad would need billions of cells (a 1 um sphere: 780 GB),
    /// so past `MAX_CELLS` a side the fields are made at a whole multiple of the cell, the
    /// pressure pooled into it (force kept); see `field_pooling`.
    pub fn fields_over(&mut self, solution: &ContactSolution, region: &Rect) -> GelFields {
        let rect = Rect {
            min: region.min.min(solution.grid.rect().min),
            max: region.max.max(solution.grid.rect().max),
        };
        let pool = field_pooling(solution.grid.cell_mm, &rect);
        let grid = Grid::covering(&rect, solution.grid.cell_mm * pool as f64);
        let embed = |src: &[f64]| {
            let mut out = vec![0.0; grid.len()];
            if pool == 1 {
                if let Some((oi, oj)) = solution.grid.offset_in(&grid) {
                    for j in 0..solution.grid.ny {
                        for i in 0..solution.grid.nx {
                            out[(j + oj) * grid.nx + i + oi] = src[j * solution.grid.nx + i];
                        }
                    }
                }
                return out;
            }
            // Each fine cell lies wholly inside one coarse cell (both lattices run through
            // the pad centre); the coarse cell holds the mean over its area.
            let share = 1.0 / (pool * pool) as f64;
            let coarse = |p: f64, origin: f64| ((p - origin) / grid.cell_mm + 0.5).floor();
            for j in 0..solution.grid.ny {
                for i in 0..solution.grid.nx {
                    let c = solution.grid.centre(i, j);
                    let (x, y) = (coarse(c.x, grid.origin_mm.x), coarse(c.y, grid.origin_mm.y));
                    if x >= 0.0 && y >= 0.0 && (x as usize) < grid.nx && (y as usize) < grid.ny {
                        out[y as usize * grid.nx + x as usize] +=
                            share * src[j * solution.grid.nx + i];
                    }
                }
            }
            out
        };
        match &solution.model {
            FieldModel::Embedded => GelFields {
                grid,
                normal_mm: embed(&solution.gel.normal_mm),
                lateral_x_mm: embed(&solution.gel.lateral_x_mm),
                lateral_y_mm: embed(&solution.gel.lateral_y_mm),
            },
            FieldModel::Hertz {
                hertz,
                centre_mm,
                gel_share,
            } => hertz::hertz_fields(&grid, hertz, *centre_mm, *gel_share, &solution.gel_spec),
            FieldModel::Kernel => {
                let pressure = embed(&solution.pressure_mpa);
                let gel_c = Elastic {
                    modulus_mpa: Some(solution.gel_spec.modulus_mpa),
                    poisson: solution.gel_spec.poisson,
                }
                .compliance();
                let layer = solution.fidelity == Fidelity::Layer;
                let k = self.kernels(&grid, &solution.gel_spec, layer);
                let object_c = solution.object.compliance();
                elastic::kernel_fields(k, &grid, &pressure, gel_c, object_c, false).0
            }
        }
    }
}

/// How many solver cells a side one cell of the gel's fields over `rect` pools: 1 unless the
/// solver's cell would need more than `MAX_CELLS` a side, and then enough for at most
/// `POOLED_CELLS` (a pad of 20 mm at 0.02 mm, finer than any sensor's pixels).
pub fn field_pooling(cell_mm: f64, rect: &Rect) -> usize {
    let across = rect.size().max_element() / cell_mm;
    if across.is_finite() && across > MAX_CELLS as f64 {
        (across / POOLED_CELLS as f64).ceil() as usize
    } else {
        1
    }
}

/// Cells a side of pooled fields (see `field_pooling`).
const POOLED_CELLS: usize = 1024;
