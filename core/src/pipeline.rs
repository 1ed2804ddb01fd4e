//! One question, end to end, generic over the device traits: parse -> ground -> press ->
//! hardness -> explain. Every stage reports its wall time and the robot's (simulated) time.

use crate::catalog::FruitCatalog;
use crate::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use crate::estimate::{Evidence, HardnessEstimator, PressSequence};
use crate::explain::{self, Explainer, Facts, Measured, location_words};
use crate::frames::TactileFrame;
use crate::geometry::Pose;
use crate::hardness::HardnessReport;
use crate::perception::centroid::median_depth;
use crate::perception::colour_name::{colour_name, mean_colour};
use crate::perception::detect::{DetectError, Detector, RgbdView};
use crate::perception::grounding::locate;
use crate::perception::markers::{detect_markers, mean_moved_displacement, track};
use crate::perception::ssim::ssim_rgb;
use crate::query::{self, Query, QueryError};
use glam::DVec3;
use serde::Serialize;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct PipelineConfig {
    /// Depth frames whose per-pixel median feeds the centroids (the paper: 10).
    pub depth_frames: usize,
    /// Frames recorded from the first contact on (the paper: 8) and the step between them.
    pub press_frames: usize,
    pub press_step_mm: f64,
    /// Contact test: SSIM to the no-contact frame at most this, and mean marker displacement
    /// above `contact_marker_px`.
    pub contact_ssim: f64,
    pub contact_marker_px: f64,
    /// The search for contact starts this far above the surface the camera saw, and gives up
    /// after `max_search_mm` of descent.
    pub approach_clearance_mm: f64,
    pub max_search_mm: f64,
    pub safe_height_m: f64,
    pub travel_speed_m_s: f64,
    pub press_speed_m_s: f64,
    /// Record wall-clock times (off for byte-reproducible output).
    pub measure_wall_time: bool,
}

