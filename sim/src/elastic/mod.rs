//! Elastic soft contact of the GelSight gel with an object: one interface, four fidelity
//! levels that trade speed for accuracy (see DESIGN.md, "fidelity levels").
//!
//! * `rigid`: the object's heightmap clipped at the gel surface and smoothed, the gel taking
//!   the whole approach (what TACTO, Taxim and FOTS do); pressure from a Winkler bed
//!   p = E_gel w / h. Hardness-blind: the baseline to beat.
//! * `hertz`: the equivalent sphere at the lowest point, Hertz pressure, each body taking its
//!   compliance share of the approach.
//! * `halfspace`: frictionless contact of any shape, both bodies half-spaces of composite
//!   compliance, solved by Polonsky-Keer conjugate gradient with DC-FFT.
//! * `layer`: as `halfspace` with the gel a layer of finite thickness bonded to the rigid
//!   acrylic, which stiffens it and makes its surface move outward around the contact.
//!
//! Units: mm, MPa, N. The solver grid covers only where the object dips below the gel
//! surface plus a margin; `fields_over` extends the gel's displacement to any part of the pad.

pub mod convolution;
pub mod grid;
pub mod hertz_level;
pub mod influence;
pub mod kernels;
pub mod polonsky_keer;
pub mod surface;
mod warm_start;

pub use grid::{Grid, Rect};
pub use surface::ObjectSurface;

use glam::DVec2;
use influence::{LayerCorrection, half_space_lateral_ratio};
use kernels::{GridKernels, KernelKey};
use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;
use tactex_core::hertz::{Elastic, Hertz};
use tactex_core::tactile::spec::GelSpec;

/// How much physics a contact solve models.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Fidelity {
    Rigid,
    Hertz,
    Halfspace,
    Layer,
}

impl Fidelity {
    pub const ALL: [Fidelity; 4] = [
        Fidelity::Rigid,
        Fidelity::Hertz,
        Fidelity::Halfspace,
        Fidelity::Layer,
    ];

    pub fn name(&self) -> &'static str {
        match self {
            Fidelity::Rigid => "rigid",
            Fidelity::Hertz => "hertz",
            Fidelity::Halfspace => "halfspace",
            Fidelity::Layer => "layer",
        }
    }
}

