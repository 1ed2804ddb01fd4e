//! `tactex compare --session DIR`: sim-to-real on a recorded session. Every tactile frame is
//! rebuilt in the twin with the pad at the pose it was taken at (the objects from the
//! manifest's scene for a session recorded on the twin, from `--scene` for a real one), and
//! each press is scored recorded against rebuilt at equal robot travel: per-frame SSIM (grey,
//! 7x7 uniform window, data range 255, as scikit-image), marker displacement error (each
//! marker's displacement from the press's no-contact frame, recorded against rebuilt), and
//! the hardness the pipeline's estimator reads from either press, both read with the twin's
//! sensor description, so that a gel that differs from the twin's shows as a hardness error.

use crate::app::estimator_choice::EstimatorChoice;
use crate::app::{load_sensor, with_gel_modulus};
use crate::report::output::{OutputDir, write_json_atomic, write_png_atomic};
#[cfg(feature = "plots")]
use crate::report::plot::{self, BarSeries};
use crate::report::side_by_side::side_by_side;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use image::RgbImage;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::{Path, PathBuf};
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::TactileSensor;
use tactex_core::frames::TactileFrame;
use tactex_core::hardness::estimate::{HardnessEstimator, PressSequence};
use tactex_core::hardness::scale::HardnessReport;
use tactex_core::press::protocol::{
    Look, PressError, PressOutcome, PressProbe, PressProtocol, run_press,
};
use tactex_core::scene::Scene;
use tactex_core::tactile::contact::ContactEvidence;
use tactex_core::tactile::markers::{detect_markers, track};
use tactex_core::tactile::spec::TactileSpec;
use tactex_core::tactile::ssim::ssim_rgb;
use tactex_hw::session::presses::press_runs;
use tactex_hw::session::{Manifest, open_session};
use tactex_sim::SimDevices;
use tactex_sim::contact::Fidelity;
use tactex_sim::contact::pad::{deepest_touch, pad_of};

/// What `compare --session` needs beside the session directory.
pub struct SessionCompare<'a> {
    pub session: &'a Path,
    /// The objects as they stood, for a session that does not carry its scene.
    pub scene: Option<&'a Path>,
    pub seed: Option<u64>,
    pub gel_modulus_mpa: Option<f64>,
    /// The twin's sensor profile (default the built-in GelSight Mini).
    pub sensor: Option<&'a Path>,
    /// The twin's contact physics for the rebuild.
    pub fidelity: Fidelity,
    pub estimator: &'a EstimatorChoice,
    pub out: Option<&'a Path>,
    pub json: bool,
}

#[derive(Serialize, Debug)]
pub struct FrameComparison {
    /// The recorded frame's file in the session.
    pub image: String,
    /// Arm travel past the press's first contact frame (mm; negative above it).
    pub travel_mm: f64,
    pub ssim: f64,
    /// Mean over the markers tracked in both of |recorded - rebuilt| displacement from the
    /// press's no-contact frame (px); None on the no-contact frame itself.
    pub marker_error_px: Option<f64>,
    /// Mean displacement of the same markers in the recorded frame (px), for scale.
    pub recorded_marker_px: Option<f64>,
    pub markers_compared: usize,
}

#[derive(Serialize, Debug)]
pub struct HardnessAgreement {
    pub recorded: HardnessReport,
    pub rebuilt: HardnessReport,
    /// Recorded minus rebuilt.
    pub shore_a_difference: f64,
    /// Recorded over rebuilt modulus (None when either reads rigid).
    pub modulus_ratio: Option<f64>,
}

#[derive(Serialize, Debug)]
pub struct PressReport {
    pub press: usize,
    /// The object the twin finds under the pad at the press's deepest frame.
    pub object: Option<String>,
    /// The pad at the press's deepest frame (world, m).
    pub position_m: [f64; 3],
    /// Frames taken at this spot, search included.
    pub frames_at_spot: usize,
    /// Index within those of the first frame the contact criterion calls contact, in the
    /// recorded frames (None: the press never touched), and its evidence.
    pub contact_frame: Option<usize>,
    pub contact: Option<ContactEvidence>,
    /// The no-contact frame, then the press frames from first contact on.
    pub frames: Vec<FrameComparison>,
    pub mean_ssim: f64,
    pub min_ssim: f64,
    pub mean_marker_error_px: Option<f64>,
    pub hardness: Option<HardnessAgreement>,
    pub warnings: Vec<String>,
}

