//! The GelSight renderer: GPU and CPU paths agree on a set of presses, a harder object leaves
//! a deeper and sharper imprint at equal travel, and the same seed gives the same bytes.

use glam::DVec2;
use image::RgbImage;
use tactex_core::hertz::Elastic;
use tactex_core::tactile::gel_glow::{ColourGlow, GelGlow, ScalarGlow};
use tactex_core::tactile::shading_table::{ShadingSample, ShadingTable};
use tactex_core::tactile::spec::TactileSpec;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::render::gel::{
    CpuRenderer, DeviceChoice, GelImageFields, GelRenderer, PressFrame, SensorOptics, Shading,
    image_fields, open_renderer, pad_rect,
};

fn press(
    surface: &ObjectSurface,
    modulus_mpa: Option<f64>,
    approach_mm: f64,
    fidelity: Fidelity,
    optics: &SensorOptics,
) -> GelImageFields {
    let spec = TactileSpec::gelsight_mini();
    let problem = ContactProblem {
        surface,
        object: Elastic {
            modulus_mpa,
            poisson: 0.45,
        },
        gel: spec.gel,
        pad: pad_rect(optics),
        approach_mm,
        cell_mm: None,
    };
    let mut solver = ContactSolver::new();
    let solution = solver.solve(&problem, fidelity).expect("solves");
    image_fields(&mut solver, &solution, &spec.gel, optics)
}

/// Presses spanning the fidelity levels, shapes and places (some near the pad's edge).
fn presses(optics: &SensorOptics) -> Vec<GelImageFields> {
    let sphere = |r: f64, x: f64, y: f64| ObjectSurface::Sphere {
        radius_mm: r,
        centre_mm: DVec2::new(x, y),
    };
    vec![
        GelImageFields::flat(optics.width, optics.height),
        press(
            &sphere(4.0, 0.0, 0.0),
            Some(0.5),
            0.8,
            Fidelity::Layer,
            optics,
        ),
        press(
            &sphere(2.35, 5.0, -3.0),
            None,
            0.6,
            Fidelity::Halfspace,
            optics,
        ),
        press(
            &sphere(6.0, -8.5, 6.0),
            Some(2.0),
            1.0,
            Fidelity::Hertz,
            optics,
        ),
        press(
            &ObjectSurface::Ellipsoid {
                semi_axes_mm: glam::DVec3::new(5.0, 3.0, 4.0),
                centre_mm: DVec2::new(-3.0, 2.0),
                yaw_rad: 0.0,
            },
            Some(0.2),
            1.2,
            Fidelity::Layer,
            optics,
        ),
        press(
            &ObjectSurface::Box {
                size_mm: DVec2::new(3.0, 2.0),
                centre_mm: DVec2::new(2.0, 3.0),
                yaw_rad: 0.4,
            },
            None,
            0.3,
            Fidelity::Rigid,
            optics,
        ),
    ]
}

/// A table fitted to the analytic lights (as a calibration would fit a real sensor).
fn fitted_table(optics: &SensorOptics) -> ShadingTable {
    let Shading::Lights(model) = optics.shading else {
        panic!("spec optics use lights")
    };
    let mut samples = Vec::new();
    for k in 0..6000u32 {
        let t = k as f32;
        let (gx, gy) = (
            (t * 0.618).fract() * 2.4 - 1.2,
            (t * 0.414).fract() * 2.4 - 1.2,
        );
        let (u, v) = (
            (t * 0.303).fract() * 2.0 - 1.0,
            (t * 0.777).fract() * 2.0 - 1.0,
        );
        let gain = model.gain_for_slope(gx as f64, gy as f64);
        let bg = [150.0 + 9.0 * v, 138.0 - 7.0 * u, 158.0 + 7.0 * u];
        samples.push(ShadingSample {
            gx,
            gy,
            u,
            v,
            change: std::array::from_fn(|c| bg[c] * (gain[c] as f32 - 1.0)),
        });
    }
    ShadingTable::fit(&samples, 10, 16, 1.5, 1e-2).unwrap()
}

