//! One press of the gel against an object, and what makes one invalid.

use super::grid::Rect;
use super::surface::ObjectSurface;
use tactex_core::hertz::Elastic;
use tactex_core::tactile::spec::GelSpec;

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

pub(super) fn invalid(field: &str, message: impl Into<String>) -> ContactError {
    ContactError {
        field: field.into(),
        message: message.into(),
    }
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

pub(super) fn validate(problem: &ContactProblem) -> Result<(), ContactError> {
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
