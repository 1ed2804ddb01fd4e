//! The physics estimators read back the modulus the twin pressed, on frames rendered through
//! the full chain (solver, shading, markers, noise).

use glam::DVec2;
use tactex_core::estimate::{HardnessEstimator, HertzSlopeEstimator};
use tactex_core::hertz::Elastic;
use tactex_core::indentation_estimator::IndentationEstimator;
use tactex_core::tactile_spec::TactileSpec;
use tactex_sim::elastic::{ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::gel_render::{CpuRenderer, SensorOptics};
use tactex_sim::press_protocol::{PressProtocol, PressSetup, plan_press};

/// Estimated modulus (MPa; None for rigid) of a sphere of `modulus_mpa` pressed at `fidelity`.
fn estimate(
    estimator: &dyn HardnessEstimator,
    surface: &ObjectSurface,
    modulus_mpa: f64,
    fidelity: Fidelity,
) -> Option<f64> {
    let spec = TactileSpec::gelsight_mini();
    let optics = SensorOptics::for_spec(&spec);
    let setup = PressSetup {
        surface,
        object: Elastic {
            modulus_mpa: Some(modulus_mpa),
            poisson: 0.35,
        },
        gel: spec.gel,
        fidelity,
        optics: &optics,
        phase_mm: 0.1,
        cell_mm: None,
        seed: 11,
    };
    let press = plan_press(&mut ContactSolver::new(), &setup, &PressProtocol::default())
        .expect("the press finds contact");
    let sequence = press.sequence(press.render(&mut CpuRenderer, &optics).expect("renders"));
    estimator
        .estimate(&sequence, &spec)
        .expect("an estimate")
        .hardness
        .modulus_mpa()
}

#[test]
fn indentation_split_on_the_bonded_gel_recovers_sphere_moduli() {
    // Soft to firm fruit flesh; the 4 mm gel is 0.3 MPa.
    let sphere = ObjectSurface::Sphere {
        radius_mm: 25.0,
        centre_mm: DVec2::new(0.8, -0.4),
    };
    let mut last = 0.0;
    for truth in [0.1, 0.4, 1.5] {
        let e = estimate(
            &IndentationEstimator::default(),
            &sphere,
            truth,
            Fidelity::Layer,
        )
        .expect("not rigid");
        assert!(
            (e / truth - 1.0).abs() < 0.25,
            "{truth} MPa read as {e:.3} MPa"
        );
        assert!(e > last, "order kept");
        last = e;
    }
}

#[test]
fn hertz_slope_fit_recovers_the_half_space_twin() {
    let sphere = ObjectSurface::Sphere {
        radius_mm: 25.0,
        centre_mm: DVec2::new(0.8, -0.4),
    };
    for truth in [0.1, 0.4, 1.5] {
        let e = estimate(
            &HertzSlopeEstimator::default(),
            &sphere,
            truth,
            Fidelity::Hertz,
        )
        .expect("not rigid");
        assert!(
            (e / truth - 1.0).abs() < 0.1,
            "{truth} MPa read as {e:.3} MPa"
        );
    }
}