/// The GPU path; its tests run in CI (lavapipe) and are ignored elsewhere.
fn gpu() -> Box<dyn GelRenderer + Send> {
    match open_renderer(DeviceChoice::Gpu) {
        Ok(choice) => choice.renderer,
        Err(e) => panic!("GPU renderer: {e}"),
    }
}

fn differences(a: &RgbImage, b: &RgbImage) -> ([f64; 3], [u8; 3]) {
    let mut sum = [0.0f64; 3];
    let mut max = [0u8; 3];
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            let d = p[c].abs_diff(q[c]);
            sum[c] += d as f64;
            max[c] = max[c].max(d);
        }
    }
    let n = (a.width() * a.height()) as f64;
    (sum.map(|s| s / n), max)
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn gpu_and_cpu_paths_agree_on_a_set_of_presses() {
    let mut gpu = gpu();
    let lights = SensorOptics::for_spec(&TactileSpec::gelsight_mini());
    let mut table = lights.clone();
    table.shading = Shading::Table(fitted_table(&lights));
    table.noise_sigma = 1.5;
    // A glow of every kind: unblurred and blurred colour terms, magnitude, indentation and
    // indented colour terms.
    let mut glowing = table.clone();
    glowing.glow = Some(GelGlow {
        colour: vec![
            ColourGlow {
                sigma_px: 0.0,
                mix: [[0.9, 0.05, 0.0], [0.0, 0.8, 0.1], [0.0, 0.0, 1.0]],
            },
            ColourGlow {
                sigma_px: 3.0,
                mix: [[0.5, 0.0, -0.1], [0.1, 0.4, 0.0], [0.0, 0.2, 0.6]],
            },
            ColourGlow {
                sigma_px: 27.0,
                mix: [[0.6, 0.1, 0.0], [0.0, 0.5, 0.1], [0.1, 0.0, 0.7]],
            },
        ],
        // 9 px at every pixel; 20 px computed on a grid of samples and interpolated.
        magnitude: vec![
            ScalarGlow {
                sigma_px: 9.0,
                colour: [0.3, 0.1, -0.2],
            },
            ScalarGlow {
                sigma_px: 20.0,
                colour: [0.4, -0.3, 0.2],
            },
        ],
        indentation: vec![ScalarGlow {
            sigma_px: 2.0,
            colour: [-23.5, -9.1, -6.5],
        }],
        indented_colour: vec![ColourGlow {
            sigma_px: 0.0,
            mix: [[0.3, 0.0, 0.0], [0.0, -0.2, 0.1], [0.0, 0.0, 0.2]],
        }],
    });
    // And a camera exposed 1.7 times as long: bright parts saturate on both paths alike.
    glowing.exposure = 1.7;
    let fields = presses(&lights);
    for optics in [&lights, &table, &glowing] {
        let frames: Vec<PressFrame> = fields
            .iter()
            .enumerate()
            .map(|(k, f)| PressFrame {
                fields: f,
                seed: 17 + k as u32,
            })
            .collect();
        let on_gpu = gpu.render_batch(optics, &frames).unwrap();
        let on_cpu = CpuRenderer.render_batch(optics, &frames).unwrap();
        for (k, (g, c)) in on_gpu.iter().zip(&on_cpu).enumerate() {
            let (mean, max) = differences(g, c);
            eprintln!(
                "press {k}: mean |gpu - cpu| {mean:.4?}, max {max:?} ({})",
                gpu.name()
            );
            // Both paths do the same arithmetic in f32; only the last rounding to a grey
            // level may differ.
            assert!(mean.iter().all(|m| *m <= 0.01), "press {k}: mean {mean:?}");
            assert!(max.iter().all(|m| *m <= 1), "press {k}: max {max:?}");
        }
    }
}

