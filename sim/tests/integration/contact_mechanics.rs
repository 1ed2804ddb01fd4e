//! The elastic contact solver against contact-mechanics theory: Hertz and Sneddon for
//! spheres, the half-space limit of a thick layer, and the stiffening of a thin one.

use glam::DVec2;
use tactex_core::hertz::{Elastic, Hertz, contact_modulus_mpa};
use tactex_core::tactile::spec::GelSpec;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface, Rect};

fn gel(thickness_mm: f64) -> GelSpec {
    GelSpec {
        modulus_mpa: 0.3,
        poisson: 0.49,
        thickness_mm,
    }
}

fn object(modulus_mpa: Option<f64>) -> Elastic {
    Elastic {
        modulus_mpa,
        poisson: 0.4,
    }
}

fn pad() -> Rect {
    Rect::centred(DVec2::new(60.0, 60.0))
}

/// Exact frictionless indentation by a sphere (not Hertz's paraboloid): Sneddon 1965,
/// delta = (a/2) ln((R+a)/(R-a)), F = (E*/2) [(a^2 + R^2) ln((R+a)/(R-a)) - 2 a R].
fn sneddon(radius: f64, approach: f64, e_star: f64) -> (f64, f64) {
    let delta = |a: f64| a / 2.0 * ((radius + a) / (radius - a)).ln();
    let (mut lo, mut hi) = (0.0, radius * (1.0 - 1e-12));
    for _ in 0..200 {
        let mid = (lo + hi) / 2.0;
        if delta(mid) < approach {
            lo = mid
        } else {
            hi = mid
        }
    }
    let a = (lo + hi) / 2.0;
    let l = ((radius + a) / (radius - a)).ln();
    (
        a,
        e_star / 2.0 * ((a * a + radius * radius) * l - 2.0 * a * radius),
    )
}

fn sphere(radius_mm: f64) -> ObjectSurface {
    ObjectSurface::Sphere {
        radius_mm,
        centre_mm: DVec2::ZERO,
    }
}

fn problem<'a>(
    surface: &'a ObjectSurface,
    e: Option<f64>,
    thickness: f64,
    depth: f64,
) -> ContactProblem<'a> {
    ContactProblem {
        surface,
        object: object(e),
        gel: gel(thickness),
        pad: pad(),
        approach_mm: depth,
        cell_mm: None,
    }
}

fn e_star(e: Option<f64>) -> f64 {
    contact_modulus_mpa(
        Elastic {
            modulus_mpa: Some(0.3),
            poisson: 0.49,
        },
        object(e),
    )
}

#[test]
fn halfspace_sphere_matches_sneddon_and_hertz_at_the_default_grid() {
    let mut solver = ContactSolver::new();
    let (mut worst_force, mut worst_radius) = (0.0f64, 0.0f64);
    for radius in [2.35, 5.0, 10.0, 25.0] {
        for depth in [0.1, 0.3, 0.7, 1.5] {
            for e in [Some(0.1), Some(1.0), Some(10.0), None] {
                let surface = sphere(radius);
                let s = solver
                    .solve(&problem(&surface, e, 4.0, depth), Fidelity::Halfspace)
                    .unwrap();
                let case = format!("R {radius} mm, depth {depth} mm, E {e:?}");
                assert!(s.warnings.is_empty(), "{case}: {:?}", s.warnings);
                let (a, f) = sneddon(radius, depth, e_star(e));
                worst_force = worst_force.max((s.force_n / f - 1.0).abs());
                worst_radius = worst_radius.max((s.contact_radius_mm / a - 1.0).abs());
                assert!(
                    (s.force_n / f - 1.0).abs() < 0.02,
                    "{case}: force {} vs {f}",
                    s.force_n
                );
                assert!(
                    (s.contact_radius_mm / a - 1.0).abs() < 0.02,
                    "{case}: radius {} vs {a}",
                    s.contact_radius_mm
                );
                // Where the paraboloid is a good sphere (a/R < 0.2), Hertz itself holds.
                let hertz = Hertz {
                    radius_mm: radius,
                    approach_mm: depth,
                    contact_modulus_mpa: e_star(e),
                };
                if hertz.contact_radius_mm() < 0.2 * radius {
                    assert!(
                        (s.force_n / hertz.force_n() - 1.0).abs() < 0.02,
                        "{case}: Hertz force"
                    );
                    assert!(
                        (s.contact_radius_mm / hertz.contact_radius_mm() - 1.0).abs() < 0.02,
                        "{case}: Hertz radius"
                    );
                }
                // Each body takes its compliance share of the approach.
                let share = tactex_core::hertz::gel_share(
                    Elastic {
                        modulus_mpa: Some(0.3),
                        poisson: 0.49,
                    },
                    object(e),
                );
                assert!(
                    (s.gel_max_indentation_mm / (share * depth) - 1.0).abs() < 0.01,
                    "{case}: gel indentation {} vs {}",
                    s.gel_max_indentation_mm,
                    share * depth
                );
            }
        }
    }
    // Shown with --nocapture: the figures quoted in docs/contact-mechanics.md.
    println!(
        "halfspace vs Sneddon, worst over the matrix: force {:.3}%, contact radius {:.3}%",
        100.0 * worst_force,
        100.0 * worst_radius
    );
}

