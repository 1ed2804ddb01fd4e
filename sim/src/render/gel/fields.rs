//! The contact solver's gel fields at the sensor's pixel centres: the fields are taken over
//! the solver grid grown by two gel thicknesses (the layer's bulge and the marker motion
//! around a contact die out within that), clipped to the pad, then resampled bilinearly;
//! beyond that the gel is taken as undisturbed.

use super::{GelImageFields, SensorOptics};
use crate::contact::{ContactSolution, ContactSolver, Rect};
use glam::DVec2;
use tactex_core::tactile::spec::GelSpec;

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

/// Per pixel along one axis: the grid index left of it and the interpolation weight of each
/// neighbour, zero where the neighbour is off the grid. Bilinear sampling is separable, so
/// the weights are computed once per column and per row, not per pixel.
fn axis_weights(
    pixels: u32,
    first_centre_mm: f64,
    step_mm: f64,
    grid_origin: f64,
    cell: f64,
    cells: usize,
) -> Vec<(usize, f64, f64)> {
    (0..pixels)
        .map(|i| {
            let q = (first_centre_mm + i as f64 * step_mm - grid_origin) / cell - 0.5;
            let i0 = q.floor();
            let f = q - i0;
            let inside = |k: f64| k >= 0.0 && k < cells as f64;
            let (w0, w1) = (
                if inside(i0) { 1.0 - f } else { 0.0 },
                if inside(i0 + 1.0) { f } else { 0.0 },
            );
            (i0.max(0.0) as usize, w0, w1)
        })
        .collect()
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
    let g = &fields.grid;
    let first = pixel_centre_mm(optics, 0.0, 0.0);
    let step = optics.mm_per_px;
    let cols = axis_weights(optics.width, first.x, step, g.origin_mm.x, g.cell_mm, g.nx);
    let rows = axis_weights(optics.height, first.y, step, g.origin_mm.y, g.cell_mm, g.ny);
    let w = optics.width as usize;
    let sources = [
        &fields.normal_mm,
        &fields.lateral_x_mm,
        &fields.lateral_y_mm,
    ];
    let targets = [
        &mut out.normal_mm,
        &mut out.lateral_x_mm,
        &mut out.lateral_y_mm,
    ];
    // Separable in two passes: each grid row interpolated along x to the pixel columns
    // (a gather, ny rows), then each pixel row a weighted sum of two such rows (plain
    // vector arithmetic). Per pixel the arithmetic is the one-pass formula's, so the bytes
    // are too; it is 5-10x faster than gathering four neighbours per pixel.
    let mut along_x = vec![0.0f64; g.ny * w];
    for (src, dst) in sources.into_iter().zip(targets) {
        for (r, expanded) in src.chunks_exact(g.nx).zip(along_x.chunks_exact_mut(w)) {
            for (x, &(i0, wx0, wx1)) in expanded.iter_mut().zip(&cols) {
                let i1 = (i0 + 1).min(g.nx - 1);
                *x = if wx0 == 0.0 && wx1 == 0.0 {
                    0.0
                } else {
                    r[i0] * wx0 + r[i1] * wx1
                };
            }
        }
        for (row, &(j0, wy0, wy1)) in dst.chunks_exact_mut(w).zip(&rows) {
            if wy0 == 0.0 && wy1 == 0.0 {
                continue;
            }
            let j1 = (j0 + 1).min(g.ny - 1);
            let (x0, x1) = (
                &along_x[j0 * w..(j0 + 1) * w],
                &along_x[j1 * w..(j1 + 1) * w],
            );
            for ((v, a), b) in row.iter_mut().zip(x0).zip(x1) {
                *v = (a * wy0 + b * wy1) as f32;
            }
        }
    }
    out
}
