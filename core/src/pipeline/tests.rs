//! The pipeline on the dummy devices (crate::dummy).

use super::*;
use crate::dummy::{DummyWorld, FixedEstimator, TOP_M};
use crate::tactile::spec::TactileSpec;

fn ask(centre: (f64, f64), shows: bool, refuse_below_m: f64) -> Answer {
    ask_on(centre, None, shows, refuse_below_m)
}

fn ask_on(
    centre: (f64, f64),
    object_m: Option<(f64, f64)>,
    shows: bool,
    refuse_below_m: f64,
) -> Answer {
    ask_with(
        centre,
        object_m,
        shows,
        refuse_below_m,
        &FixedEstimator::new(2.0),
    )
    .expect("the question is answered")
}

fn ask_with(
    centre: (f64, f64),
    object_m: Option<(f64, f64)>,
    shows: bool,
    refuse_below_m: f64,
    estimator: &dyn HardnessEstimator,
) -> Result<Answer, PipelineError> {
    let mut world = DummyWorld::apple();
    world.tactile.centre = centre;
    world.tactile.object_m = object_m;
    world.tactile.shows = shows;
    world.arm.refuse_below_m = refuse_below_m;
    ask_in(&mut world, estimator)
}

/// "How hard is the apple?" in `world`.
fn ask_in(
    world: &mut DummyWorld,
    estimator: &dyn HardnessEstimator,
) -> Result<Answer, PipelineError> {
    answer(
        "How hard is the apple?",
        &FruitCatalog::builtin(),
        Devices {
            camera: &mut world.camera,
            tactile: &mut world.tactile,
            arm: &mut world.arm,
        },
        &world.detector,
        estimator,
        Language::OFFLINE,
        &PipelineConfig::default(),
    )
}

/// Panics on every press, as a broken estimator would.
struct Panics;
impl HardnessEstimator for Panics {
    fn name(&self) -> &str {
        "panics"
    }
    fn estimate(
        &self,
        _: &PressSequence,
        _: &TactileSpec,
    ) -> Result<HardnessEstimate, EstimateError> {
        panic!("a broken estimator")
    }
}

#[test]
fn an_estimator_that_panics_fails_the_question_with_an_error_not_a_panic() {
    // Whichever thread reads the press (the reader, or the arm's once it is done pressing).
    for _ in 0..4 {
        let failed = ask_with((48.0, 40.0), None, true, 0.0, &Panics);
        assert!(
            matches!(&failed, Err(PipelineError::Estimator(why)) if why.contains("panicked")),
            "{:?}",
            failed.map(|a| a.answer)
        );
    }
}

#[test]
fn a_press_records_eight_frames_from_the_first_contact_frame() {
    let a = ask((48.0, 40.0), true, 0.0);
    let o = &a.objects[0];
    assert!(o.not_measured.is_none(), "{:?}", o.not_measured);
    assert_eq!(o.hardness.unwrap().modulus_mpa, Some(2.0));
    let evidence = o.contact.as_ref().unwrap();
    assert!(evidence.contact && !evidence.fired_by.is_empty());
    // The search starts 4 mm above the top the camera saw and fires once the disc shows.
    let search = o.contact_search_mm.unwrap();
    assert!((4.0..=5.0).contains(&search), "{search}");
    let press = a.presses[0].as_ref().unwrap();
    assert_eq!(press.travel_mm.len(), 8);
    for (j, t) in press.travel_mm.iter().enumerate() {
        assert!((t - 0.25 * j as f64).abs() < 1e-9, "{t}");
    }
    assert!(
        a.answer.contains("2.00 MPa") || a.answer.contains("Shore"),
        "{}",
        a.answer
    );
}

#[test]
fn a_gel_that_never_changes_is_no_contact_not_a_failed_question() {
    let a = ask((48.0, 40.0), false, 0.0);
    let o = &a.objects[0];
    let why = o.not_measured.as_ref().unwrap();
    assert_eq!(why.reason, NotMeasuredReason::NoContact);
    assert!(o.hardness.is_none());
    assert!(
        a.answer
            .contains("could not measure (no contact within 20 mm"),
        "{}",
        a.answer
    );
}

#[test]
fn a_blown_out_or_blank_sensor_is_an_unreadable_frame_not_an_imprint_or_no_contact() {
    for (from_mm, which) in [
        (
            1.0,
            "pressed frame 5 cannot be read: 100% of its pixels are saturated",
        ),
        (
            -1e3,
            "no-contact frame cannot be read: 100% of its pixels are saturated",
        ),
    ] {
        let mut world = DummyWorld::apple();
        world.tactile.blown_out_from_mm = Some(from_mm);
        let a = ask_in(&mut world, &FixedEstimator::new(2.0)).expect("the question is answered");
        let o = &a.objects[0];
        let why = o.not_measured.as_ref().unwrap();
        assert_eq!(why.reason, NotMeasuredReason::UnreadableFrame, "{why:?}");
        assert!(why.detail.contains(which), "{}", why.detail);
        assert!(o.hardness.is_none());
        assert!(a.answer.contains("could not measure"), "{}", a.answer);
    }
}

#[test]
fn a_refused_move_is_reported_with_the_arms_reason() {
    // The arm will not go below 1 mm above the apple's top: the search is cut short.
    let a = ask((48.0, 40.0), true, TOP_M + 0.001);
    let why = a.objects[0].not_measured.as_ref().unwrap();
    assert_eq!(why.reason, NotMeasuredReason::ArmRefused);
    assert!(why.detail.contains("crush limit"), "{}", why.detail);
    assert!(
        a.answer.contains("the arm refused the press"),
        "{}",
        a.answer
    );
}

#[test]
fn an_imprint_at_the_frames_edge_wherever_the_pad_goes_is_reported_as_cut() {
    let a = ask((4.0, 40.0), true, 0.0);
    let why = a.objects[0].not_measured.as_ref().unwrap();
    assert_eq!(why.reason, NotMeasuredReason::ImprintCut);
    assert!(
        why.detail.contains("again with the pad moved"),
        "{}",
        why.detail
    );
    assert!(a.objects[0].hardness.is_none());
}

#[test]
fn an_imprint_at_the_frames_edge_is_pressed_again_with_the_pad_over_it() {
    // The pad's first contact lies 44 px (of 96) left of the frame's middle: the object
    // is 9.3 mm off along the world's -x. The second press, moved there, is centred.
    let mm_per_px = 320.0 * 0.0634 / 96.0;
    let object = (-44.0 * mm_per_px * 1e-3, 0.0);
    let a = ask_on((0.0, 0.0), Some(object), true, 0.0);
    let o = &a.objects[0];
    assert!(o.not_measured.is_none(), "{:?}", o.not_measured);
    assert_eq!(o.hardness.unwrap().modulus_mpa, Some(2.0));
    assert_eq!(o.warnings.len(), 1, "{:?}", o.warnings);
    assert!(o.warnings[0].contains("moved 9."), "{}", o.warnings[0]);
}
