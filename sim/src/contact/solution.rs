//! What a contact solve returns: pressure, the gel's displacement fields, the contact's
//! figures, and how the fields extend beyond the solver grid.

use super::fidelity::Fidelity;
use super::grid::Grid;
use super::problem::ContactProblem;
use glam::DVec2;
use tactex_core::hertz::{Elastic, Hertz};
use tactex_core::tactile::spec::GelSpec;

/// How a solution extends its gel fields beyond its grid.
#[derive(Clone, Debug)]
pub(super) enum FieldModel {
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
    pub(super) model: FieldModel,
    pub(super) gel_spec: GelSpec,
    pub(super) object: Elastic,
}

impl ContactSolution {
    /// A solution's figures from its pressure and gel fields (grid sums).
    pub(super) fn assemble(
        problem: &ContactProblem,
        fidelity: Fidelity,
        grid: Grid,
        pressure: Vec<f64>,
        gel: GelFields,
        model: FieldModel,
    ) -> Self {
        let area = grid.cell_area_mm2();
        let force: f64 = pressure.iter().sum::<f64>() * area;
        let contact_area = pressure.iter().filter(|p| **p > 0.0).count() as f64 * area;
        Self {
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

    /// No contact: zero fields on a single cell, with the reasons in `warnings`.
    pub(super) fn no_contact(
        problem: &ContactProblem,
        fidelity: Fidelity,
        warnings: Vec<String>,
    ) -> Self {
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
        let mut s = Self::assemble(
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
}
