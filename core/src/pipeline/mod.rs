//! One question, end to end, generic over the device traits: parse -> ground -> press ->
//! hardness -> explain. Every stage reports its wall time and the robot's (simulated) time.
//! `targets` is the ground stage on the camera, `arm_press` the press stage on the arm and
//! the sensor; `answer` and `config` are what goes out and in. The unit tests run it on
//! the public dummy devices (`crate::dummy`).

mod answer;
mod arm_press;
mod config;
mod targets;
#[cfg(test)]
mod tests;

pub use answer::{
    Answer, NotMeasured, NotMeasuredReason, ObjectReport, Progress, Sighting, StageTiming,
};
pub use config::{PipelineConfig, PipelineError};

use crate::catalog::FruitCatalog;
use crate::devices::{Arm, RgbdCamera, TactileSensor};
use crate::explain::{self, Explainer, Facts, Measured, location_words};
use crate::ground::detect::Detector;
use crate::hardness::estimate::{
    EstimateError, HardnessEstimate, HardnessEstimator, PressSequence,
};
use crate::press::site::PadClearance;
use crate::query::reader::PromptReader;
use arm_press::{PressTaken, press};
use std::time::Instant;
use targets::ground;

/// Who reads the question and who writes the answer.
#[derive(Clone, Copy)]
pub struct Language<'a> {
    pub reader: &'a dyn PromptReader,
    pub explainer: &'a dyn Explainer,
}

impl Language<'static> {
    /// The rules read, the template writes: offline and deterministic (evaluations, benches).
    pub const OFFLINE: Self = Self {
        reader: &crate::query::reader::RuleReader,
        explainer: &crate::explain::TemplateExplainer,
    };
}

/// The devices one question runs on.
pub struct Devices<'a, C: RgbdCamera, T: TactileSensor, A: Arm> {
    pub camera: &'a mut C,
    pub tactile: &'a mut T,
    pub arm: &'a mut A,
}

/// What `Answer::contact_criterion` says every press ran.
pub const CONTACT_CRITERION: &str = "local SSIM against the no-contact frame (worst 32 px tile <= 0.88, or past 1.3x the sensor's noise floor from a second no-contact frame) or mean marker motion > 2 px";

pub fn answer<C: RgbdCamera, T: TactileSensor, A: Arm>(
    prompt: &str,
    catalog: &FruitCatalog,
    devices: Devices<'_, C, T, A>,
    detector: &dyn Detector,
    estimator: &dyn HardnessEstimator,
    language: Language<'_>,
    config: &PipelineConfig,
) -> Result<Answer, PipelineError> {
    answer_with_progress(
        prompt,
        catalog,
        devices,
        detector,
        estimator,
        language,
        config,
        &|_| {},
    )
}

