//! The physics estimators read back the modulus the twin pressed, on frames rendered through
//! the full chain (solver, shading, markers, noise).

use glam::DVec2;
use tactex_core::hardness::estimate::PressSequence;
use tactex_core::hardness::estimate::{HardnessEstimator, HertzSlopeEstimator};
use tactex_core::hardness::indentation_estimator::IndentationEstimator;
use tactex_core::hertz::Elastic;
use tactex_core::press::protocol::PressProtocol;
use tactex_core::tactile::spec::TactileSpec;
use tactex_sim::contact::{ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::datagen::press_protocol::{PlannedPress, PressSetup, plan_press};
use tactex_sim::render::gel::{CpuRenderer, SensorOptics};

/// A sphere pressed into the gel of `spec` at `fidelity`, rendered on the
/// CPU through `optics`: the solver's press and the frames an estimator reads.
fn press_sphere(
    spec: &TactileSpec,
    optics: &SensorOptics,
    fidelity: Fidelity,
    sphere: &ObjectSurface,
    modulus_mpa: f64,
    seed: u32,
) -> (PlannedPress, PressSequence) {
    let setup = PressSetup {
        surface: sphere,
        object: Elastic {
            modulus_mpa: Some(modulus_mpa),
            poisson: 0.35,
        },
        gel: spec.gel,
        fidelity,
        optics,
        phase_mm: 0.1,
        cell_mm: None,
        seed,
    };
    let press = plan_press(&mut ContactSolver::new(), &setup, &PressProtocol::default())
        .expect("the press finds contact");
    let sequence = press.sequence(press.render(&mut CpuRenderer, optics).expect("renders"));
    (press, sequence)
}

/// Presses a 25 mm sphere of soft to firm fruit flesh (0.1, 0.4, 1.5 MPa; the 4 mm gel is
/// 0.3 MPa) at `fidelity` and asserts the estimator reads each modulus back within
/// `tolerance` (relative), in order.
fn reads_back_sphere_moduli(estimator: &dyn HardnessEstimator, fidelity: Fidelity, tolerance: f64) {
    let spec = TactileSpec::gelsight_mini();
    let optics = SensorOptics::for_spec(&spec);
    let sphere = ObjectSurface::Sphere {
        radius_mm: 25.0,
        centre_mm: DVec2::new(0.8, -0.4),
    };
    let mut last = 0.0;
    for truth in [0.1, 0.4, 1.5] {
        let (_, sequence) = press_sphere(&spec, &optics, fidelity, &sphere, truth, 11);
        let e = estimator
            .estimate(&sequence, &spec)
            .expect("an estimate")
            .hardness
            .modulus_mpa()
            .expect("not rigid");
        assert!(
            (e / truth - 1.0).abs() < tolerance,
            "{}: {truth} MPa read as {e:.3} MPa",
            estimator.name()
        );
        assert!(e > last, "order kept");
        last = e;
    }
}

#[test]
fn indentation_split_on_the_bonded_gel_recovers_sphere_moduli() {
    reads_back_sphere_moduli(&IndentationEstimator::default(), Fidelity::Layer, 0.25);
}

#[test]
fn hertz_slope_fit_recovers_the_half_space_twin() {
    reads_back_sphere_moduli(&HertzSlopeEstimator::default(), Fidelity::Hertz, 0.1);
}

#[test]
fn a_press_does_not_depend_on_what_the_solver_pressed_before() {
    // Parallel data generation reuses one solver per thread in whatever order the scheduler
    // picks, so its caches must not change a press's numbers.
    let spec = TactileSpec::gelsight_mini();
    let optics = SensorOptics::for_spec(&spec);
    let press = |solver: &mut ContactSolver, radius_mm: f64| {
        let surface = ObjectSurface::Sphere {
            radius_mm,
            centre_mm: DVec2::new(0.3, 0.2),
        };
        let setup = PressSetup {
            surface: &surface,
            object: Elastic {
                modulus_mpa: Some(0.5),
                poisson: 0.4,
            },
            gel: spec.gel,
            fidelity: Fidelity::Layer,
            optics: &optics,
            phase_mm: 0.1,
            cell_mm: None,
            seed: 3,
        };
        plan_press(solver, &setup, &PressProtocol::default()).expect("contact")
    };
    let fresh = press(&mut ContactSolver::new(), 8.0);
    let mut used = ContactSolver::new();
    press(&mut used, 200.0); // a wide contact first: larger grids and layer tables
    let after = press(&mut used, 8.0);
    for (a, b) in fresh.frames.iter().zip(&after.frames) {
        assert_eq!(a.fields.normal_mm, b.fields.normal_mm);
        assert_eq!(a.force_n, b.force_n);
    }
}

#[test]
fn frames_past_the_first_one_cut_by_the_frames_edge_are_not_read() {
    // A wide soft sphere: its contact outgrows the Mini's frame within the press.
    let spec = TactileSpec::gelsight_mini();
    let optics = SensorOptics::for_spec(&spec);
    let sphere = ObjectSurface::Sphere {
        radius_mm: 60.0,
        centre_mm: DVec2::new(0.5, 0.3),
    };
    let (_, sequence) = press_sphere(&spec, &optics, Fidelity::Layer, &sphere, 0.3, 5);
    let within: Vec<bool> = sequence
        .frames
        .iter()
        .map(|f| {
            tactex_core::tactile::frame_reading::read_frame(
                &f.image,
                &sequence.reference.image,
                &spec,
                tactex_core::tactile::slopes::ColourDrift::Measured,
            )
            .expect("same size")
            .within_frame
        })
        .collect();
    let first_cut = (3..within.len())
        .find(|k| !within[*k])
        .expect("the imprint reaches the frame's edge within the press");
    assert!(first_cut + 1 < within.len(), "{within:?}");
    let estimator = IndentationEstimator::default();
    let read = estimator.estimate(&sequence, &spec).expect("an estimate");
    // The frames past the first cut one replaced by a blank gel: nothing changes.
    let mut blanked = sequence.clone();
    for frame in &mut blanked.frames[first_cut + 1..] {
        frame.image = sequence.reference.image.clone();
    }
    let read_blanked = estimator.estimate(&blanked, &spec).expect("an estimate");
    assert_eq!(
        format!("{:?}", read.hardness),
        format!("{:?}", read_blanked.hardness)
    );
}

/// A wide contact's glow lights the gel far from it, where the reader measures the colour
/// drift; taken for drift, it read the deeper frames of wide presses through the FOTS profile
/// at up to 3.6x the solver's depth (a 60 mm sphere at 1 MPa: +262%; a 30 mm sphere at 3 MPa:
/// +93%). A press's frames are taken under the same light, so its deeper frames take the
/// drift its first frame (the least glow) shows.
#[test]
fn a_wide_contacts_glow_is_not_taken_for_colour_drift_in_a_press() {
    use tactex_core::hardness::border_level::read_share_of_indentation;
    use tactex_core::tactile::frame_reading::read_frame;
    use tactex_core::tactile::sensor_profile::SensorProfile;
    use tactex_core::tactile::slopes::ColourDrift;
    let profile = SensorProfile::load(
        &std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../tests/fixtures/fots/profile/fots-9.toml"),
    )
    .expect("the fixture profile loads");
    let spec = profile.spec.clone();
    let optics = SensorOptics::for_profile(&profile);
    // (sphere radius mm, modulus MPa, centre off the pad's middle mm)
    for (radius_mm, modulus_mpa, off_mm) in [(60.0, 1.0, 0.0), (30.0, 3.0, 0.0), (40.0, 2.0, 2.0)] {
        let sphere = ObjectSurface::Sphere {
            radius_mm,
            centre_mm: DVec2::splat(off_mm),
        };
        let (press, sequence) =
            press_sphere(&spec, &optics, Fidelity::Layer, &sphere, modulus_mpa, 5);
        let mut drift = ColourDrift::Measured;
        for (k, (truth, frame)) in press.frames.iter().zip(&sequence.frames).enumerate() {
            let reading = read_frame(&frame.image, &sequence.reference.image, &spec, drift)
                .expect("same size");
            drift = drift.for_next_frame(reading.drift);
            // As the estimator reads it: the peak against the frame's border.
            let read_mm = reading.peak_mm / read_share_of_indentation(&reading, &spec.gel);
            let ratio = read_mm / truth.gel_max_indentation_mm;
            let case =
                format!("{radius_mm} mm sphere at {modulus_mpa} MPa, frame {k}: {ratio:.2}x");
            assert!(ratio < 1.6, "{case}");
            // The first three frames are fitted whatever the frame's edge does.
            if k < 3 {
                assert!((ratio - 1.0).abs() < 0.15, "{case}");
            }
        }
    }
}
