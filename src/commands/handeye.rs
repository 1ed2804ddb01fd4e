//! `tactex handeye`: where the scene camera stands in the arm's frame, from a ChArUco board
//! the arm holds at planned stations (eye-to-hand). On the twin the camera can be misplaced
//! by a known error first; every solver's answer is scored against the twin's truth. Writes
//! the calibration (the camera's pose, each solver's, residuals per station) as TOML.

use crate::app::camera_placement::CameraPlacement;
use crate::app::flag_range::{count, within};
use crate::app::hand_eye::{TwinHandEye, TwinHandEyeRequest, hand_eye_on_twin, pose_error};
use crate::report::output::{OutputDir, same_file, write_bytes_atomic, write_png_atomic};
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::{Path, PathBuf};
use tactex_core::charuco::{BoardDetector, CharucoBoard};
use tactex_core::geometry::Pose;
use tactex_core::hand_eye::calibration_file::CameraInBase;
use tactex_core::hand_eye::{
    BoardCorner, HandEyeSolution, MAX_STATIONS, MIN_POSE_CORNERS, StationReport,
};

#[derive(Args, Debug)]
pub struct HandEyeArgs {
    /// Which robot and camera: the twin (the scene's camera and the simulated arm).
    #[arg(long, value_enum, default_value = "twin")]
    pub backend: Backend,
    /// The scene the twin is built from (its camera is where the calibration starts);
    /// default the built-in demo scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Stations the arm holds the board at, 3 to 100.
    #[arg(long, default_value_t = 15, value_parser = count::<usize>(3, MAX_STATIONS as u64))]
    pub poses: usize,
    /// The calibration to write (TOML).
    #[arg(long)]
    pub out: PathBuf,
    /// The board's description (the TOML `tactex board` writes); the default 7 x 5 board
    /// otherwise.
    #[arg(long)]
    pub board: Option<PathBuf>,
    /// Twin: how far the camera really stands from where the scene puts it (mm), 0 to 200.
    #[arg(long, default_value_t = 0.0, value_parser = within(0.0, 200.0))]
    pub camera_error_mm: f64,
    /// Twin: how far it is turned from the scene's (degrees), 0 to 20.
    #[arg(long, default_value_t = 0.0, value_parser = within(0.0, 20.0))]
    pub camera_error_deg: f64,
    /// Twin: draws the directions the camera is moved and turned in (the same seed, the same
    /// misplaced rig: give `ask` the same to ask on it).
    #[arg(long, default_value_t = 1)]
    pub camera_error_seed: u64,
    /// Seeds the camera's noise.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write each station's frame with the corners found marked (station-NN.png).
    #[arg(long)]
    pub frames: Option<PathBuf>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Backend {
    Twin,
}

/// The board's detector this build has.
pub(crate) fn detector() -> Result<Box<dyn BoardDetector>> {
    #[cfg(feature = "opencv")]
    {
        Ok(Box::new(tactex_vision::CharucoDetector))
    }
    #[cfg(not(feature = "opencv"))]
    {
        bail!(
            "this tactex was built without OpenCV, which finds the board's corners: install libopencv-dev and libopencv-contrib-dev, then build with `cargo build --release --features opencv`"
        )
    }
}

fn load_board(path: &Option<PathBuf>) -> Result<CharucoBoard> {
    let Some(path) = path else {
        return Ok(CharucoBoard::default());
    };
    crate::app::file_input::present(path, "file: cannot read board")?;
    let text = tactex_core::text_file::read_to_string(path)
        .with_context(|| format!("{}: cannot read board", path.display()))?;
    let board: CharucoBoard = toml::from_str(&text).map_err(|e| {
        anyhow::anyhow!(
            "{}: {}",
            path.display(),
            e.message()
                .lines()
                .next()
                .unwrap_or("not a board description")
        )
    })?;
    board
        .check()
        .map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let corners = board.corners().len();
    if corners < MIN_POSE_CORNERS {
        bail!(
            "{}: a {} x {} board has {corners} inner corners; the board's pose needs {MIN_POSE_CORNERS}",
            path.display(),
            board.squares_x,
            board.squares_y
        );
    }
    Ok(board)
}

/// `--out` and `--frames` refused before the run where they cannot be written or would
/// replace an input.
fn check_outputs(args: &HandEyeArgs, scene: &Path) -> Result<()> {
    let out = &args.out;
    if out.is_dir() {
        bail!(
            "--out {}: is a directory; the calibration is a file",
            out.display()
        );
    }
    let folder = out.parent().filter(|p| !p.as_os_str().is_empty());
    if let Some(folder) = folder.filter(|f| !f.is_dir()) {
        bail!(
            "--out {}: {} is not a folder",
            out.display(),
            folder.display()
        );
    }
    let inputs = std::iter::once(scene).chain(args.board.as_deref());
    for input in inputs {
        if same_file(out, input) {
            bail!(
                "--out {}: is one of this command's inputs; nothing was written",
                out.display()
            );
        }
    }
    if let Some(frames) = &args.frames
        && (frames == out || same_file(frames, out))
    {
        bail!(
            "--frames {}: is where --out writes the calibration",
            frames.display()
        );
    }
    Ok(())
}

/// The calibration file: the camera's pose first, then how it was found.
#[derive(Serialize)]
struct CalibrationFile {
    camera: CameraInBase,
    fit: Fit,
    board: CharucoBoard,
    solvers: Vec<Solver>,
    #[serde(skip_serializing_if = "Option::is_none")]
    twin: Option<TwinTruth>,
    stations: Vec<Station>,
}

#[derive(Serialize)]
struct Fit {
    method: String,
    rms_px: f64,
    converged: bool,
    stations: usize,
    stations_used: usize,
}

#[derive(Serialize)]
struct Solver {
    method: &'static str,
    camera: CameraInBase,
    #[serde(skip_serializing_if = "Option::is_none")]
    median_residual_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    median_residual_deg: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error_mm: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    error_deg: Option<f64>,
}

#[derive(Serialize)]
struct TwinTruth {
    scene: String,
    seed: u64,
    camera_error_seed: u64,
    camera_error_mm: f64,
    camera_error_deg: f64,
    believed: CameraInBase,
    truth: CameraInBase,
}

#[derive(Serialize)]
struct Station {
    station: usize,
    markers: usize,
    corners: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    unseen: Option<String>,
    #[serde(skip_serializing_if = "Option::is_none")]
    board_pose_rms_px: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    refined_rms_px: Option<f64>,
}

impl From<&StationReport> for Station {
    fn from(s: &StationReport) -> Self {
        Self {
            station: s.station,
            markers: s.markers,
            corners: s.corners,
            unseen: s.unseen.clone(),
            board_pose_rms_px: s.board_pose_rms_px.map(round6),
            refined_rms_px: s.refined_rms_px.map(round6),
        }
    }
}

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6
}

