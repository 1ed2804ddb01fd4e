//! The contact solver's gel fields at the sensor's pixel centres: the fields are taken over
//! the solver grid grown by two gel thicknesses (the layer's bulge and the marker motion
//! around a contact die out within that), clipped to the pad, then resampled bilinearly;
//! beyond that the gel is taken as undisturbed.

use super::{GelImageFields, SensorOptics};
use crate::elastic::{ContactSolution, ContactSolver, GelFields, Rect};
use glam::DVec2;
use tactex_core::tactile_spec::GelSpec;

/// Pad coordinates (mm) of pixel centre (i, j): the pad is centred on the frame, x along
/// columns and y along rows.
pub fn pixel_centre_mm(optics: &SensorOptics, i: f64, j: f64) -> DVec2 {
    DVec2::new(
        (i + 0.5 - optics.width as f64 / 2.0) * optics.mm_per_px,
        (j + 0.5 - optics.height as f64 / 2.0) * optics.mm_per_px,
    )
}

/// The pad the frame sees (mm).
pub fn pad_rect(optics: &SensorOptics) -> Rect {
    Rect::centred(DVec2::new(optics.width as f64, optics.height as f64) * optics.mm_per_px / 2.0)
}

/// Bilinear sample with zero beyond the grid's outermost cell centres.
fn sample_or_zero(fields: &GelFields, field: &[f64], p: DVec2) -> f64 {
    let g = &fields.grid;
    let q = (p - g.origin_mm) / g.cell_mm - DVec2::splat(0.5);
    let (i0, j0) = (q.x.floor(), q.y.floor());
    let (fx, fy) = (q.x - i0, q.y - j0);
    let at = |i: f64, j: f64| {
        if i < 0.0 || j < 0.0 || i >= g.nx as f64 || j >= g.ny as f64 {
            0.0
        } else {
            field[j as usize * g.nx + i as usize]
        }
    };
    (at(i0, j0) * (1.0 - fx) + at(i0 + 1.0, j0) * fx) * (1.0 - fy)
        + (at(i0, j0 + 1.0) * (1.0 - fx) + at(i0 + 1.0, j0 + 1.0) * fx) * fy
}

/// The solution's gel fields at every pixel of `optics`' frame.
pub fn image_fields(
    solver: &mut ContactSolver,
    solution: &ContactSolution,
    gel: &GelSpec,
    optics: &SensorOptics,
) -> GelImageFields {
    let pad = pad_rect(optics);
    let mut out = GelImageFields::flat(optics.width, optics.height);
    if solution.grid.is_empty() || solution.force_n <= 0.0 && solution.gel_max_indentation_mm <= 0.0
    {
        return out;
    }
    let region = solution
        .grid
        .rect()
        .grown(2.0 * gel.thickness_mm)
        .intersect(&pad)
        .unwrap_or(pad);
    let fields = solver.fields_over(solution, &region);
    let (w, h) = (optics.width as usize, optics.height as usize);
    for j in 0..h {
        for i in 0..w {
            let p = pixel_centre_mm(optics, i as f64, j as f64);
            let k = j * w + i;
            out.normal_mm[k] = sample_or_zero(&fields, &fields.normal_mm, p) as f32;
            out.lateral_x_mm[k] = sample_or_zero(&fields, &fields.lateral_x_mm, p) as f32;
            out.lateral_y_mm[k] = sample_or_zero(&fields, &fields.lateral_y_mm, p) as f32;
        }
    }
    out
}