#[test]
fn halfspace_error_shrinks_as_the_grid_is_refined() {
    let mut solver = ContactSolver::new();
    let surface = sphere(10.0);
    let (a, f) = sneddon(10.0, 1.0, e_star(Some(1.0)));
    let mut errors = Vec::new();
    for cell in [0.4, 0.2, 0.1, 0.05] {
        let mut p = problem(&surface, Some(1.0), 4.0, 1.0);
        p.cell_mm = Some(cell);
        let s = solver.solve(&p, Fidelity::Halfspace).unwrap();
        errors.push((
            (s.force_n / f - 1.0).abs(),
            (s.contact_radius_mm / a - 1.0).abs(),
        ));
    }
    for w in errors.windows(2) {
        assert!(w[1].0 < w[0].0, "force error must shrink: {errors:?}");
    }
    assert!(
        errors[3].1 < errors[0].1 / 2.0,
        "radius error must shrink: {errors:?}"
    );
}

/// int_0^inf (K(x) - 1) dx for nu = 0.49, by scipy.integrate.quad: a bonded layer's surface
/// under a point load sits lower than the half-space's by beta c P / (pi h).
const LAYER_BETA_NU049: f64 = -1.7374540168626604;

#[test]
fn a_thick_layer_is_a_half_space_and_a_thin_one_is_stiffer() {
    let mut solver = ContactSolver::new();
    let mut worst_theory = 0.0f64;
    for (radius, depth) in [
        (2.35, 0.1),
        (5.0, 0.1),
        (10.0, 0.1),
        (5.0, 0.3),
        (10.0, 1.0),
        (25.0, 1.5),
    ] {
        for e in [Some(1.0), None] {
            let surface = sphere(radius);
            let half = solver
                .solve(&problem(&surface, e, 4.0, depth), Fidelity::Halfspace)
                .unwrap();
            let thick = solver
                .solve(&problem(&surface, e, 50.0, depth), Fidelity::Layer)
                .unwrap();
            let thin = solver
                .solve(&problem(&surface, e, 4.0, depth), Fidelity::Layer)
                .unwrap();
            let case = format!("R {radius}, depth {depth}, E {e:?}");
            // To first order in a/h the layer is the half-space with its surface shifted by
            // beta c_gel F / (pi h), so F_layer / F_half - 1 = 1.5 |beta| share (4 / 3 pi) a / h.
            let a = half.contact_radius_mm;
            let share = tactex_core::hertz::gel_share(
                Elastic {
                    modulus_mpa: Some(0.3),
                    poisson: 0.49,
                },
                object(e),
            );
            let predicted =
                1.5 * -LAYER_BETA_NU049 * share * 4.0 / (3.0 * std::f64::consts::PI) * a / 50.0;
            let stiffening = thick.force_n / half.force_n - 1.0;
            if a / 50.0 < 0.03 {
                worst_theory = worst_theory.max((stiffening / predicted - 1.0).abs());
                assert!(
                    (stiffening / predicted - 1.0).abs() < 0.05,
                    "{case}: stiffening {stiffening} vs first-order {predicted}"
                );
            }
            if a / 50.0 < 0.018 {
                assert!(
                    stiffening.abs() < 0.02,
                    "{case}: 50 mm layer {} vs half-space {}",
                    thick.force_n,
                    half.force_n
                );
                assert!(
                    (thick.contact_radius_mm / a - 1.0).abs() < 0.02,
                    "{case}: radius"
                );
            }
            assert!(
                thin.force_n > 1.02 * half.force_n,
                "{case}: 4 mm layer must be stiffer"
            );
            assert!(thin.warnings.is_empty(), "{case}: {:?}", thin.warnings);
            println!(
                "{case}: 4 mm layer / half-space force {:.3}",
                thin.force_n / half.force_n
            );
        }
    }
    println!(
        "50 mm layer stiffening vs first-order theory (a/h < 0.03): worst {:.2}%",
        100.0 * worst_theory
    );
}