impl fmt::Display for Fidelity {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for Fidelity {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

impl FromStr for Fidelity {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Fidelity::ALL
            .into_iter()
            .find(|f| f.name() == s.trim().to_ascii_lowercase())
            .ok_or_else(|| format!("unknown fidelity {s:?} (use rigid, hertz, halfspace or layer)"))
    }
}

/// Smoothing of the `rigid` level's imprint (mm), of the order the peers' Gaussian kernels.
pub const RIGID_SMOOTHING_MM: f64 = 0.25;
/// Default solver cells across the narrower side of the region the object dips into.
pub const DEFAULT_CELLS_ACROSS: f64 = 40.0;
/// The default grid never exceeds this many cells per side (it coarsens instead).
pub const DEFAULT_MAX_CELLS: usize = 256;
/// A user-chosen cell may not give more than this many cells per side.
pub const MAX_CELLS: usize = 2048;

/// One press of the gel against an object.
#[derive(Clone, Copy, Debug)]
pub struct ContactProblem<'a> {
    pub surface: &'a ObjectSurface,
    pub object: Elastic,
    pub gel: GelSpec,
    /// The gel pad (pad frame, mm).
    pub pad: Rect,
    /// Total approach of gel and object past first touch (mm): the sensor's travel.
    pub approach_mm: f64,
    /// Solver cell side (mm); None picks one from the contact's size.
    pub cell_mm: Option<f64>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ContactError {
    pub field: String,
    pub message: String,
}

fn invalid(field: &str, message: impl Into<String>) -> ContactError {
    ContactError {
        field: field.into(),
        message: message.into(),
    }
}

/// How a solution extends its gel fields beyond its grid.
#[derive(Clone, Debug)]
enum FieldModel {
    /// Nothing outside the grid (no contact, or the rigid imprint).
    Embedded,
    Hertz {
        hertz: Hertz,
        centre_mm: DVec2,
        gel_share: f64,
    },
    /// Convolution of the pressure with the influence kernels.
    Kernel,
}

/// The gel's surface displacement over a grid (mm; normal = into the gel).
#[derive(Clone, Debug)]
pub struct GelFields {
    pub grid: Grid,
    pub normal_mm: Vec<f64>,
    pub lateral_x_mm: Vec<f64>,
    pub lateral_y_mm: Vec<f64>,
}

/// The result of one contact solve.
#[derive(Clone, Debug)]
pub struct ContactSolution {
    pub fidelity: Fidelity,
    pub approach_mm: f64,
    pub grid: Grid,
    pub pressure_mpa: Vec<f64>,
    pub gel: GelFields,
    pub force_n: f64,
    pub contact_area_mm2: f64,
    /// sqrt(area / pi): the radius of the circle of the same area.
    pub contact_radius_mm: f64,
    pub max_pressure_mpa: f64,
    pub gel_max_indentation_mm: f64,
    pub object_max_indentation_mm: f64,
    pub iterations: usize,
    pub residual: f64,
    pub warnings: Vec<String>,
    model: FieldModel,
    gel_spec: GelSpec,
    object: Elastic,
}

/// Solves contacts, caching FFT plans and kernel spectra between calls (a press sequence
/// reuses them; the layer tables behind the kernels are shared by the whole process).
#[derive(Default)]
pub struct ContactSolver {
    pub settings: polonsky_keer::Settings,
    kernels: HashMap<KernelKey, GridKernels>,
}

fn finite_in(field: &str, v: f64, lo: f64, hi: f64) -> Result<(), ContactError> {
    if v.is_finite() && v >= lo && v <= hi {
        Ok(())
    } else {
        Err(invalid(
            field,
            format!("must be a finite number in [{lo}, {hi}], got {v}"),
        ))
    }
}

fn validate(problem: &ContactProblem) -> Result<(), ContactError> {
    finite_in("approach_mm", problem.approach_mm, 0.0, 1e6)?;
    if let Some(cell) = problem.cell_mm
        && !(cell.is_finite() && cell > 0.0)
    {
        return Err(invalid(
            "cell_mm",
            format!("must be a positive finite number, got {cell}"),
        ));
    }
    let gel = &problem.gel;
    if !(gel.modulus_mpa.is_finite() && gel.modulus_mpa > 0.0) {
        return Err(invalid(
            "gel.modulus_mpa",
            format!("must be positive and finite, got {}", gel.modulus_mpa),
        ));
    }
    finite_in("gel.poisson", gel.poisson, 0.0, 0.4999)?;
    if !(gel.thickness_mm.is_finite() && gel.thickness_mm > 0.0) {
        return Err(invalid(
            "gel.thickness_mm",
            format!("must be positive and finite, got {}", gel.thickness_mm),
        ));
    }
    if let Some(e) = problem.object.modulus_mpa
        && !(e.is_finite() && e > 0.0)
    {
        return Err(invalid(
            "object.modulus_mpa",
            format!("must be positive and finite, got {e}"),
        ));
    }
    finite_in("object.poisson", problem.object.poisson, 0.0, 0.5)?;
    let pad = problem.pad.size();
    if !(pad.x.is_finite() && pad.y.is_finite() && pad.x > 0.0 && pad.y > 0.0) {
        return Err(invalid("pad", "must have a positive finite size"));
    }
    problem
        .surface
        .validate()
        .map_err(|m| invalid("surface", m))
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

/// Separable Gaussian blur with zero padding.
fn gaussian_blur(field: &[f64], nx: usize, ny: usize, sigma_cells: f64) -> Vec<f64> {
    if sigma_cells < 1e-3 {
        return field.to_vec();
    }
    let radius = ((3.0 * sigma_cells).ceil() as usize).min(nx.max(ny));
    let taps: Vec<f64> = (0..=radius)
        .map(|k| (-(k as f64).powi(2) / (2.0 * sigma_cells * sigma_cells)).exp())
        .collect();
    let norm = taps[0] + 2.0 * taps[1..].iter().sum::<f64>();
    let blur = |src: &[f64], len: usize, stride: usize, count: usize, step: usize| {
        let mut out = vec![0.0; src.len()];
        for line in 0..count {
            for i in 0..len {
                let mut acc = 0.0;
                for (k, w) in taps.iter().enumerate() {
                    if i >= k {
                        acc += w * src[line * step + (i - k) * stride];
                    }
                    if k > 0 && i + k < len {
                        acc += w * src[line * step + (i + k) * stride];
                    }
                }
                out[line * step + i * stride] = acc / norm;
            }
        }
        out
    };
    let rows = blur(field, nx, 1, ny, nx);
    blur(&rows, ny, nx, nx, 1)
}

impl ContactSolver {
    pub fn new() -> Self {
        Self::default()
    }

    /// The kernel spectra of `grid` for the half-space or (`layer`) the bonded layer.
    fn kernels(&mut self, grid: &Grid, gel: &GelSpec, layer: bool) -> &mut GridKernels {
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
            return Ok(self.no_contact(problem, fidelity, warnings));
        };
        if problem.approach_mm == 0.0 {
            return Ok(self.no_contact(problem, fidelity, warnings));
        }
        let approach = problem.approach_mm;
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
            Fidelity::Rigid => self.rigid(problem, grid, &separation),
            Fidelity::Hertz => self.hertz(problem, grid, &separation, &mut warnings),
            Fidelity::Halfspace | Fidelity::Layer => {
                self.elastic(problem, fidelity, grid, &separation, warm, &mut warnings)
            }
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

    fn base(
        &self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        grid: Grid,
        pressure: Vec<f64>,
        gel: GelFields,
        model: FieldModel,
    ) -> ContactSolution {
        let area = grid.cell_area_mm2();
        let force: f64 = pressure.iter().sum::<f64>() * area;
        let contact_area = pressure.iter().filter(|p| **p > 0.0).count() as f64 * area;
        ContactSolution {
            fidelity,
            approach_mm: problem.approach_mm,
            force_n: force,
            contact_area_mm2: contact_area,
            contact_radius_mm: (contact_area / std::f64::consts::PI).sqrt(),
            max_pressure_mpa: pressure.iter().copied().fold(0.0, f64::max),
            gel_max_indentation_mm: gel.normal_mm.iter().copied().fold(0.0, f64::max),
            object_max_indentation_mm: 0.0,
            iterations: 0,
            residual: 0.0,
            warnings: Vec::new(),
            grid,
            pressure_mpa: pressure,
            gel,
            model,
            gel_spec: problem.gel,
            object: problem.object,
        }
    }

    fn no_contact(
        &self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        warnings: Vec<String>,
    ) -> ContactSolution {
        let grid = Grid {
            origin_mm: DVec2::ZERO,
            cell_mm: problem.cell_mm.unwrap_or(0.1),
            nx: 1,
            ny: 1,
        };
        let gel = GelFields {
            grid,
            normal_mm: vec![0.0],
            lateral_x_mm: vec![0.0],
            lateral_y_mm: vec![0.0],
        };
        let mut s = self.base(
            problem,
            fidelity,
            grid,
            vec![0.0],
            gel,
            FieldModel::Embedded,
        );
        s.warnings = warnings;
        s
    }

    fn rigid(&self, problem: &ContactProblem, grid: Grid, separation: &[f64]) -> ContactSolution {
        let imprint: Vec<f64> = separation
            .iter()
            .map(|s| if s.is_finite() { (-s).max(0.0) } else { 0.0 })
            .collect();
        let normal = gaussian_blur(
            &imprint,
            grid.nx,
            grid.ny,
            RIGID_SMOOTHING_MM / grid.cell_mm,
        );
        let stiffness = problem.gel.modulus_mpa / problem.gel.thickness_mm;
        let pressure: Vec<f64> = imprint.iter().map(|w| stiffness * w).collect();
        let zeros = vec![0.0; grid.len()];
        let gel = GelFields {
            grid,
            normal_mm: normal,
            lateral_x_mm: zeros.clone(),
            lateral_y_mm: zeros,
        };
        self.base(
            problem,
            Fidelity::Rigid,
            grid,
            pressure,
            gel,
            FieldModel::Embedded,
        )
    }

    fn hertz(
        &self,
        problem: &ContactProblem,
        grid: Grid,
        separation: &[f64],
        warnings: &mut Vec<String>,
    ) -> ContactSolution {
        let heights: Vec<f64> = separation.iter().map(|s| s + problem.approach_mm).collect();
        let sphere = hertz_level::equivalent_sphere(&grid, &heights, problem.approach_mm);
        let mut sphere = sphere.unwrap_or(hertz_level::EquivalentSphere {
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
        let mut s = self.base(problem, Fidelity::Hertz, grid, pressure, fields, model);
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

    fn elastic(
        &mut self,
        problem: &ContactProblem,
        fidelity: Fidelity,
        grid: Grid,
        separation: &[f64],
        warm: Option<&ContactSolution>,
        warnings: &mut Vec<String>,
    ) -> ContactSolution {
        let layer = fidelity == Fidelity::Layer;
        let gel_c = Elastic {
            modulus_mpa: Some(problem.gel.modulus_mpa),
            poisson: problem.gel.poisson,
        }
        .compliance();
        let object_c = problem.object.compliance();
        let settings = self.settings;
        let k = self.kernels(&grid, &problem.gel, layer);
        // Cold start: the overlap over one cell's self-compliance, spread over the cells
        // across, so that the contact set starts as a superset and shrinks.
        let self_c = (gel_c + object_c)
            * influence::love_normal(0.0, 0.0, grid.cell_mm / 2.0)
            * (grid.nx.max(grid.ny) as f64);
        let cold = separation.iter().map(|s| {
            if s.is_finite() {
                (-s).max(0.0) / self_c
            } else {
                0.0
            }
        });
        // Warm start: the previous frame of a press grown the way a Hertz contact grows;
        // the cold guess when it had no contact to grow.
        let grown = warm
            .filter(|w| w.grid == grid && w.approach_mm > 0.0)
            .and_then(|w| {
                let ratio = problem.approach_mm / w.approach_mm;
                warm_start::hertz_grown(&grid, &w.pressure_mpa, ratio)
            });
        let start: Vec<f64> = grown.unwrap_or_else(|| cold.collect());
        let (conv, weighted) = k.weighted(gel_c, object_c);
        let outcome = polonsky_keer::solve(
            conv,
            &weighted.total_normal,
            &weighted.total_normal_preconditioner,
            separation,
            problem.approach_mm,
            start,
            settings,
        );
        if !outcome.converged {
            warnings.push(format!(
                "contact solver stopped after {} iterations without converging (residual {:.2e} of the approach)",
                outcome.iterations, outcome.residual
            ));
        }
        let p = outcome.pressure;
        // Pressure on the grid's rim, away from the pad edge, means the margin was too small.
        let r = grid.rect();
        let pad = problem.pad;
        let cut = [
            r.min.x <= pad.min.x + grid.cell_mm,
            r.max.x >= pad.max.x - grid.cell_mm,
            r.min.y <= pad.min.y + grid.cell_mm,
            r.max.y >= pad.max.y - grid.cell_mm,
        ];
        let on_rim = (0..grid.len()).any(|q| {
            let (i, j) = (q % grid.nx, q / grid.nx);
            p[q] > 0.0
                && ((i == 0 && !cut[0])
                    || (i + 1 == grid.nx && !cut[1])
                    || (j == 0 && !cut[2])
                    || (j + 1 == grid.ny && !cut[3]))
        });
        if on_rim {
            warnings.push("the contact reached the edge of the solver grid".into());
        }
        let (gel, object_max) = kernel_fields(k, &grid, &p, gel_c, object_c, true);
        let mut s = self.base(problem, fidelity, grid, p, gel, FieldModel::Kernel);
        s.object_max_indentation_mm = object_max;
        s.iterations = outcome.iterations;
        s.residual = outcome.residual;
        s
    }

    /// The gel's displacement over `region` at the solution's cell size: beyond the solver
    /// grid the gel still moves (the layer's bulge, the markers around the contact).
    pub fn fields_over(&mut self, solution: &ContactSolution, region: &Rect) -> GelFields {
        let rect = Rect {
            min: region.min.min(solution.grid.rect().min),
            max: region.max.max(solution.grid.rect().max),
        };
        let grid = Grid::covering(&rect, solution.grid.cell_mm);
        let embed = |src: &[f64]| {
            let mut out = vec![0.0; grid.len()];
            if let Some((oi, oj)) = solution.grid.offset_in(&grid) {
                for j in 0..solution.grid.ny {
                    for i in 0..solution.grid.nx {
                        out[(j + oj) * grid.nx + i + oi] = src[j * solution.grid.nx + i];
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
            } => hertz_fields(&grid, hertz, *centre_mm, *gel_share, &solution.gel_spec),
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
                kernel_fields(k, &grid, &pressure, gel_c, object_c, false).0
            }
        }
    }
}

fn hertz_fields(
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
            let ur = hertz_level::gel_radial_mm(hertz, r, gel_c, t_inf);
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

/// Gel normal and lateral fields from a pressure field by convolution with the kernels,
/// and (when `object_depth`) the object's largest indentation.
fn kernel_fields(
    k: &mut GridKernels,
    grid: &Grid,
    pressure: &[f64],
    gel_c: f64,
    object_c: f64,
    object_depth: bool,
) -> (GelFields, f64) {
    let n = grid.len();
    let (conv, w) = k.weighted(gel_c, object_c);
    let spectrum = conv.spectrum(pressure);
    let (mut normal, mut lx, mut ly) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    conv.apply(&spectrum, &w.gel_normal, &mut normal);
    conv.apply(&spectrum, &w.gel_lateral[0], &mut lx);
    conv.apply(&spectrum, &w.gel_lateral[1], &mut ly);
    let object_max = match &w.object_normal {
        Some(kernel) if object_depth => {
            let mut object = vec![0.0; n];
            conv.apply(&spectrum, kernel, &mut object);
            object.into_iter().fold(0.0, f64::max)
        }
        _ => 0.0,
    };
    (
        GelFields {
            grid: *grid,
            normal_mm: normal,
            lateral_x_mm: lx,
            lateral_y_mm: ly,
        },
        object_max,
    )
}