#[derive(Serialize, Debug)]
pub struct SessionComparison {
    pub session: String,
    /// The backend the session was recorded on.
    pub recorded_backend: String,
    pub scene: String,
    pub seed: u64,
    /// The gel the recording's sensor describes, and the one the twin rebuilt with.
    pub recorded_gel_modulus_mpa: f64,
    pub twin_gel_modulus_mpa: f64,
    pub fidelity: String,
    pub estimator: String,
    pub presses: Vec<PressReport>,
    /// Over the press frames of every press (no-contact frames left out).
    pub mean_ssim: f64,
    pub min_ssim: f64,
    pub mean_marker_error_px: Option<f64>,
    /// Largest |recorded - rebuilt| Shore A over the presses with both estimates.
    pub max_shore_a_difference: Option<f64>,
    /// Every recorded tactile frame, and their mean SSIM (search frames included).
    pub frames: usize,
    pub all_frames_mean_ssim: f64,
}

/// The objects the twin rebuilds the presses among, and where that description came from.
fn session_scene(
    args: &SessionCompare,
    manifest: &Manifest,
    catalog: &FruitCatalog,
) -> Result<(Scene, String)> {
    if let Some(path) = args.scene {
        return Ok((Scene::load(path, catalog)?, path.display().to_string()));
    }
    let Some(twin) = &manifest.twin else {
        bail!(
            "{}: twin: the session carries no scene (recorded on '{}'); give --scene FILE with the objects as they stood",
            args.session.join("manifest.json").display(),
            manifest.backend
        );
    };
    // The text is the session's copy: an error in it is the session's, not the file the
    // scene was once read from (that path only anchors its meshes).
    let scene =
        Scene::parse(&twin.scene_toml, Path::new(&twin.scene_path), catalog).map_err(|e| {
            anyhow::anyhow!(
                "{}: twin.scene_toml (the scene recorded from {}): {}: {}",
                args.session.join("manifest.json").display(),
                twin.scene_path,
                e.field,
                e.message
            )
        })?;
    Ok((scene, format!("{} (from the session)", twin.scene_path)))
}

fn load_frame(dir: &Path, file: &str, timestamp_s: f64) -> Result<TactileFrame> {
    let path = dir.join(file);
    let image = tactex_core::image_file::open(&path)
        .map_err(|e| anyhow::anyhow!("{}: cannot read the recorded frame: {e}", path.display()))?
        .to_rgb8();
    Ok(TactileFrame { image, timestamp_s })
}

/// Each frame taken again in the twin, in recording order (so that a sim session's sensor
/// noise, drawn per frame from the seed, repeats).
fn rebuild_frames(sim: &mut SimDevices, manifest: &Manifest) -> Result<Vec<TactileFrame>> {
    let bar = ProgressBar::new(manifest.tactile.frames.len() as u64).with_style(
        ProgressStyle::with_template("rebuilding frames [{bar:40}] {pos}/{len}, eta {eta}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    let mut frames = Vec::with_capacity(manifest.tactile.frames.len());
    for record in &manifest.tactile.frames {
        sim.world.lock().expect("world lock").tool = record.arm_pose;
        frames.push(sim.tactile.capture()?);
        bar.inc(1);
    }
    bar.finish_and_clear();
    Ok(frames)
}

/// Marker displacements from `reference` in `frame`, per reference marker.
fn displacements(
    reference: &[(f64, f64)],
    frame: &RgbImage,
    pitch_px: f64,
) -> Vec<Option<(f64, f64)>> {
    track(reference, &detect_markers(frame), 0.45 * pitch_px)
}

/// Markers of the two no-contact frames paired (recorded index, rebuilt index) by nearest
/// neighbour within 0.45 pitch.
fn pair_markers(
    recorded: &[(f64, f64)],
    rebuilt: &[(f64, f64)],
    pitch_px: f64,
) -> Vec<(usize, usize)> {
    recorded
        .iter()
        .enumerate()
        .filter_map(|(i, r)| {
            rebuilt
                .iter()
                .enumerate()
                .map(|(j, s)| (j, (s.0 - r.0).hypot(s.1 - r.1)))
                .filter(|(_, d)| *d <= 0.45 * pitch_px)
                .min_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(j, _)| (i, j))
        })
        .collect()
}

/// A recorded descent read back by the press protocol: the spot's first two frames are its
/// no-contact frames, frame 1 + k the pad lowered k steps.
struct RecordedDescent<'a> {
    run: &'a [usize],
    recorded: &'a [TactileFrame],
    mm_per_px: f64,
}

