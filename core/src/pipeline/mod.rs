//! One question, end to end, generic over the device traits: parse -> ground -> press ->
//! hardness -> explain. Every stage reports its wall time and the robot's (simulated) time.

use crate::catalog::FruitCatalog;
use crate::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use crate::explain::{self, Explainer, Facts, Measured, location_words};
use crate::frames::TactileFrame;
use crate::geometry::Pose;
use crate::ground::centroid::median_depth;
use crate::ground::colour_name::{colour_name, mean_colour};
use crate::ground::detect::{DetectError, Detector, RgbdView};
use crate::ground::grounding::locate;
use crate::hardness::estimate::{
    EstimateError, Evidence, HardnessEstimate, HardnessEstimator, ModulusInterval, PressSequence,
};
use crate::hardness::scale::HardnessReport;
use crate::press::protocol::{Look, PressOutcome, PressProbe, PressProtocol, run_press};
use crate::press::site::{HeightMap, PadClearance, PressSite, press_site};
use crate::query::{self, Query, QueryError};
use crate::tactile::contact::ContactEvidence;
use glam::DVec3;
use serde::Serialize;
use std::time::Instant;

#[derive(Clone, Debug)]
pub struct PipelineConfig {
    /// Depth frames whose per-pixel median feeds the centroids (the paper: 10).
    pub depth_frames: usize,
    /// The press (the paper's: 0.25 mm steps, 8 frames from the first contact on, the one
    /// contact criterion); its search gives up after `max_search_mm` of descent.
    pub press: PressProtocol,
    /// The search for contact starts this far above the surface the camera saw.
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
            press: PressProtocol::default(),
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
    #[error("hardness: {0}")]
    Estimator(String),
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
    /// The estimate's 68% and 95% intervals and what they rest on.
    pub interval: Option<ModulusInterval>,
    pub ripeness: Option<String>,
    pub evidence: Option<Evidence>,
    /// Press facts: travel from the search start to the first contact frame, and the contact
    /// criterion's evidence there.
    pub contact_search_mm: Option<f64>,
    pub contact: Option<ContactEvidence>,
    /// Why the object has no hardness, when it has none.
    pub not_measured: Option<NotMeasured>,
    pub warnings: Vec<String>,
}

/// Why an object the camera found was not measured. The rest of the question is answered.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NotMeasuredReason {
    /// The contact criterion never fired within the search.
    NoContact,
    /// The arm refused a move of the press (out of its workspace, or past its crush limit).
    ArmRefused,
    /// The first contact frame's imprint crosses the frame's edge: the pad came down beside
    /// the object, and no estimator reads a cut imprint.
    ImprintCut,
    /// The estimator could not read the press.
    Estimator,
}

/// The reason for machines, and the detail for people.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotMeasured {
    pub reason: NotMeasuredReason,
    pub detail: String,
}

impl NotMeasured {
    fn no_contact(travel_mm: f64) -> Self {
        Self {
            reason: NotMeasuredReason::NoContact,
            detail: format!("no contact within {travel_mm} mm of descent"),
        }
    }

    fn arm_refused(reason: &str) -> Self {
        Self {
            reason: NotMeasuredReason::ArmRefused,
            detail: format!("the arm refused the press: {reason}"),
        }
    }
}

impl std::fmt::Display for NotMeasured {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.detail)
    }
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
        /// Press frames recorded; 0 when the object could not be pressed.
        frames: usize,
        not_measured: Option<NotMeasured>,
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
    /// The contact criterion every press ran (see `tactile::contact`).
    pub contact_criterion: String,
    /// The twin's contact physics (rigid, hertz, halfspace, layer); None on real or replayed
    /// devices.
    pub fidelity: Option<String>,
    /// The tactile sensor's profile (name and content hash) the presses were rendered or
    /// read through, when one is known.
    pub sensor: Option<crate::tactile::sensor_profile::ProfileId>,
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
    /// The pad's turn about the vertical for this press (see `press_site`).
    pad_yaw_rad: f64,
    /// No site was clear of the neighbours by the grounding margin (see `press_site`).
    crowded: bool,
}