fn closed_form(name: &'static str, s: &HandEyeSolution, truth: Option<&Pose>) -> Solver {
    let error = truth.map(|t| pose_error(&s.camera_in_base, t));
    Solver {
        method: name,
        camera: CameraInBase::of(&s.camera_in_base),
        median_residual_mm: Some(round6(median(
            s.residuals.iter().map(|r| r.translation_mm).collect(),
        ))),
        median_residual_deg: Some(round6(median(
            s.residuals.iter().map(|r| r.rotation_deg).collect(),
        ))),
        error_mm: error.map(|e| round6(e.0)),
        error_deg: error.map(|e| round6(e.1)),
    }
}

pub fn run(args: &HandEyeArgs) -> Result<()> {
    let board = load_board(&args.board)?;
    let scene = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    crate::app::file_input::present(&scene, "file: cannot read scene")?;
    check_outputs(args, &scene)?;
    let detector = detector()?;
    let bar = ProgressBar::new(args.poses as u64).with_style(
        ProgressStyle::with_template("handeye {bar:30} {pos}/{len} stations {elapsed}")
            .context("progress style")?,
    );
    let Backend::Twin = args.backend;
    let request = TwinHandEyeRequest {
        scene: &scene,
        board,
        stations: args.poses,
        placement: CameraPlacement::checked(
            args.camera_error_mm,
            args.camera_error_deg,
            args.camera_error_seed,
            None,
        )?,
        seed: args.seed,
        keep_frames: args.frames.is_some(),
    };
    let frames_dir = match &args.frames {
        Some(dir) => Some(OutputDir::create("--frames", dir)?),
        None => None,
    };
    let TwinHandEye {
        run,
        believed,
        truth,
        sightings,
    } = hand_eye_on_twin(&request, detector.as_ref(), |n| bar.set_position(n as u64))?;
    bar.finish_and_clear();
    let refined = &run.refined;
    let refined_error = pose_error(&refined.camera_in_base, &truth);
    let method = format!(
        "refined on the corners (from {})",
        match run.refined_from {
            tactex_core::hand_eye::HandEyeMethod::TsaiLenz => "Tsai-Lenz",
            tactex_core::hand_eye::HandEyeMethod::ParkMartin => "Park-Martin",
        }
    );
    let used = run.stations.iter().filter(|s| s.unseen.is_none()).count();
    let file = CalibrationFile {
        camera: CameraInBase::of(&refined.camera_in_base),
        fit: Fit {
            method: method.clone(),
            rms_px: round6(refined.rms_px),
            converged: refined.converged,
            stations: run.stations.len(),
            stations_used: used,
        },
        board,
        solvers: vec![
            closed_form("Tsai-Lenz", &run.tsai_lenz, Some(&truth)),
            closed_form("Park-Martin", &run.park_martin, Some(&truth)),
            Solver {
                method: "refined",
                camera: CameraInBase::of(&refined.camera_in_base),
                median_residual_mm: None,
                median_residual_deg: None,
                error_mm: Some(round6(refined_error.0)),
                error_deg: Some(round6(refined_error.1)),
            },
        ],
        twin: Some(TwinTruth {
            scene: scene.display().to_string(),
            seed: args.seed,
            camera_error_seed: args.camera_error_seed,
            camera_error_mm: request.placement.error_mm,
            camera_error_deg: request.placement.error_deg,
            believed: CameraInBase::of(&believed),
            truth: CameraInBase::of(&truth),
        }),
        stations: run.stations.iter().map(Station::from).collect(),
    };
    let text = format!(
        "# The scene camera's pose in the arm's frame, by `tactex handeye` (eye-to-hand, ChArUco).\n# camera.rotation_xyzw turns OpenCV's camera axes (x right, y down the image, z along the view) into the arm's frame.\n{}",
        toml::to_string(&file).context("writing the calibration's TOML")?
    );
    // The calibration first, the frames after: frames are only kept beside a calibration,
    // and a calibration whose frames could not be written is taken back.
    let existed = args.out.exists();
    write_bytes_atomic(&args.out, text.as_bytes()).map_err(|e| e.context("--out"))?;
    if let Some(dir) = frames_dir {
        let written = (|| -> Result<()> {
            for (i, s) in sightings.iter().enumerate() {
                if let Some(image) = &s.image {
                    let marked = marked_corners(image, &s.corners);
                    write_png_atomic(&dir.path().join(format!("station-{i:02}.png")), &marked)?;
                }
            }
            dir.finish()
        })();
        if let Err(e) = written {
            if !existed {
                let _ = std::fs::remove_file(&args.out);
            }
            return Err(e);
        }
    }
    print_json_or_text(&file, args.json, || {
        println!(
            "{}: camera at ({:.4}, {:.4}, {:.4}) m, {method}, {:.3} px RMS over {used} of {} stations",
            args.out.display(),
            refined.camera_in_base.position.x,
            refined.camera_in_base.position.y,
            refined.camera_in_base.position.z,
            refined.rms_px,
            run.stations.len()
        );
        let (before_mm, before_deg) = pose_error(&believed, &truth);
        println!(
            "twin truth: the scene's camera pose was {before_mm:.2} mm / {before_deg:.3} deg off"
        );
        println!("{:<12} {:>10} {:>10}", "solver", "error mm", "error deg");
        for s in &file.solvers {
            println!(
                "{:<12} {:>10.3} {:>10.4}",
                s.method,
                s.error_mm.unwrap_or(f64::NAN),
                s.error_deg.unwrap_or(f64::NAN)
            );
        }
        for s in run.stations.iter().filter(|s| s.unseen.is_some()) {
            println!(
                "station {}: left out: {}",
                s.station,
                s.unseen.as_deref().unwrap_or("")
            );
        }
        Ok(())
    })
}

/// The frame with a red cross on each corner found (5 px arms), for a person to check.
fn marked_corners(image: &image::RgbImage, corners: &[BoardCorner]) -> image::RgbImage {
    let mut out = image.clone();
    let (w, h) = (out.width() as i64, out.height() as i64);
    for c in corners {
        // Pixel x spans [x, x + 1): the corner's pixel is its coordinates' floor.
        let (x, y) = (c.seen_px[0].floor() as i64, c.seen_px[1].floor() as i64);
        for d in -5..=5 {
            for (px, py) in [(x + d, y), (x, y + d)] {
                if (0..w).contains(&px) && (0..h).contains(&py) {
                    out.put_pixel(px as u32, py as u32, image::Rgb([230, 30, 30]));
                }
            }
        }
    }
    out
}