/// The recording holds fewer frames at the spot than the protocol asks for.
struct RecordingEnds;

impl RecordedDescent<'_> {
    fn at(&self, k: usize) -> Result<usize, RecordingEnds> {
        self.run.get(k).copied().ok_or(RecordingEnds)
    }
}

impl PressProbe for RecordedDescent<'_> {
    type Frame = usize;
    type Error = RecordingEnds;

    fn look(&mut self, at: Look) -> Result<(RgbImage, usize), RecordingEnds> {
        let i = self.at(match at {
            Look::Reference => 0,
            Look::NoiseFloor => 1,
            Look::Search(k) => 1 + k,
        })?;
        Ok((self.recorded[i].image.clone(), i))
    }

    fn record(&mut self, k: usize) -> Result<usize, RecordingEnds> {
        self.at(1 + k)
    }

    fn mm_per_px(&self) -> f64 {
        self.mm_per_px
    }
}

/// The session's tactile frames beside their rebuilds, and the SSIM of each pair.
#[derive(Clone, Copy)]
struct FramePairs<'a> {
    manifest: &'a Manifest,
    recorded: &'a [TactileFrame],
    rebuilt: &'a [TactileFrame],
    ssim: &'a [f64],
}

/// Compares one press: `run` indexes the session's frames at one spot, highest first.
fn compare_press(
    index: usize,
    run: &[usize],
    pairs: &FramePairs,
    spec: &TactileSpec,
    sim: &SimDevices,
    scene: &Scene,
    estimator: &dyn HardnessEstimator,
) -> PressReport {
    let FramePairs {
        manifest,
        recorded,
        rebuilt,
        ssim: frame_ssim,
    } = *pairs;
    let pitch_px = spec.markers.pitch_mm / spec.mm_per_px;
    let mut warnings = Vec::new();
    let reference = run[0];
    let (rec_ref, sim_ref) = (&recorded[reference], &rebuilt[reference]);
    let rec_markers = detect_markers(&rec_ref.image);
    let sim_markers = detect_markers(&sim_ref.image);
    let marker_pairs = pair_markers(&rec_markers, &sim_markers, pitch_px);
    let protocol = PressProtocol {
        max_search_steps: run.len(),
        ..PressProtocol::default()
    };
    let mut descent = RecordedDescent {
        run,
        recorded,
        mm_per_px: spec.mm_per_px,
    };
    let (contact, evidence, press_frames) = match run_press(&protocol, &mut descent) {
        Ok(PressOutcome::Pressed(p)) => (
            run.iter().position(|&i| i == p.frames[0]),
            Some(p.evidence),
            p.frames,
        ),
        Ok(PressOutcome::NoContact { .. }) | Err(PressError::Probe(RecordingEnds)) => {
            warnings.push("the recorded frames never pass the contact criterion".into());
            (None, None, Vec::new())
        }
        Err(PressError::Invalid(m)) => {
            warnings.push(m);
            (None, None, Vec::new())
        }
    };
    let z = |i: usize| manifest.tactile.frames[i].arm_pose.position.z;
    let contact_z = press_frames.first().map_or(z(reference), |&i| z(i));
    let compare_frame = |i: usize, with_markers: bool| -> FrameComparison {
        let (mut error, mut scale, mut n) = (0.0, 0.0, 0usize);
        if with_markers {
            let d_rec = displacements(&rec_markers, &recorded[i].image, pitch_px);
            let d_sim = displacements(&sim_markers, &rebuilt[i].image, pitch_px);
            for &(r, s) in &marker_pairs {
                if let (Some(a), Some(b)) = (d_rec[r], d_sim[s]) {
                    error += (a.0 - b.0).hypot(a.1 - b.1);
                    scale += a.0.hypot(a.1);
                    n += 1;
                }
            }
        }
        FrameComparison {
            image: manifest.tactile.frames[i].image.clone(),
            travel_mm: (contact_z - z(i)) * 1e3,
            ssim: frame_ssim[i],
            marker_error_px: (n > 0).then(|| error / n as f64),
            recorded_marker_px: (n > 0).then(|| scale / n as f64),
            markers_compared: n,
        }
    };
    let mut frames = vec![compare_frame(reference, false)];
    frames.extend(press_frames.iter().map(|&i| compare_frame(i, true)));
    if markers_lost(&frames[1..]) {
        warnings.push("no marker was tracked in both the recorded and rebuilt frames".into());
    }

    let sequence = |all: &[TactileFrame]| PressSequence {
        reference: all[reference].clone(),
        frames: press_frames.iter().map(|&i| all[i].clone()).collect(),
        travel_mm: press_frames
            .iter()
            .map(|&i| (contact_z - z(i)) * 1e3)
            .collect(),
    };
    let hardness = if press_frames.len() >= 2 {
        let estimate = |all: &[TactileFrame], which: &str| {
            estimator
                .estimate(&sequence(all), spec)
                .map_err(|e| format!("{which} press: {e}"))
        };
        match (estimate(recorded, "recorded"), estimate(rebuilt, "rebuilt")) {
            (Ok(a), Ok(b)) => {
                let (a, b) = (
                    HardnessReport::from(a.hardness),
                    HardnessReport::from(b.hardness),
                );
                Some(HardnessAgreement {
                    shore_a_difference: a.shore_a - b.shore_a,
                    modulus_ratio: a.modulus_mpa.zip(b.modulus_mpa).map(|(x, y)| x / y),
                    recorded: a,
                    rebuilt: b,
                })
            }
            (a, b) => {
                warnings.extend(a.err().into_iter().chain(b.err()));
                None
            }
        }
    } else {
        None
    };

    let deepest = *run.last().expect("a run holds a frame");
    let pose = manifest.tactile.frames[deepest].arm_pose;
    let object = {
        let world = sim.world.lock().expect("world lock");
        deepest_touch(&world, &pose, &pad_of(spec)).map(|c| scene.objects[c.object].label.clone())
    };
    let scored = &frames[1..];
    let ssims: Vec<f64> = scored.iter().map(|f| f.ssim).collect();
    let errors: Vec<f64> = scored.iter().filter_map(|f| f.marker_error_px).collect();
    PressReport {
        press: index,
        object,
        position_m: pose.position.to_array(),
        frames_at_spot: run.len(),
        contact_frame: contact,
        contact: evidence,
        mean_ssim: tactex_core::stats::mean(&ssims).unwrap_or(f64::NAN),
        min_ssim: ssims.iter().copied().fold(f64::NAN, f64::min),
        mean_marker_error_px: tactex_core::stats::mean(&errors),
        frames,
        hardness,
        warnings,
    }
}