#[test]
fn a_thin_near_incompressible_layer_pushes_its_surface_outward() {
    // Real GelSight markers move away from the contact; a half-space pulls them inward.
    let mut solver = ContactSolver::new();
    let surface = sphere(10.0);
    let p = problem(&surface, None, 4.0, 1.0);
    let region = Rect::centred(DVec2::new(8.0, 8.0));
    for (fidelity, outward) in [(Fidelity::Layer, true), (Fidelity::Halfspace, false)] {
        let s = solver.solve(&p, fidelity).unwrap();
        let fields = solver.fields_over(&s, &region);
        let at = |x: f64| fields.grid.sample(&fields.lateral_x_mm, DVec2::new(x, 0.0));
        let edge = s.contact_radius_mm;
        assert_eq!(at(edge) > 0.0, outward, "{fidelity} at +a: {}", at(edge));
        assert_eq!(at(-edge) < 0.0, outward, "{fidelity} at -a");
        // Normal displacement is continuous across the solver grid's edge.
        let inside = s.grid.sample(&s.gel.normal_mm, DVec2::new(edge, 0.0));
        let outside = fields.grid.sample(&fields.normal_mm, DVec2::new(edge, 0.0));
        assert!(
            (inside - outside).abs() < 1e-9 + 1e-6 * inside.abs(),
            "{inside} vs {outside}"
        );
    }
}

#[test]
fn hertz_level_is_hertz_and_rigid_level_is_hardness_blind() {
    let mut solver = ContactSolver::new();
    let surface = sphere(10.0);
    let soft = solver
        .solve(&problem(&surface, Some(0.5), 4.0, 0.5), Fidelity::Hertz)
        .unwrap();
    let hertz = Hertz {
        radius_mm: 10.0,
        approach_mm: 0.5,
        contact_modulus_mpa: e_star(Some(0.5)),
    };
    assert!(
        (soft.force_n / hertz.force_n() - 1.0).abs() < 0.01,
        "{} vs {}",
        soft.force_n,
        hertz.force_n()
    );
    let rigid_soft = solver
        .solve(&problem(&surface, Some(0.5), 4.0, 0.5), Fidelity::Rigid)
        .unwrap();
    let rigid_hard = solver
        .solve(&problem(&surface, None, 4.0, 0.5), Fidelity::Rigid)
        .unwrap();
    assert_eq!(rigid_soft.force_n, rigid_hard.force_n);
    assert_eq!(rigid_soft.gel.normal_mm, rigid_hard.gel.normal_mm);
}

