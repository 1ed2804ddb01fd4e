//! Criterion timings of the pieces of one soft-contact frame: a DC-FFT convolution on the
//! press's grid, the contact solve at `halfspace` and `layer`, the gel fields at pixel
//! resolution, and the CPU render. They back the per-stage figures of `tactex bench render`
//! with criterion's statistics, and the convolution time is what a GPU offload of one
//! convolution per solver step would have to beat (README, "GelSight rendering").
//!
//! `cargo bench -p tactex-sim --bench contact_frame`

use criterion::{Criterion, criterion_group, criterion_main};
use glam::DVec2;
use std::hint::black_box;
use tactex_core::hertz::Elastic;
use tactex_core::tactile::spec::TactileSpec;
use tactex_sim::contact::kernels::GridKernels;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::render::gel::{CpuRenderer, PressFrame, SensorOptics, image_fields, pad_rect};

/// The render bench's press: a 10 mm ball of 1 MPa, 1 mm past first touch.
fn bench_frame(c: &mut Criterion) {
    let spec = TactileSpec::gelsight_mini();
    let optics = SensorOptics::for_spec(&spec);
    let surface = ObjectSurface::Sphere {
        radius_mm: 10.0,
        centre_mm: DVec2::ZERO,
    };
    let problem = ContactProblem {
        surface: &surface,
        object: Elastic {
            modulus_mpa: Some(1.0),
            poisson: 0.45,
        },
        gel: spec.gel,
        pad: pad_rect(&optics),
        approach_mm: 1.0,
        cell_mm: None,
    };
    let mut solver = ContactSolver::new();
    let pressed = solver
        .solve(&problem, Fidelity::Layer)
        .expect("the bench press solves");
    let grid = pressed.grid;

    let mut kernels = GridKernels::new(&grid, spec.gel.poisson, None);
    let (conv, weighted) = kernels.weighted(1.0, 0.5);
    let field: Vec<f64> = pressed.pressure_mpa.clone();
    let mut out = vec![0.0; field.len()];
    let name = format!("dc_fft_convolution/{}x{}", grid.nx, grid.ny);
    c.bench_function(&name, |b| {
        b.iter(|| conv.convolve(black_box(&field), &weighted.total_normal, &mut out))
    });

    for fidelity in [Fidelity::Halfspace, Fidelity::Layer] {
        // Kernels built once outside the timing, as within a press sequence.
        solver
            .solve(&problem, fidelity)
            .expect("the bench press solves");
        c.bench_function(&format!("contact_solve/{fidelity}"), |b| {
            b.iter(|| solver.solve(black_box(&problem), fidelity).expect("solves"))
        });
    }

    c.bench_function("gel_fields_at_pixels/layer", |b| {
        b.iter(|| image_fields(&mut solver, black_box(&pressed), &spec.gel, &optics))
    });

    let fields = image_fields(&mut solver, &pressed, &spec.gel, &optics);
    let frame = PressFrame {
        fields: &fields,
        seed: 7,
    };
    c.bench_function("cpu_render/320x240", |b| {
        b.iter(|| CpuRenderer.render_one(&optics, black_box(&frame)))
    });
}

criterion_group!(benches, bench_frame);
criterion_main!(benches);