fn markers_lost(frames: &[FrameComparison]) -> bool {
    !frames.is_empty() && frames.iter().all(|f| f.markers_compared == 0)
}

/// Rebuilds every press of the session in the twin and scores recorded against rebuilt,
/// writing `--out` when given.
pub fn compare_session(args: &SessionCompare) -> Result<SessionComparison> {
    let catalog = FruitCatalog::builtin();
    let (manifest, ..) = open_session(args.session).context("--session")?;
    let (scene, scene_name) = session_scene(args, &manifest, &catalog)?;
    let seed = args
        .seed
        .or(manifest.twin.as_ref().map(|t| t.seed))
        .unwrap_or(0);
    let sensor = with_gel_modulus(load_sensor(args.sensor)?, args.gel_modulus_mpa)?;
    let spec = sensor.spec.clone();
    let recorded_spec = &manifest.tactile.spec;
    if (recorded_spec.width_px, recorded_spec.height_px) != (spec.width_px, spec.height_px) {
        bail!(
            "{}: tactile.spec: frames of {}x{} px; the twin's {} renders {}x{}",
            args.session.join("manifest.json").display(),
            recorded_spec.width_px,
            recorded_spec.height_px,
            spec.model,
            spec.width_px,
            spec.height_px
        );
    }
    if manifest.tactile.frames.is_empty() {
        bail!(
            "{}: tactile.frames: the session holds no tactile frame to compare",
            args.session.join("manifest.json").display()
        );
    }
    let recorded = manifest
        .tactile
        .frames
        .iter()
        .map(|f| load_frame(args.session, &f.image, f.timestamp_s))
        .collect::<Result<Vec<_>>>()?;
    if let Some(f) = recorded
        .iter()
        .zip(&manifest.tactile.frames)
        .find(|(f, _)| f.image.dimensions() != (spec.width_px, spec.height_px))
    {
        bail!(
            "{}: {}x{} px where the manifest says {}x{}",
            args.session.join(&f.1.image).display(),
            f.0.image.width(),
            f.0.image.height(),
            spec.width_px,
            spec.height_px
        );
    }
    let estimator = args.estimator.open(
        "--estimator",
        args.fidelity.name(),
        None,
        &sensor,
        args.sensor,
    )?;
    let mut sim = SimDevices::with_sensor(&scene, seed, sensor.clone(), args.fidelity)
        .with_context(|| format!("{scene_name}: the twin cannot stand it up"))?;
    let rebuilt = rebuild_frames(&mut sim, &manifest)?;

    let all: Vec<f64> = recorded
        .iter()
        .zip(&rebuilt)
        .map(|(a, b)| ssim_rgb(&a.image, &b.image).unwrap_or(f64::NAN))
        .collect();
    let pairs = FramePairs {
        manifest: &manifest,
        recorded: &recorded,
        rebuilt: &rebuilt,
        ssim: &all,
    };
    let presses: Vec<PressReport> = press_runs(&manifest.tactile.frames)
        .iter()
        .filter(|run| run.len() >= 2)
        .enumerate()
        .map(|(k, run)| compare_press(k, run, &pairs, &spec, &sim, &scene, estimator.as_ref()))
        .collect();
    let press_ssims: Vec<f64> = presses
        .iter()
        .flat_map(|p| p.frames[1..].iter().map(|f| f.ssim))
        .collect();
    let errors: Vec<f64> = presses
        .iter()
        .flat_map(|p| p.frames.iter().filter_map(|f| f.marker_error_px))
        .collect();
    let report = SessionComparison {
        session: args.session.display().to_string(),
        recorded_backend: manifest.backend.clone(),
        scene: scene_name,
        seed,
        recorded_gel_modulus_mpa: recorded_spec.gel.modulus_mpa,
        twin_gel_modulus_mpa: spec.gel.modulus_mpa,
        fidelity: args.fidelity.name().into(),
        estimator: estimator.name().into(),
        mean_ssim: tactex_core::stats::mean(&press_ssims).unwrap_or(f64::NAN),
        min_ssim: press_ssims.iter().copied().fold(f64::NAN, f64::min),
        mean_marker_error_px: tactex_core::stats::mean(&errors),
        max_shore_a_difference: presses
            .iter()
            .filter_map(|p| p.hardness.as_ref().map(|h| h.shore_a_difference.abs()))
            .reduce(f64::max),
        frames: all.len(),
        all_frames_mean_ssim: tactex_core::stats::mean(&all).unwrap_or(f64::NAN),
        presses,
    };
    if let Some(dir) = args.out {
        let out = OutputDir::create("--out", dir)?;
        write_outputs(out.path(), &report, &recorded, &rebuilt, &manifest)?;
        out.finish()?;
    }
    Ok(report)
}