/// [`answer`], telling `on_progress` what happens as it happens.
#[allow(clippy::too_many_arguments)]
pub fn answer_with_progress<C: RgbdCamera, T: TactileSensor, A: Arm>(
    prompt: &str,
    catalog: &FruitCatalog,
    devices: Devices<'_, C, T, A>,
    detector: &dyn Detector,
    estimator: &dyn HardnessEstimator,
    language: Language<'_>,
    config: &PipelineConfig,
    on_progress: &dyn Fn(Progress),
) -> Result<Answer, PipelineError> {
    let Language { reader, explainer } = language;
    let Devices {
        camera,
        tactile,
        arm,
    } = devices;
    let mut timing = Vec::new();
    let mut lap = |stage: &str, arm: &A, start: (Instant, Option<f64>)| {
        let stage = StageTiming {
            stage: stage.into(),
            wall_ms: config
                .measure_wall_time
                .then(|| start.0.elapsed().as_secs_f64() * 1e3),
            sim_s: arm.sim_time_s().zip(start.1).map(|(now, then)| now - then),
        };
        on_progress(Progress::StageFinished(stage.clone()));
        timing.push(stage);
    };
    let start = |stage: &str, arm: &A| {
        on_progress(Progress::StageStarted {
            stage: stage.into(),
        });
        (Instant::now(), arm.sim_time_s())
    };

    let t = start("parse", arm);
    let read = reader.read(prompt, catalog);
    let query = match (read.query, &read.notice) {
        (Ok(q), _) => q,
        // The rules refused what the model could not read: both reasons, in one line.
        (Err(e), Some(notice)) => {
            return Err(PipelineError::Unread {
                error: e,
                notice: notice.clone(),
            });
        }
        (Err(e), None) => return Err(e.into()),
    };
    lap("parse", arm, t);

    let t = start("ground", arm);
    let pad = PadClearance::for_pad_mm(tactile.spec().pad_size_mm());
    let targets = ground(&query, camera, detector, &pad, config)?;
    on_progress(Progress::Detected {
        objects: targets
            .iter()
            .map(|t| Sighting {
                label: t.label.clone(),
                score: t.score,
                bbox: t.bbox,
                position_m: t.centre.to_array(),
            })
            .collect(),
    });
    lap("ground", arm, t);
    let not_found: Vec<String> = query
        .targets
        .iter()
        .chain(&query.candidate)
        .filter(|k| !targets.iter().any(|t| &t.label == *k))
        .cloned()
        .collect();

    // Each press is read on a second thread as soon as it is taken, while the arm goes on to
    // the next object (the real arm's travel hides it the same way): the hardness stage's
    // wall time is what remains after the last press. The arm's thread, done pressing, reads
    // the presses still queued beside the reader.
    let spec = tactile.spec().clone();
    let (to_reader, pressed_rx) = std::sync::mpsc::channel::<(usize, PressSequence)>();
    let pressed_rx = std::sync::Mutex::new(pressed_rx);
    let (estimated, presses) = std::thread::scope(|scope| {
        let read_queued = || {
            let mut read = Vec::new();
            loop {
                // The lock is held only while taking the next press, not while reading it.
                let next = pressed_rx.lock().unwrap_or_else(|e| e.into_inner()).recv();
                let Ok((index, sequence)) = next else {
                    break;
                };
                let estimate = estimator.estimate(&sequence, &spec);
                read.push((index, sequence, estimate));
            }
            read
        };
        let reader = scope.spawn(read_queued);
        let t = start("press", arm);
        let mut presses: Vec<Result<PressTaken, NotMeasured>> = Vec::new();
        for (index, target) in targets.iter().enumerate() {
            on_progress(Progress::Pressing {
                index,
                of: targets.len(),
                label: target.label.clone(),
            });
            let pressed = press(target, tactile, arm, config)?;
            on_progress(Progress::Pressed {
                index,
                label: target.label.clone(),
                frames: pressed.as_ref().map_or(0, |p| p.sequence.frames.len()),
                not_measured: pressed.as_ref().err().cloned(),
            });
            presses.push(pressed.map(|p| {
                // The reader outlives this loop, so the send cannot fail.
                let _ = to_reader.send((index, p.sequence));
                PressTaken {
                    search_mm: p.search_mm,
                    evidence: p.evidence,
                    recentred_mm: p.recentred_mm,
                }
            }));
        }
        lap("press", arm, t);
        drop(to_reader);
        let t = start("hardness", arm);
        let panicked = |_| PipelineError::Estimator("the hardness reader panicked".into());
        // A panic in an estimator is an error of the question here as on the reader's thread.
        let mut estimated = std::panic::catch_unwind(std::panic::AssertUnwindSafe(read_queued))
            .map_err(panicked)?;
        estimated.extend(reader.join().map_err(panicked)?);
        Ok::<_, PipelineError>(((estimated, t), presses))
    })?;
    let (estimated, t) = estimated;
    let mut sequences: Vec<Option<PressSequence>> = vec![None; targets.len()];
    let mut estimates: Vec<Option<Result<HardnessEstimate, EstimateError>>> =
        (0..targets.len()).map(|_| None).collect();
    for (index, sequence, estimate) in estimated {
        sequences[index] = Some(sequence);
        estimates[index] = Some(estimate);
    }
    let mut objects = Vec::new();
    for ((target, pressed), estimate) in targets.iter().zip(&presses).zip(estimates) {
        let mut report = ObjectReport {
            label: target.label.clone(),
            reference: target.reference,
            detection_score: target.score,
            position_m: target.centre.to_array(),
            surface_centroid_m: target.surface.to_array(),
            location: location_words(target.centre.x, target.centre.y),
            hardness: None,
            interval: None,
            ripeness: None,
            evidence: None,
            contact_search_mm: None,
            contact: None,
            not_measured: None,
            warnings: Vec::new(),
        };
        if target.crowded {
            report.warnings.push(
                "no spot on it was clear of its neighbours by the grounding margin; pressed where they reach least under the pad"
                    .into(),
            );
        }
        match (pressed, estimate) {
            (Ok(p), Some(estimate)) => {
                report.contact_search_mm = Some(p.search_mm);
                report.contact = Some(p.evidence.clone());
                if let Some(mm) = p.recentred_mm {
                    report.warnings.push(format!(
                        "the first imprint lay at the pad's edge; pressed again with the pad moved {mm:.1} mm over it"
                    ));
                }
                match estimate {
                    Ok(est) => {
                        report.hardness = Some(est.hardness.into());
                        report.interval = Some(est.interval);
                        report.ripeness = catalog
                            .get(&target.label)
                            .filter(|f| f.has_ripeness())
                            .map(|f| f.stage_for_modulus(est.hardness.modulus_mpa()).name.clone());
                        report.evidence = Some(est.evidence);
                    }
                    Err(EstimateError::OutsideCompetence(why)) => {
                        report.not_measured = Some(NotMeasured {
                            reason: NotMeasuredReason::OutsideCompetence,
                            detail: why,
                        })
                    }
                    Err(e) => {
                        report.not_measured = Some(NotMeasured {
                            reason: NotMeasuredReason::Estimator,
                            detail: format!("the press could not be read: {e}"),
                        })
                    }
                }
            }
            (Ok(_), None) => {
                return Err(PipelineError::Estimator(format!(
                    "the {}'s press was never read",
                    target.label
                )));
            }
            (Err(why), _) => report.not_measured = Some(why.clone()),
        }
        objects.push(report);
    }
    lap("hardness", arm, t);

    let t = start("explain", arm);
    let measured: Vec<Measured> = objects
        .iter()
        .map(|o| {
            // Only a measured coverage is worded as "likely".
            let calibrated = o.interval.as_ref().filter(|i| i.calibrated);
            Measured {
                label: o.label.clone(),
                location: o.location.clone(),
                hardness: o.hardness,
                interval_68_mpa: calibrated.map_or([None, None], |i| i.p68_mpa),
                interval_95_mpa: calibrated.map_or([None, None], |i| i.p95_mpa),
                ripeness: o.ripeness.clone(),
                not_measured: o.not_measured.as_ref().map(|n| n.to_string()),
                reference: o.reference,
            }
        })
        .collect();
    let selected = explain::select(&query, &measured, catalog);
    let facts = Facts {
        prompt: prompt.into(),
        query,
        objects: measured,
        selected,
        not_found,
    };
    let explanation = explainer.explain(&facts);
    lap("explain", arm, t);

    Ok(Answer {
        query: facts.query,
        objects,
        selected: facts.selected,
        answer: explanation.text,
        not_found: facts.not_found,
        estimator: estimator.name().into(),
        contact_criterion: CONTACT_CRITERION.into(),
        fidelity: None,
        sensor: None,
        explainer: explanation.explainer,
        explain_notice: explanation.notice,
        parser: read.parser,
        parse_notice: read.notice,
        timing,
        presses: sequences,
    })
}