#[test]
fn twice_the_exposure_doubles_every_grey_level_until_it_saturates() {
    let mut once = SensorOptics::for_spec(&TactileSpec::gelsight_mini());
    once.noise_sigma = 0.0;
    let twice = SensorOptics {
        exposure: 2.0,
        ..once.clone()
    };
    let fields = &presses(&once)[1];
    let render = |o: &SensorOptics| CpuRenderer.render_one(o, &PressFrame { fields, seed: 3 });
    let (a, b) = (render(&once), render(&twice));
    let mut saturated = 0;
    for (p, q) in a.pixels().zip(b.pixels()) {
        for c in 0..3 {
            // A linear camera: round(2 v) against 2 round(v), within the rounding.
            let want = (2 * p[c] as i32).min(255);
            assert!((q[c] as i32 - want).abs() <= 1, "{} -> {}", p[c], q[c]);
            saturated += usize::from(q[c] == 255);
        }
    }
    assert!(
        saturated > 0,
        "the stock gel's bright half saturates at twice the exposure"
    );
}

#[test]
fn same_seed_same_bytes_and_seeds_change_only_the_noise() {
    let optics = SensorOptics::for_spec(&TactileSpec::gelsight_mini());
    let fields = &presses(&optics)[1];
    let render = |seed| CpuRenderer.render_one(&optics, &PressFrame { fields, seed });
    let (a, b, c) = (render(5), render(5), render(6));
    assert_eq!(a.as_raw(), b.as_raw());
    let (mean, max) = differences(&a, &c);
    // Noise sigma 0.5: two independent draws differ by ~0.56 on average after rounding.
    assert!(mean.iter().all(|m| *m > 0.1 && *m < 1.0), "{mean:?}");
    assert!(max.iter().all(|m| *m <= 4), "{max:?}");
}

/// Grey level at every pixel, and the largest grey-level gradient away from the marker dots.
fn imprint(image: &RgbImage, flat: &RgbImage) -> (f64, f64) {
    let grey = |img: &RgbImage, x: u32, y: u32| {
        let p = img.get_pixel(x, y);
        (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0
    };
    let (w, h) = image.dimensions();
    let mut change = 0.0;
    let mut sharpest = 0.0f64;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            change += (grey(image, x, y) - grey(flat, x, y)).abs();
            let gx = grey(image, x + 1, y) - grey(image, x - 1, y);
            let gy = grey(image, x, y + 1) - grey(image, x, y - 1);
            let fx = grey(flat, x + 1, y) - grey(flat, x - 1, y);
            let fy = grey(flat, x, y + 1) - grey(flat, x, y - 1);
            // Only where the flat frame is smooth: marker rims are sharp in both.
            if fx.hypot(fy) < 3.0 {
                sharpest = sharpest.max(gx.hypot(gy));
            }
        }
    }
    (change, sharpest)
}

#[test]
fn harder_object_leaves_a_deeper_sharper_imprint_at_equal_travel() {
    let mut optics = SensorOptics::for_spec(&TactileSpec::gelsight_mini());
    optics.noise_sigma = 0.0;
    let sphere = ObjectSurface::Sphere {
        radius_mm: 5.0,
        centre_mm: DVec2::ZERO,
    };
    let flat_fields = GelImageFields::flat(optics.width, optics.height);
    let flat = CpuRenderer.render_one(
        &optics,
        &PressFrame {
            fields: &flat_fields,
            seed: 1,
        },
    );
    let mut last: Option<(f32, f64, f64)> = None;
    // Soft fruit flesh to near-rigid, all at 1 mm of travel.
    for modulus in [0.05, 0.3, 2.0, 50.0] {
        let fields = press(&sphere, Some(modulus), 1.0, Fidelity::Layer, &optics);
        let depth = fields.normal_mm.iter().cloned().fold(0.0, f32::max);
        let image = CpuRenderer.render_one(
            &optics,
            &PressFrame {
                fields: &fields,
                seed: 1,
            },
        );
        let (change, sharpest) = imprint(&image, &flat);
        eprintln!(
            "E {modulus} MPa: gel depth {depth:.3} mm, change {change:.0}, sharpest {sharpest:.1}"
        );
        if let Some((d, c, s)) = last {
            assert!(
                depth > d && change > c && sharpest > s,
                "E {modulus}: not deeper and sharper"
            );
        }
        last = Some((depth, change, sharpest));
    }
}