pub(crate) fn run(args: &SessionCompare) -> Result<()> {
    let report = compare_session(args)?;
    print_json_or_text(&report, args.json, || {
        print_report(&report);
        Ok(())
    })?;
    Ok(())
}

/// compare-session.json, per press its deepest frame recorded | rebuilt | difference, and
/// the hardness read from either press as bars (hardness.png).
fn write_outputs(
    dir: &Path,
    report: &SessionComparison,
    recorded: &[TactileFrame],
    rebuilt: &[TactileFrame],
    manifest: &Manifest,
) -> Result<()> {
    for press in &report.presses {
        let Some(last) = press.frames.last() else {
            continue;
        };
        let i = manifest
            .tactile
            .frames
            .iter()
            .position(|f| f.image == last.image)
            .expect("the report's frames come from the manifest");
        let path: PathBuf = dir.join(format!("press-{:02}.png", press.press));
        write_png_atomic(&path, &side_by_side(&recorded[i].image, &rebuilt[i].image))?;
    }
    // Built without plots (the Python extension), the chart is left out; the JSON is whole.
    #[cfg(feature = "plots")]
    let measured: Vec<&PressReport> = report
        .presses
        .iter()
        .filter(|p| p.hardness.is_some())
        .collect();
    #[cfg(feature = "plots")]
    if !measured.is_empty() {
        let shore = |pick: fn(&HardnessAgreement) -> f64| -> Vec<f64> {
            measured
                .iter()
                .filter_map(|p| p.hardness.as_ref().map(pick))
                .collect()
        };
        plot::bars(
            &dir.join("hardness.png"),
            &format!(
                "Hardness read from each press: recorded (gel {} MPa) vs twin (gel {} MPa)",
                report.recorded_gel_modulus_mpa, report.twin_gel_modulus_mpa
            ),
            "Shore A",
            &measured
                .iter()
                .map(|p| format!("{} {}", p.press, p.object.as_deref().unwrap_or("?")))
                .collect::<Vec<_>>(),
            &[
                BarSeries {
                    name: "recorded".into(),
                    values: shore(|h| h.recorded.shore_a),
                },
                BarSeries {
                    name: "twin".into(),
                    values: shore(|h| h.rebuilt.shore_a),
                },
            ],
            false,
        )?;
    }
    write_json_atomic(&dir.join("compare-session.json"), report)
}