struct Press {
    sequence: PressSequence,
    search_mm: f64,
    evidence: ContactEvidence,
    /// How far the pad was moved for a second press after the first imprint lay at its edge.
    recentred_mm: Option<f64>,
}

/// What the pipeline keeps of a press once its sequence is handed to the hardness reader.
struct PressTaken {
    search_mm: f64,
    evidence: ContactEvidence,
    recentred_mm: Option<f64>,
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
        .filter(|k| !targets.iter().any(|t| &t.label == *k))
        .cloned()
        .collect();

    // Each press is read on a second thread as soon as it is taken, while the arm goes on to
    // the next object (the real arm's travel hides it the same way): the hardness stage's
    // wall time is what remains after the last press.
    let spec = tactile.spec().clone();
    let (estimated, presses) = std::thread::scope(|scope| {
        let (to_reader, pressed_rx) = std::sync::mpsc::channel::<(usize, PressSequence)>();
        let reader = scope.spawn(move || {
            pressed_rx
                .into_iter()
                .map(|(index, sequence)| {
                    let estimate = estimator.estimate(&sequence, &spec);
                    (index, sequence, estimate)
                })
                .collect::<Vec<_>>()
        });
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
        let estimated = reader
            .join()
            .map_err(|_| PipelineError::Estimator("the hardness reader panicked".into()))?;
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
        .map(|o| Measured {
            label: o.label.clone(),
            location: o.location.clone(),
            hardness: o.hardness,
            interval_68_mpa: o.interval.as_ref().map_or([None, None], |i| i.p68_mpa),
            interval_95_mpa: o.interval.as_ref().map_or([None, None], |i| i.p95_mpa),
            ripeness: o.ripeness.clone(),
            not_measured: o.not_measured.as_ref().map(|n| n.to_string()),
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
        timing,
        presses: sequences,
    })
}

/// Detections for the query's targets, with refined-mask centroids from the depth median.
fn ground<C: RgbdCamera>(
    query: &Query,
    camera: &mut C,
    detector: &dyn Detector,
    pad: &PadClearance,
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
    let detections = detector.detect_for(&view, query)?;
    // Every pixel's point once: each target's press site looks at all the others.
    let (w, h) = depth.dimensions();
    let cloud: Vec<Option<DVec3>> = (0..h)
        .flat_map(|v| (0..w).map(move |u| (u, v)))
        .map(|(u, v)| {
            let z = f64::from(depth.get_pixel(u, v)[0]);
            (z > 0.0 && z.is_finite())
                .then(|| pose.transform_point(k.back_project(f64::from(u), f64::from(v), z)))
        })
        .collect();
    let candidates: Vec<Target> = detections
        .iter()
        .enumerate()
        .filter_map(|(i, d)| {
            let at = locate(&d.mask, true, &depth, &k, &pose)?;
            if query.filters.color.is_some() {
                let colour = mean_colour(&frames[0].color, &at.mask).map_or("grey", colour_name);
                if !query.filters.colour_matches(colour) {
                    return None;
                }
            }
            let site = clear_touch(at.touch, i, &detections, &cloud, pad).unwrap_or(PressSite {
                at: at.touch,
                yaw_rad: 0.0,
                crowded: false,
            });
            Some(Target {
                label: d.label.clone(),
                score: d.score,
                bbox: d.bbox,
                centre: at.centre,
                surface: at.surface,
                touch: site.at,
                pad_yaw_rad: site.yaw_rad,
                crowded: site.crowded,
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

/// Where the pad can press detection `index` without meeting anything else first (see
/// `press_site`); None when the detection has no depth points.
/// The object's own points are its mask's; everything else is the other detections' and
/// whatever lies more than a few pixels outside its mask (its own flank just outside the mask
/// is not an obstacle).
fn clear_touch(
    crest: DVec3,
    index: usize,
    detections: &[crate::ground::detect::Detection],
    cloud: &[Option<DVec3>],
    pad: &PadClearance,
) -> Option<PressSite> {
    let mask = &detections[index].mask;
    // Holes in the mask (a highlight, a dropout) are the object's own, not obstacles.
    let near = imageproc::morphology::dilate(
        &fill_holes(mask),
        imageproc::distance_transform::Norm::LInf,
        4,
    );
    let in_other = |at: usize| {
        detections
            .iter()
            .enumerate()
            .any(|(j, d)| j != index && d.mask.as_raw().get(at).is_some_and(|m| *m > 0))
    };
    let (mut own, mut others) = (Vec::new(), Vec::new());
    for (at, p) in cloud.iter().enumerate() {
        let Some(p) = p else { continue };
        if mask.as_raw().get(at).is_some_and(|m| *m > 0) {
            own.push(*p);
        } else if near.as_raw().get(at).is_none_or(|m| *m == 0) || in_other(at) {
            others.push(*p);
        }
    }
    const CELL_M: f64 = 0.002;
    press_site(
        crest,
        &HeightMap::new(&own, CELL_M)?,
        &HeightMap::new(&others, CELL_M)?,
        pad,
    )
}

/// `mask` with every background region that does not reach the image's border filled.
fn fill_holes(mask: &image::GrayImage) -> image::GrayImage {
    use imageproc::region_labelling::{Connectivity, connected_components};
    let background = image::GrayImage::from_fn(mask.width(), mask.height(), |x, y| {
        image::Luma([if mask.get_pixel(x, y)[0] > 0 { 0 } else { 255 }])
    });
    let regions = connected_components(&background, Connectivity::Four, image::Luma([0u8]));
    let (w, h) = mask.dimensions();
    let mut outside = std::collections::HashSet::new();
    for (x, y, l) in regions.enumerate_pixels() {
        if l[0] > 0 && (x == 0 || y == 0 || x + 1 == w || y + 1 == h) {
            outside.insert(l[0]);
        }
    }
    image::GrayImage::from_fn(w, h, |x, y| {
        let l = regions.get_pixel(x, y)[0];
        image::Luma([if l == 0 || !outside.contains(&l) {
            255
        } else {
            0
        }])
    })
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

/// What `Answer::contact_criterion` says every press ran.
pub const CONTACT_CRITERION: &str = "local SSIM against the no-contact frame (worst 32 px tile <= 0.88, or past 1.3x the sensor's noise floor from a second no-contact frame) or mean marker motion > 2 px";

/// The pad over a target, lowered in the protocol's steps from `start_z_m`.
struct ArmProbe<'d, T: TactileSensor, A: Arm> {
    tactile: &'d mut T,
    arm: &'d mut A,
    touch: DVec3,
    pad_yaw_rad: f64,
    start_z_m: f64,
    config: &'d PipelineConfig,
}

impl<T: TactileSensor, A: Arm> ArmProbe<'_, T, A> {
    fn above(&self, z: f64) -> Pose {
        Pose::tool_down_turned(DVec3::new(self.touch.x, self.touch.y, z), self.pad_yaw_rad)
    }

    /// The frame with the pad `k` steps down, and where the arm says the pad is (m).
    fn lowered(&mut self, k: usize) -> Result<(TactileFrame, f64), DeviceError> {
        let z = self.start_z_m - k as f64 * self.config.press.step_mm * 1e-3;
        self.arm
            .move_linear(&self.above(z), self.config.press_speed_m_s)?;
        let frame = self.tactile.capture()?;
        Ok((frame, self.arm.pose()?.position.z))
    }
}

impl<T: TactileSensor, A: Arm> PressProbe for ArmProbe<'_, T, A> {
    type Frame = (TactileFrame, f64);
    type Error = DeviceError;

    fn look(&mut self, at: Look) -> Result<(image::RgbImage, (TactileFrame, f64)), DeviceError> {
        let k = match at {
            // Both no-contact frames at the start: the second gives the noise floor.
            Look::Reference | Look::NoiseFloor => 0,
            Look::Search(k) => k,
        };
        let (frame, z) = self.lowered(k)?;
        Ok((frame.image.clone(), (frame, z)))
    }

    fn record(&mut self, k: usize) -> Result<(TactileFrame, f64), DeviceError> {
        self.lowered(k)
    }
}

/// Where the imprint of the first contact frame lies, as a fraction of the frame's width and
/// height: the middle of its colour change against `reference` (where the change, smoothed
/// over a few pixels against noise and marker dots, exceeds half its largest value); None
/// when nothing changed. A press is cut when the middle falls in the frame's outer eighth: at
/// first contact the imprint is small and a press centred on the object has it in the middle,
/// a long ridge across the pad included; deeper frames of a large fruit reach the edge and are
/// still read.
fn imprint_middle(first_contact: &TactileFrame, reference: &TactileFrame) -> Option<glam::DVec2> {
    let (a, b) = (&first_contact.image, &reference.image);
    if a.dimensions() != b.dimensions() {
        return None;
    }
    let (w, h) = a.dimensions();
    let change = image::ImageBuffer::<image::Luma<f32>, Vec<f32>>::from_fn(w, h, |x, y| {
        let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
        image::Luma([(0..3).map(|c| (p[c] as f32 - q[c] as f32).abs()).sum()])
    });
    let smooth = imageproc::filter::gaussian_blur_f32(&change, 4.0);
    let peak = smooth.pixels().map(|p| p[0]).fold(0.0, f32::max);
    if peak <= 0.0 {
        return None;
    }
    let (mut sx, mut sy, mut n) = (0.0, 0.0, 0.0);
    for (x, y, p) in smooth.enumerate_pixels() {
        if p[0] > 0.5 * peak {
            sx += x as f64;
            sy += y as f64;
            n += 1.0;
        }
    }
    Some(glam::DVec2::new(sx / n / w as f64, sy / n / h as f64))
}

/// Above the target, run the press protocol from `approach_clearance_mm` above the surface
/// the camera saw, retract. An object that cannot be pressed (no contact, a refused move, an
/// imprint cut by the pad's edge) is reported as not measured, not a failure of the question;
/// a device that fails otherwise fails it.
fn press<T: TactileSensor, A: Arm>(
    target: &Target,
    tactile: &mut T,
    arm: &mut A,
    config: &PipelineConfig,
) -> Result<Result<Press, NotMeasured>, PipelineError> {
    let offset_m = match press_at(target.touch, target, tactile, arm, config)? {
        Attempt::Pressed(p) => return Ok(Ok(p)),
        Attempt::NotMeasured(why) => return Ok(Err(why)),
        Attempt::Cut { offset_m } => offset_m,
    };
    // The imprint lay at the pad's edge: the object is off to that side. Press once more with
    // the pad moved over the imprint's middle, as an operator would.
    let moved_mm = offset_m.length() * 1e3;
    let moved = target.touch + offset_m.extend(0.0);
    Ok(match press_at(moved, target, tactile, arm, config)? {
        Attempt::Pressed(mut p) => {
            p.recentred_mm = Some(moved_mm);
            Ok(p)
        }
        Attempt::NotMeasured(why) => Err(why),
        Attempt::Cut { .. } => Err(NotMeasured {
            reason: NotMeasuredReason::ImprintCut,
            detail: format!(
                "the imprint was cut by the pad's edge, again with the pad moved {moved_mm:.1} mm over it: the pad came down beside the object"
            ),
        }),
    })
}

/// What one press came to.
enum Attempt {
    Pressed(Press),
    NotMeasured(NotMeasured),
    /// The first imprint lay at the pad's edge; the pad's centre lies `offset_m` (world x, y)
    /// from the imprint's middle.
    Cut {
        offset_m: glam::DVec2,
    },
}

/// One press with the pad over `touch`.
fn press_at<T: TactileSensor, A: Arm>(
    touch: DVec3,
    target: &Target,
    tactile: &mut T,
    arm: &mut A,
    config: &PipelineConfig,
) -> Result<Attempt, PipelineError> {
    // The pad's size, for where on it an imprint lies.
    let pad_mm = tactile.spec().pad_size_mm();
    let refused = |e: DeviceError| match e {
        DeviceError::UnsafeMove { reason, .. } => Ok(NotMeasured::arm_refused(&reason)),
        e => Err(PipelineError::Device(e)),
    };
    let above =
        |z: f64| Pose::tool_down_turned(DVec3::new(touch.x, touch.y, z), target.pad_yaw_rad);
    let safe = above(touch.z + config.safe_height_m);
    let start_z_m = touch.z + config.approach_clearance_mm * 1e-3;
    let approach = arm
        .move_linear(&safe, config.travel_speed_m_s)
        .and_then(|()| arm.move_linear(&above(start_z_m), config.travel_speed_m_s));
    if let Err(e) = approach {
        return Ok(Attempt::NotMeasured(refused(e)?));
    }
    let protocol = PressProtocol {
        max_search_steps: (config.max_search_mm / config.press.step_mm).ceil() as usize,
        ..config.press
    };
    let mut probe = ArmProbe {
        tactile,
        arm,
        touch,
        pad_yaw_rad: target.pad_yaw_rad,
        start_z_m,
        config,
    };
    let outcome = run_press(&protocol, &mut probe);
    // Whatever happened below, the pad goes back up before the next object.
    arm.move_linear(&safe, config.travel_speed_m_s)?;
    let pressed = match outcome {
        Ok(PressOutcome::Pressed(p)) => p,
        Ok(PressOutcome::NoContact { travel_mm, .. }) => {
            return Ok(Attempt::NotMeasured(NotMeasured::no_contact(travel_mm)));
        }
        Err(crate::press::protocol::PressError::Probe(e)) => {
            return Ok(Attempt::NotMeasured(refused(e)?));
        }
        Err(crate::press::protocol::PressError::Invalid(m)) => {
            return Err(PipelineError::Camera(format!("tactile sensor: {m}")));
        }
    };
    let (reference, _) = pressed.reference;
    let contact_z = pressed.frames[0].1;
    let travel_mm = pressed
        .frames
        .iter()
        .map(|(_, z)| (contact_z - z) * 1e3)
        .collect();
    let frames: Vec<TactileFrame> = pressed.frames.into_iter().map(|(f, _)| f).collect();
    if let Some(middle) = imprint_middle(&frames[0], &reference)
        && !((0.125..=0.875).contains(&middle.x) && (0.125..=0.875).contains(&middle.y))
    {
        // From the frame's middle to the imprint's, in the pad's frame, then the world's.
        let in_pad_mm = DVec3::new(
            (middle.x - 0.5) * pad_mm[0],
            (middle.y - 0.5) * pad_mm[1],
            0.0,
        );
        let in_world = above(0.0).rotation * in_pad_mm * 1e-3;
        return Ok(Attempt::Cut {
            offset_m: in_world.truncate(),
        });
    }
    Ok(Attempt::Pressed(Press {
        sequence: PressSequence {
            reference,
            frames,
            travel_mm,
        },
        search_mm: pressed.first_contact_step as f64 * config.press.step_mm,
        evidence: pressed.evidence,
        recentred_mm: None,
    }))
}

#[cfg(test)]
mod tests {
    //! The pipeline on fake devices: one apple under a downward camera, a gel that shows a
    //! disc once the pad is below the apple's top, and an arm that may refuse to go low.

    use super::*;
    use crate::frames::{DepthImage, RgbdFrame};
    use crate::geometry::CameraIntrinsics;
    use crate::ground::detect::Detection;
    use crate::hardness::estimate::{EstimateError, HardnessEstimate, PhysicsEvidence};
    use crate::hardness::scale::Hardness;
    use crate::tactile::spec::TactileSpec;
    use image::{GrayImage, Luma, Rgb, RgbImage};
    use std::cell::Cell;
    use std::rc::Rc;

    const TOP_M: f64 = 0.03;
    const K: CameraIntrinsics = CameraIntrinsics {
        width: 64,
        height: 48,
        fx: 60.0,
        fy: 60.0,
        cx: 32.0,
        cy: 24.0,
    };

    fn on_apple(x: u32, y: u32) -> bool {
        (x as f64 - 32.0).hypot(y as f64 - 24.0) < 14.0
    }

    struct Camera;
    impl RgbdCamera for Camera {
        fn name(&self) -> &str {
            "fake-camera"
        }
        fn intrinsics(&self) -> CameraIntrinsics {
            K
        }
        fn pose(&self) -> Pose {
            Pose::tool_down(DVec3::new(0.0, 0.0, 0.7))
        }
        fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
            Ok(RgbdFrame {
                color: RgbImage::from_fn(64, 48, |x, y| {
                    if on_apple(x, y) {
                        Rgb([180, 30, 30])
                    } else {
                        Rgb([120, 110, 100])
                    }
                }),
                depth_m: DepthImage::from_fn(64, 48, |x, y| {
                    Luma([if on_apple(x, y) {
                        0.7 - TOP_M as f32
                    } else {
                        0.7
                    }])
                }),
                timestamp_s: 0.0,
            })
        }
    }

    struct OneApple;
    impl Detector for OneApple {
        fn name(&self) -> &str {
            "one-apple"
        }
        fn detect(&self, _: &RgbdView<'_>) -> Result<Vec<Detection>, DetectError> {
            Ok(vec![Detection {
                label: "apple".into(),
                score: 0.9,
                bbox: [18, 10, 46, 38],
                mask: GrayImage::from_fn(64, 48, |x, y| Luma([255 * on_apple(x, y) as u8])),
                size_m: [0.07, 0.07, TOP_M],
            }])
        }
    }

    /// The gel shows a dark disc at `centre` growing with the pad's depth below the apple's
    /// top (never, when `shows` is false). With `object_m` the disc is instead where a point
    /// that far (world x, y) from the pad's first place lies under the pad, wherever the arm
    /// has put the pad since.
    struct Gel {
        z: Rc<Cell<f64>>,
        xy: Rc<Cell<(f64, f64)>>,
        first_xy: Cell<Option<(f64, f64)>>,
        centre: (f64, f64),
        object_m: Option<(f64, f64)>,
        shows: bool,
        spec: TactileSpec,
    }
    impl TactileSensor for Gel {
        fn name(&self) -> &str {
            "fake-gel"
        }
        fn spec(&self) -> &TactileSpec {
            &self.spec
        }
        fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
            let depth_mm = (TOP_M - self.z.get()) * 1e3;
            let radius = if self.shows && depth_mm > 0.0 {
                6.0 * depth_mm.sqrt()
            } else {
                0.0
            };
            // The pad's x along the world's, its y against it (`Pose::tool_down`).
            let first = *self.first_xy.get().get_or_insert(self.xy.get());
            self.first_xy.set(Some(first));
            let centre = self.object_m.map_or(self.centre, |(dx, dy)| {
                let (ox, oy) = (first.0 + dx, first.1 + dy);
                let (px, py) = self.xy.get();
                let mm_per_px = f64::from(self.spec.width_px) * self.spec.mm_per_px / 96.0;
                (
                    48.0 + (ox - px) * 1e3 / mm_per_px,
                    40.0 - (oy - py) * 1e3 / mm_per_px,
                )
            });
            Ok(TactileFrame {
                image: RgbImage::from_fn(96, 80, |x, y| {
                    let base = 120 + ((x * 7 + y * 13) % 17) as u8;
                    let r = (x as f64 - centre.0).hypot(y as f64 - centre.1);
                    if r < radius {
                        Rgb([base / 3, base / 2, base])
                    } else {
                        Rgb([base, base, base])
                    }
                }),
                timestamp_s: 0.0,
            })
        }
    }

    struct FakeArm {
        z: Rc<Cell<f64>>,
        xy: Rc<Cell<(f64, f64)>>,
        refuse_below_m: f64,
    }
    impl Arm for FakeArm {
        fn name(&self) -> &str {
            "fake-arm"
        }
        fn pose(&self) -> Result<Pose, DeviceError> {
            let (x, y) = self.xy.get();
            Ok(Pose::tool_down(DVec3::new(x, y, self.z.get())))
        }
        fn move_linear(&mut self, target: &Pose, _: f64) -> Result<(), DeviceError> {
            if target.position.z < self.refuse_below_m {
                return Err(DeviceError::UnsafeMove {
                    device: "fake-arm".into(),
                    reason: "crush limit".into(),
                });
            }
            self.z.set(target.position.z);
            self.xy.set((target.position.x, target.position.y));
            Ok(())
        }
        fn stop(&mut self) -> Result<(), DeviceError> {
            Ok(())
        }
    }

    /// Reads every press as 2 MPa: the pipeline is under test, not estimation.
    struct TwoMpa;
    impl HardnessEstimator for TwoMpa {
        fn name(&self) -> &str {
            "two-mpa"
        }
        fn estimate(
            &self,
            press: &PressSequence,
            _: &TactileSpec,
        ) -> Result<HardnessEstimate, EstimateError> {
            assert_eq!(press.frames.len(), 8);
            Ok(HardnessEstimate {
                hardness: Hardness::ModulusMpa(2.0),
                interval: ModulusInterval::log_normal(2f64.ln(), 0.1, "test"),
                evidence: Evidence::Physics(PhysicsEvidence {
                    gel_share: 0.1,
                    gel_share_se: 0.0,
                    local_radius_mm: 30.0,
                    first_contact_approach_mm: 0.1,
                    last_contact_radius_mm: 3.0,
                    last_gel_indentation_mm: 0.2,
                    frames_used: 8,
                    gel_layer_factor: 1.0,
                    fit_residual_rms: 0.0,
                    fit_residual_unit: "mm",
                    object_poisson: 0.35,
                    first_contact_aspect: None,
                }),
            })
        }
    }

    fn ask(centre: (f64, f64), shows: bool, refuse_below_m: f64) -> Answer {
        ask_on(centre, None, shows, refuse_below_m)
    }

    fn ask_on(
        centre: (f64, f64),
        object_m: Option<(f64, f64)>,
        shows: bool,
        refuse_below_m: f64,
    ) -> Answer {
        let z = Rc::new(Cell::new(0.3));
        let xy = Rc::new(Cell::new((0.0, 0.0)));
        let mut gel = Gel {
            z: z.clone(),
            xy: xy.clone(),
            first_xy: Cell::new(None),
            centre,
            object_m,
            shows,
            spec: TactileSpec::gelsight_mini(),
        };
        let mut arm = FakeArm {
            z,
            xy,
            refuse_below_m,
        };
        answer(
            "How hard is the apple?",
            &FruitCatalog::builtin(),
            Devices {
                camera: &mut Camera,
                tactile: &mut gel,
                arm: &mut arm,
            },
            &OneApple,
            &TwoMpa,
            &explain::TemplateExplainer,
            &PipelineConfig::default(),
        )
        .expect("the question is answered")
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
}