impl Default for PipelineConfig {
    fn default() -> Self {
        Self {
            depth_frames: 10,
            press_frames: 8,
            press_step_mm: 0.25,
            contact_ssim: 0.96,
            contact_marker_px: 2.0,
            approach_clearance_mm: 4.0,
            max_search_mm: 20.0,
            safe_height_m: 0.20,
            travel_speed_m_s: 0.15,
            press_speed_m_s: 0.005,
            measure_wall_time: true,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum PipelineError {
    #[error(transparent)]
    Query(#[from] QueryError),
    #[error(transparent)]
    Device(#[from] DeviceError),
    #[error("camera: {0}")]
    Camera(String),
    #[error(transparent)]
    Detect(#[from] DetectError),
}

#[derive(Clone, Debug, Serialize)]
pub struct StageTiming {
    pub stage: String,
    pub wall_ms: Option<f64>,
    pub sim_s: Option<f64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct ObjectReport {
    pub label: String,
    pub detection_score: f64,
    /// Centre estimate: x, y of the refined-mask centroid, z half the top height (it rests on
    /// the table).
    pub position_m: [f64; 3],
    /// The paper's centroid: median of the refined mask's back-projected points.
    pub surface_centroid_m: [f64; 3],
    pub location: String,
    pub hardness: Option<HardnessReport>,
    pub modulus_interval_mpa: [Option<f64>; 2],
    pub ripeness: Option<String>,
    pub evidence: Option<Evidence>,
    /// Press facts: travel from the search start to the first contact frame, and the contact
    /// test's values there.
    pub contact_search_mm: Option<f64>,
    pub contact_ssim: Option<f64>,
    pub contact_marker_px: Option<f64>,
    pub warnings: Vec<String>,
}

/// What a running question has got to, for a live view: the stage it entered, what the camera
/// found, which object the arm is pressing, and each stage's time as it ends.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "event", rename_all = "snake_case")]
pub enum Progress {
    StageStarted {
        stage: String,
    },
    Detected {
        objects: Vec<Sighting>,
    },
    Pressing {
        index: usize,
        of: usize,
        label: String,
    },
    Pressed {
        index: usize,
        label: String,
        /// Press frames recorded; 0 when no contact was found.
        frames: usize,
        warning: Option<String>,
    },
    StageFinished(StageTiming),
}

/// One grounded object as the camera saw it, in the order the arm will press them.
#[derive(Clone, Debug, Serialize)]
pub struct Sighting {
    pub label: String,
    pub score: f64,
    /// x0, y0, x1, y1 in colour-image pixels (inclusive).
    pub bbox: [u32; 4],
    pub position_m: [f64; 3],
}

#[derive(Clone, Debug, Serialize)]
pub struct Answer {
    pub query: Query,
    pub objects: Vec<ObjectReport>,
    pub selected: Vec<usize>,
    pub answer: String,
    pub not_found: Vec<String>,
    pub estimator: String,
    /// "template", or "llm:<model>" when a model's grounded reply is the answer.
    pub explainer: String,
    /// Why a model's reply was not used, when the template stood in for it.
    pub explain_notice: Option<String>,
    pub timing: Vec<StageTiming>,
    /// Each object's press (no-contact reference and press frames), in `objects`' order;
    /// None where no contact was found. Left out of the JSON: images belong in image files.
    #[serde(skip)]
    pub presses: Vec<Option<PressSequence>>,
}

/// The devices one question runs on.
pub struct Devices<'a, C: RgbdCamera, T: TactileSensor, A: Arm> {
    pub camera: &'a mut C,
    pub tactile: &'a mut T,
    pub arm: &'a mut A,
}

struct Target {
    label: String,
    score: f64,
    bbox: [u32; 4],
    centre: DVec3,
    surface: DVec3,
    touch: DVec3,
}

struct Press {
    sequence: PressSequence,
    search_mm: f64,
    ssim: f64,
    marker_px: f64,
}

pub fn answer<C: RgbdCamera, T: TactileSensor, A: Arm>(
    prompt: &str,
    catalog: &FruitCatalog,
    devices: Devices<'_, C, T, A>,
    detector: &dyn Detector,
    estimator: &dyn HardnessEstimator,
    explainer: &dyn Explainer,
    config: &PipelineConfig,
) -> Result<Answer, PipelineError> {
    answer_with_progress(
        prompt,
        catalog,
        devices,
        detector,
        estimator,
        explainer,
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
    explainer: &dyn Explainer,
    config: &PipelineConfig,
    on_progress: &dyn Fn(Progress),
) -> Result<Answer, PipelineError> {
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
    let query = query::parse(prompt, catalog)?;
    lap("parse", arm, t);

    let t = start("ground", arm);
    let targets = ground(&query, camera, detector, config)?;
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
        .filter(|k| !targets.iter().any(|t| &t.label == *k))
        .cloned()
        .collect();

    let t = start("press", arm);
    let mut presses = Vec::new();
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
            warning: pressed.as_ref().err().cloned(),
        });
        presses.push(pressed);
    }
    lap("press", arm, t);

    let t = start("hardness", arm);
    let mut objects = Vec::new();
    for (target, pressed) in targets.iter().zip(&presses) {
        let mut report = ObjectReport {
            label: target.label.clone(),
            detection_score: target.score,
            position_m: target.centre.to_array(),
            surface_centroid_m: target.surface.to_array(),
            location: location_words(target.centre.x, target.centre.y),
            hardness: None,
            modulus_interval_mpa: [None, None],
            ripeness: None,
            evidence: None,
            contact_search_mm: None,
            contact_ssim: None,
            contact_marker_px: None,
            warnings: Vec::new(),
        };
        match pressed {
            Ok(p) => {
                report.contact_search_mm = Some(p.search_mm);
                report.contact_ssim = Some(p.ssim);
                report.contact_marker_px = Some(p.marker_px);
                match estimator.estimate(&p.sequence, tactile.spec()) {
                    Ok(est) => {
                        report.hardness = Some(est.hardness.into());
                        report.modulus_interval_mpa = est.modulus_interval_mpa;
                        report.ripeness = catalog
                            .get(&target.label)
                            .filter(|f| f.has_ripeness())
                            .map(|f| f.stage_for_modulus(est.hardness.modulus_mpa()).name.clone());
                        report.evidence = Some(est.evidence);
                    }
                    Err(e) => report.warnings.push(e.to_string()),
                }
            }
            Err(w) => report.warnings.push(w.clone()),
        }
        objects.push(report);
    }
    lap("hardness", arm, t);

    let t = start("explain", arm);
    let measured: Vec<Measured> = objects
        .iter()
        .map(|o| Measured {
            label: o.label.clone(),
            location: o.location.clone(),
            hardness: o.hardness,
            modulus_interval_mpa: o.modulus_interval_mpa,
            ripeness: o.ripeness.clone(),
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
        explainer: explanation.explainer,
        explain_notice: explanation.notice,
        timing,
        presses: presses
            .into_iter()
            .map(|p| p.ok().map(|p| p.sequence))
            .collect(),
    })
}

/// Detections for the query's targets, with refined-mask centroids from the depth median.
fn ground<C: RgbdCamera>(
    query: &Query,
    camera: &mut C,
    detector: &dyn Detector,
    config: &PipelineConfig,
) -> Result<Vec<Target>, PipelineError> {
    let frames = (0..config.depth_frames.max(1))
        .map(|_| camera.capture())
        .collect::<Result<Vec<_>, _>>()?;
    let depths: Vec<_> = frames.iter().map(|f| &f.depth_m).collect();
    let depth = median_depth(&depths).ok_or_else(|| {
        PipelineError::Camera(format!("{}: depth frames differ in size", camera.name()))
    })?;
    let (k, pose) = (camera.intrinsics(), camera.pose());
    let view = RgbdView {
        color: &frames[0].color,
        depth: &depth,
        intrinsics: &k,
        pose: &pose,
    };
    let candidates: Vec<Target> = detector
        .detect_for(&view, query)?
        .into_iter()
        .filter_map(|d| {
            let at = locate(&d.mask, true, &depth, &k, &pose)?;
            if query.filters.color.is_some() {
                let colour = mean_colour(&frames[0].color, &at.mask).map_or("grey", colour_name);
                if !query.filters.colour_matches(colour) {
                    return None;
                }
            }
            Some(Target {
                label: d.label,
                score: d.score,
                bbox: d.bbox,
                centre: at.centre,
                surface: at.surface,
                touch: at.touch,
            })
        })
        .collect();
    let mut targets = apply_position(query, candidates);
    // A stable order: left to right, then front to back.
    targets.sort_by(|a, b| {
        (a.centre.x, a.centre.y)
            .partial_cmp(&(b.centre.x, b.centre.y))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(targets)
}

/// Targets whose location matches the query's position filter. When none does ("the fruit
/// on the left" with every fruit right of centre), the one furthest that way answers.
fn apply_position(query: &Query, targets: Vec<Target>) -> Vec<Target> {
    let Some(filter) = query.filters.position.as_deref() else {
        return targets;
    };
    let located = |t: &Target| location_words(t.centre.x, t.centre.y);
    let matches = |t: &Target| query.filters.position_matches(&located(t));
    if targets.iter().any(matches) {
        return targets.into_iter().filter(matches).collect();
    }
    // How far a target lies in the filter's direction (x right, y back).
    let toward = |t: &Target| -> f64 {
        filter
            .split(' ')
            .map(|w| match w {
                "left" => -t.centre.x,
                "right" => t.centre.x,
                "front" => -t.centre.y,
                "back" => t.centre.y,
                _ => -t.centre.truncate().length(),
            })
            .sum()
    };
    targets
        .into_iter()
        .max_by(|a, b| toward(a).total_cmp(&toward(b)))
        .into_iter()
        .collect()
}

/// The press's contact test on one frame against the no-contact reference.
#[derive(Clone, Copy, Debug)]
pub struct ContactReading {
    pub contact: bool,
    pub ssim: f64,
    /// Mean displacement of the markers that moved (px).
    pub marker_px: f64,
}

/// Contact when the frame's SSIM to the reference is at most `config.contact_ssim` and the
/// markers that moved did so by more than `config.contact_marker_px` on average (markers
/// tracked within 0.45 of the grid pitch).
pub fn contact_test(
    reference: &TactileFrame,
    reference_markers: &[(f64, f64)],
    frame: &TactileFrame,
    pitch_px: f64,
    config: &PipelineConfig,
) -> ContactReading {
    let ssim = ssim_rgb(&frame.image, &reference.image).unwrap_or(1.0);
    let marker_px = mean_moved_displacement(&track(
        reference_markers,
        &detect_markers(&frame.image),
        0.45 * pitch_px,
    ));
    ContactReading {
        contact: ssim <= config.contact_ssim && marker_px > config.contact_marker_px,
        ssim,
        marker_px,
    }
}

/// Above the target, descend until the contact test fires, record the press frames, retract.
/// A press that finds no contact is a warning for that object, not a failure of the question.
fn press<T: TactileSensor, A: Arm>(
    target: &Target,
    tactile: &mut T,
    arm: &mut A,
    config: &PipelineConfig,
) -> Result<Result<Press, String>, PipelineError> {
    let above = |z: f64| Pose::tool_down(DVec3::new(target.touch.x, target.touch.y, z));
    let safe = above(target.touch.z + config.safe_height_m);
    arm.move_linear(&safe, config.travel_speed_m_s)?;
    let start_z = target.touch.z + config.approach_clearance_mm * 1e-3;
    arm.move_linear(&above(start_z), config.travel_speed_m_s)?;
    let reference = tactile.capture()?;
    let spec = tactile.spec().clone();
    let pitch_px = spec.markers.pitch_mm / spec.mm_per_px;
    let reference_markers = detect_markers(&reference.image);

    let step_m = config.press_step_mm * 1e-3;
    let max_steps = (config.max_search_mm / config.press_step_mm).ceil() as usize;
    let mut found = None;
    for i in 1..=max_steps {
        arm.move_linear(&above(start_z - i as f64 * step_m), config.press_speed_m_s)?;
        let frame = tactile.capture()?;
        let test = contact_test(&reference, &reference_markers, &frame, pitch_px, config);
        if test.contact {
            found = Some((i, frame, test.ssim, test.marker_px));
            break;
        }
    }
    let Some((contact_step, first, ssim, moved)) = found else {
        arm.move_linear(&safe, config.travel_speed_m_s)?;
        return Ok(Err(format!(
            "no contact within {} mm of descent",
            config.max_search_mm
        )));
    };
    let contact_z = arm.pose()?.position.z;
    let mut frames = vec![first];
    let mut travel_mm = vec![0.0];
    for j in 1..config.press_frames {
        arm.move_linear(
            &above(start_z - (contact_step + j) as f64 * step_m),
            config.press_speed_m_s,
        )?;
        frames.push(tactile.capture()?);
        travel_mm.push((contact_z - arm.pose()?.position.z) * 1e3);
    }
    arm.move_linear(&safe, config.travel_speed_m_s)?;
    Ok(Ok(Press {
        sequence: PressSequence {
            reference,
            frames,
            travel_mm,
        },
        search_mm: contact_step as f64 * config.press_step_mm,
        ssim,
        marker_px: moved,
    }))
}
