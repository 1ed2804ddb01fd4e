//! Where the arm holds the board: stations that fix the camera's pose well. Each shows the
//! whole sheet to the camera (nominal pose: what the user measured by hand, or the twin's
//! scene), about half the image wide, tilted 15 to 35 degrees towards a direction that goes
//! round the circle by the golden angle and turned about its normal by up to 40 degrees
//! either way, so that the motions between stations turn about every axis (Tsai and Lenz's
//! conditioning: large turns, axes far apart). The sequence is deterministic: the same
//! request gives the same stations.

use super::HandEyeError;
use super::rotation_fit::{logarithm, symmetric_eigen};
use crate::charuco::CharucoBoard;
use crate::geometry::{CameraIntrinsics, Pose};
use glam::{DMat3, DQuat, DVec3};

/// What the stations are planned from.
#[derive(Clone, Copy, Debug)]
pub struct StationRequest {
    /// Where the camera is believed to stand (base frame, OpenCV's camera axes).
    pub camera_in_base: Pose,
    pub intrinsics: CameraIntrinsics,
    pub board: CharucoBoard,
    /// The white margin round the printed board (mm): the whole sheet stays in view.
    pub margin_mm: f64,
    /// The board's frame in the tool's (the pose the arm reports and moves).
    pub board_in_tool: Pose,
    pub stations: usize,
}

/// The sheet's width as a share of the image's when it faces the camera squarely.
const SHEET_SHARE_OF_WIDTH: f64 = 0.55;
/// The sheet's outline keeps this far inside the image (px).
const IMAGE_MARGIN_PX: f64 = 12.0;
/// Candidates tried per station before the plan gives up.
const TRIES_PER_STATION: usize = 40;
/// Most stations a plan holds: a camera is fixed well by 15; a hundred is a long afternoon.
pub const MAX_STATIONS: usize = 100;

/// The tool poses of `request.stations` stations in view and, by `reachable`, in the arm's
/// reach, or why there are not that many.
pub fn plan_stations(
    request: &StationRequest,
    reachable: impl Fn(&Pose) -> bool,
) -> Result<Vec<Pose>, HandEyeError> {
    let n = request.stations;
    if !(3..=MAX_STATIONS).contains(&n) {
        return Err(HandEyeError::StationCount(n));
    }
    request
        .intrinsics
        .check()
        .map_err(HandEyeError::BadIntrinsics)?;
    let k = &request.intrinsics;
    let (w_mm, h_mm) = request.board.size_mm();
    let m = request.margin_mm;
    let sheet_w_m = (w_mm + 2.0 * m) * 1e-3;
    let distance_m = k.fx * sheet_w_m / (SHEET_SHARE_OF_WIDTH * k.width as f64);
    let centre_on_board = DVec3::new(w_mm / 2.0, h_mm / 2.0, 0.0) * 1e-3;
    let outline = [
        (-m, -m),
        (w_mm + m, -m),
        (w_mm + m, h_mm + m),
        (-m, h_mm + m),
    ]
    .map(|(x, y)| DVec3::new(x, y, 0.0) * 1e-3);
    let mut out = Vec::with_capacity(n);
    let mut candidate = 0usize;
    let (mut out_of_view, mut out_of_reach, mut one_axis) = (0, 0, 0);
    while out.len() < n {
        if candidate >= TRIES_PER_STATION * n {
            return Err(HandEyeError::StationsOutOfReach {
                planned: out.len(),
                asked: n,
                tried: candidate,
                distance_m,
                out_of_view,
                out_of_reach,
                one_axis,
            });
        }
        let board_in_camera = candidate_pose(candidate, distance_m, k, centre_on_board);
        candidate += 1;
        let in_view = outline.iter().all(|p| {
            let c = board_in_camera.transform_point(*p);
            c.z > 0.0 && {
                let u = k.fx * c.x / c.z + k.cx;
                let v = k.fy * c.y / c.z + k.cy;
                (IMAGE_MARGIN_PX..k.width as f64 - IMAGE_MARGIN_PX).contains(&u)
                    && (IMAGE_MARGIN_PX..k.height as f64 - IMAGE_MARGIN_PX).contains(&v)
            }
        });
        if !in_view {
            out_of_view += 1;
            continue;
        }
        let tool = request
            .camera_in_base
            .compose(&board_in_camera)
            .compose(&request.board_in_tool.inverse());
        if !reachable(&tool) {
            out_of_reach += 1;
        } else if !turns_about_two_axes(&out, &tool) {
            one_axis += 1;
        } else {
            out.push(tool);
        }
    }
    Ok(out)
}

/// The motions' turns must span a second axis with at least this share of the first's
/// (the rotation vectors' second principal length over the first): both closed forms refuse
/// below about 0.03, and a station's noise tilts the axes.
const MIN_SECOND_AXIS_SPREAD: f64 = 0.2;

/// Whether the stations `so_far` with `tool` added turn about two axes well apart (always,
/// for fewer than three stations: two make one motion).
fn turns_about_two_axes(so_far: &[Pose], tool: &Pose) -> bool {
    if so_far.len() < 2 {
        return true;
    }
    let mut spread = DMat3::ZERO;
    let all: Vec<&Pose> = so_far.iter().chain(std::iter::once(tool)).collect();
    for (i, a) in all.iter().enumerate() {
        for b in &all[i + 1..] {
            let turn = logarithm(b.rotation * a.rotation.inverse());
            spread += DMat3::from_cols(turn * turn.x, turn * turn.y, turn * turn.z);
        }
    }
    let [first, second, _] = symmetric_eigen(spread).0;
    second >= MIN_SECOND_AXIS_SPREAD * MIN_SECOND_AXIS_SPREAD * first
}

/// Fractional part of i times an irrational step: an evenly spread sequence in [0, 1).
fn spread(i: usize, step: f64) -> f64 {
    (i as f64 * step).fract()
}

/// Candidate `i`: the board's frame in the camera's.
fn candidate_pose(i: usize, distance_m: f64, k: &CameraIntrinsics, centre_on_board: DVec3) -> Pose {
    let golden = (5f64.sqrt() - 1.0) / 2.0;
    let tilt = (15.0 + 20.0 * spread(i, 2f64.sqrt())).to_radians();
    let towards = std::f64::consts::TAU * spread(i, golden);
    let roll = (40.0 * (2.0 * spread(i, 3f64.sqrt()) - 1.0)).to_radians();
    let depth = distance_m * (0.9 + 0.25 * spread(i, 5f64.sqrt()));
    // The sheet's centre wanders over the middle of the image (a fifth of it each way).
    let u = k.cx + 0.2 * k.width as f64 * (2.0 * spread(i, 7f64.sqrt()) - 1.0);
    let v = k.cy + 0.2 * k.height as f64 * (2.0 * spread(i, 11f64.sqrt()) - 1.0);
    let centre = DVec3::new((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0) * depth;
    // Face on: the board's axes along the camera's, its printed face (-z) at the camera.
    let rotation = DQuat::from_axis_angle(DVec3::new(towards.cos(), towards.sin(), 0.0), tilt)
        * DQuat::from_rotation_z(roll);
    Pose::new(centre - rotation * centre_on_board, rotation)
}