#[test]
fn press_sequence_is_warm_started_and_monotone() {
    let mut solver = ContactSolver::new();
    let surface = sphere(20.0);
    let depths: Vec<f64> = (1..=8).map(|k| 0.25 * k as f64).collect();
    let seq = solver
        .press_sequence(
            &problem(&surface, Some(0.8), 4.0, 0.0),
            Fidelity::Layer,
            &depths,
        )
        .unwrap();
    assert_eq!(seq.len(), 8);
    for w in seq.windows(2) {
        assert!(w[1].force_n > w[0].force_n);
        assert_eq!(w[1].grid, w[0].grid);
    }
    // Same answers as cold solves.
    for (warm, depth) in seq.iter().zip(&depths) {
        let cold = solver
            .solve_on(
                &problem(&surface, Some(0.8), 4.0, *depth),
                Fidelity::Layer,
                Some(warm.grid),
                None,
            )
            .unwrap();
        assert!((warm.force_n / cold.force_n - 1.0).abs() < 1e-5);
    }
}

#[test]
fn every_catalog_fruit_mesh_can_be_pressed_at_every_level() {
    // The procedural catalog meshes, pressed on their top at each fruit's own stages.
    let catalog = tactex_core::catalog::FruitCatalog::builtin();
    let mut solver = ContactSolver::new();
    for fruit in &catalog.fruits {
        let size = glam::DVec3::from_array(fruit.size_m);
        let mesh = tactex_sim::mesh::fruit(fruit.shape, size);
        let surface = ObjectSurface::from_mesh_top(&mesh, 1e3);
        let modulus = fruit.stages.last().map(|s| s.modulus_mpa);
        let mut forces = Vec::new();
        for fidelity in Fidelity::ALL {
            let mut p = problem(&surface, modulus, 4.0, 1.0);
            p.pad = Rect::centred(DVec2::new(10.15, 7.6));
            let s = solver.solve(&p, fidelity).unwrap();
            assert!(
                s.force_n > 0.0 && s.force_n.is_finite(),
                "{} {fidelity}",
                fruit.name
            );
            assert!(s.gel_max_indentation_mm > 0.0 && s.gel_max_indentation_mm <= 1.0 + 1e-9);
            forces.push(s.force_n);
        }
        // The thin layer is stiffer than the half-space it refines.
        assert!(forces[3] > forces[2], "{}: {forces:?}", fruit.name);
    }
}

/// The first frame of every press is a shallow press of a large object: from 1 um in, for
/// radii 1-100 mm, the force is finite and rises with depth; on a half-space it is Hertz's
/// at 1 um (on the 4 mm layer it is stiffer by the layer's share, 5.6% at R = 100 mm where
/// a/h = 0.08); the gel's fields over the whole pad stay a bounded grid even when the
/// solver's cell is far below a pixel (a 1 um press of a 1 mm sphere: 0.3 um cells).
#[test]
fn shallow_presses_of_large_spheres_are_hertz_and_their_fields_stay_bounded() {
    let mut solver = ContactSolver::new();
    for radius in [1.0, 10.0, 100.0] {
        let surface = sphere(radius);
        let mut last = 0.0;
        for depth in [0.001, 0.01, 0.1] {
            let p = problem(&surface, Some(0.5), 4.0, depth);
            let s = solver.solve(&p, Fidelity::Layer).unwrap();
            assert!(
                s.force_n.is_finite() && s.force_n > last,
                "R {radius} d {depth}"
            );
            last = s.force_n;
            if depth == 0.001 {
                let hertz = Hertz {
                    radius_mm: radius,
                    approach_mm: depth,
                    contact_modulus_mpa: e_star(Some(0.5)),
                };
                let half = solver.solve(&p, Fidelity::Halfspace).unwrap();
                assert!(
                    (half.force_n / hertz.force_n() - 1.0).abs() < 0.02,
                    "R {radius}: {} vs Hertz {}",
                    half.force_n,
                    hertz.force_n()
                );
                assert!(
                    s.force_n >= half.force_n,
                    "R {radius}: the layer is stiffer"
                );
            }
            let fields = solver.fields_over(&s, &pad());
            assert!(
                fields.grid.nx <= 2048 && fields.grid.ny <= 2048,
                "R {radius} d {depth}"
            );
            let deepest = fields.normal_mm.iter().copied().fold(0.0f64, f64::max);
            assert!(
                deepest > 0.0 && deepest <= depth,
                "R {radius} d {depth}: {deepest}"
            );
        }
    }
}
