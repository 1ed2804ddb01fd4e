//! Hand-eye calibration on the twin: the arm holds a ChArUco board at planned stations, the
//! scene camera (placed, if asked, off where the scene says by a known error the calibration
//! is not told) sees it with its own noise, a detector finds the corners, and every solver
//! places the camera; the twin knows the truth each is scored against.

use super::camera_placement::CameraPlacement;
use anyhow::{Context, Result};
use glam::{DQuat, DVec3};
use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::charuco::{BoardDetector, CharucoBoard};
use tactex_core::devices::RgbdCamera;
use tactex_core::geometry::Pose;
use tactex_core::hand_eye::{
    HandEyeRun, StationRequest, StationSighting, Visit, plan_stations, solve_sightings,
    visit_stations,
};
use tactex_sim::SimDevices;
use tactex_sim::render::board_view::SheetLook;
use tactex_sim::world::HeldBoard;

/// How far past the gel the board's sheet is held (m): mounted over the pad's face.
const MOUNT_OFFSET_M: f64 = 0.005;
/// The arm's speed between stations (m/s).
const STATION_SPEED_M_S: f64 = 0.2;

/// One calibration run on the twin, as asked.
#[derive(Clone, Debug)]
pub struct TwinHandEyeRequest<'a> {
    pub scene: &'a Path,
    pub board: CharucoBoard,
    pub stations: usize,
    /// Where the camera really stands against the scene's pose.
    pub placement: CameraPlacement,
    /// Seeds the camera's noise.
    pub seed: u64,
    /// Keep each station's frame in the answer.
    pub keep_frames: bool,
}

/// The run, and the twin's truth beside it.
#[derive(Clone, Debug)]
pub struct TwinHandEye {
    pub run: HandEyeRun,
    /// Where the scene puts the camera: what the calibration started from.
    pub believed: Pose,
    /// Where the twin's camera really stands.
    pub truth: Pose,
    /// What each station saw: the corners found (and its frame, if kept), in order.
    pub sightings: Vec<StationSighting>,
}

/// The board on the twin's tool: centred on the pad's axis, just past the gel, its printed
/// face looking where the pad points.
pub fn board_in_tool_on_twin(board: &CharucoBoard) -> Pose {
    let (w_mm, h_mm) = board.size_mm();
    // A half turn about the tool's x: the board's z (into the sheet) runs back along the
    // tool's -z, its y along the tool's -y.
    Pose::new(
        DVec3::new(-w_mm / 2.0 * 1e-3, h_mm / 2.0 * 1e-3, MOUNT_OFFSET_M),
        DQuat::from_rotation_x(std::f64::consts::PI),
    )
}

/// Calibrates the twin's camera by `detector`, telling `progress` after each station.
pub fn hand_eye_on_twin(
    request: &TwinHandEyeRequest,
    detector: &dyn BoardDetector,
    progress: impl FnMut(usize),
) -> Result<TwinHandEye> {
    let catalog = FruitCatalog::builtin();
    let (scene, _) = super::load_scene(request.scene, &catalog)?;
    let mut sim = SimDevices::from_scene(&scene, request.seed)
        .with_context(|| format!("{}: building the twin", request.scene.display()))?;
    let board_in_tool = board_in_tool_on_twin(&request.board);
    let look = SheetLook::default();
    request.placement.apply(&mut sim);
    let believed = sim.camera.pose();
    let held = HeldBoard {
        board: request.board,
        board_in_tool,
        look,
    };
    let (truth, intrinsics) = {
        let mut world = sim.world.lock().expect("world lock");
        world.held_board = Some(held.clone());
        (world.camera_pose, world.intrinsics)
    };
    let plan = plan_stations(
        &StationRequest {
            camera_in_base: believed,
            intrinsics,
            board: request.board,
            margin_mm: look.margin_mm,
            board_in_tool,
            stations: request.stations,
        },
        |tool| sim.arm.reaches(tool) && held.clears(&sim.world.lock().expect("world lock"), tool),
    )?;
    let sightings = visit_stations(
        &mut sim.arm,
        &mut sim.camera,
        detector,
        &Visit {
            board: &request.board,
            tool_poses: &plan,
            speed_m_s: STATION_SPEED_M_S,
            keep_images: request.keep_frames,
        },
        progress,
    )?;
    let run = solve_sightings(&sightings, &intrinsics)?;
    Ok(TwinHandEye {
        run,
        believed,
        truth,
        sightings,
    })
}

/// How far `found` is from `truth`: millimetres and degrees.
pub fn pose_error(found: &Pose, truth: &Pose) -> (f64, f64) {
    let q = found.rotation.inverse() * truth.rotation;
    (
        1000.0 * (found.position - truth.position).length(),
        (2.0 * q.xyz().length().atan2(q.w.abs())).to_degrees(),
    )
}