fn print_report(r: &SessionComparison) {
    println!(
        "{} ({}), scene {}, seed {}: recorded gel {:.3} MPa, twin gel {:.3} MPa",
        r.session,
        r.recorded_backend,
        r.scene,
        r.seed,
        r.recorded_gel_modulus_mpa,
        r.twin_gel_modulus_mpa
    );
    println!(
        "{:<5} {:<11} {:>7} {:>8} {:>8} {:>12} | {:>11} {:>11} {:>8}",
        "press",
        "object",
        "frames",
        "SSIM",
        "min",
        "marker err",
        "Shore A rec",
        "Shore A twin",
        "diff"
    );
    let opt = |v: Option<f64>, digits: usize| v.map_or("-".into(), |v| format!("{v:.digits$}"));
    for p in &r.presses {
        let h = p.hardness.as_ref();
        println!(
            "{:<5} {:<11} {:>7} {:>8.4} {:>8.4} {:>9} px | {:>11} {:>12} {:>8}",
            p.press,
            p.object.as_deref().unwrap_or("-"),
            p.frames.len() - 1,
            p.mean_ssim,
            p.min_ssim,
            opt(p.mean_marker_error_px, 2),
            opt(h.map(|h| h.recorded.shore_a), 1),
            opt(h.map(|h| h.rebuilt.shore_a), 1),
            opt(h.map(|h| h.shore_a_difference), 1),
        );
        for w in &p.warnings {
            println!("    warning: {w}");
        }
    }
    println!(
        "mean over press frames: SSIM {:.4} (min {:.4}), marker displacement error {} px; largest hardness difference {} Shore A; all {} frames' mean SSIM {:.4} ({}, twin at {})",
        r.mean_ssim,
        r.min_ssim,
        opt(r.mean_marker_error_px, 3),
        opt(r.max_shore_a_difference, 1),
        r.frames,
        r.all_frames_mean_ssim,
        r.estimator,
        r.fidelity
    );
}
