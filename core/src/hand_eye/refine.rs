//! The closed forms' answer refined on what the camera really measured: the board's corners
//! in the image. Each closed form sees a station only through the board's pose, whose depth
//! along the optical axis is its least certain part; minimising the corners' reprojection
//! error over the camera in the base (X) and the board on the flange (Z) together weighs
//! every corner by what the image fixes. Levenberg-Marquardt (`least_squares`) over the 12
//! parameters: a turn and a shift applied to each.

use super::board_pose::push_reprojection;
use super::least_squares::{levenberg_marquardt, nudged};
use super::{HandEyeError, HandEyeSolution, checked_pose};
use crate::geometry::{CameraIntrinsics, Pose};
use glam::DVec3;
use serde::Serialize;

/// A station with the board's corners as the camera saw them.
#[derive(Clone, Debug, PartialEq)]
pub struct CornerStation {
    pub flange_in_base: Pose,
    pub corners: Vec<BoardCorner>,
}

/// One corner: its place on the board (m, board frame) and where the camera saw it (px,
/// undistorted: the intrinsics are a pinhole).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoardCorner {
    pub on_board_m: DVec3,
    pub seen_px: [f64; 2],
}

/// The refined calibration, its reprojection error (px, RMS over every corner and per
/// station), and whether the steps stopped for lack of improvement (converged) or at the
/// iteration limit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RefinedHandEye {
    pub camera_in_base: Pose,
    pub board_in_flange: Pose,
    pub rms_px: f64,
    pub station_rms_px: Vec<f64>,
    pub iterations: usize,
    pub converged: bool,
}

const PARAMETERS: usize = 12;

/// Refines `start` (a closed form's solution) on the stations' corners.
pub fn refine_on_corners(
    stations: &[CornerStation],
    intrinsics: &CameraIntrinsics,
    start: &HandEyeSolution,
) -> Result<RefinedHandEye, HandEyeError> {
    let corners: usize = stations.iter().map(|s| s.corners.len()).sum();
    if stations.len() < 3 {
        return Err(HandEyeError::TooFewStations(stations.len()));
    }
    intrinsics.check().map_err(HandEyeError::BadIntrinsics)?;
    let stations = checked_corner_stations(stations)?;
    let stations = stations.as_slice();
    if corners < PARAMETERS {
        return Err(HandEyeError::TooFewCorners(corners));
    }
    let base = (start.camera_in_base, start.board_in_flange);
    let fit = levenberg_marquardt(&|p: &[f64; PARAMETERS]| {
        residuals(stations, intrinsics, &moved(&base, p))
    });
    let (p, r) = (fit.parameters, fit.residuals);
    let cost = |r: &[f64]| r.iter().map(|v| v * v).sum::<f64>();
    let err = cost(&r);
    let (camera_in_base, board_in_flange) = moved(&base, &p);
    let mut station_rms_px = Vec::with_capacity(stations.len());
    let mut at = 0;
    for s in stations {
        let n = 2 * s.corners.len();
        station_rms_px.push((cost(&r[at..at + n]) / s.corners.len() as f64).sqrt());
        at += n;
    }
    Ok(RefinedHandEye {
        camera_in_base,
        board_in_flange,
        rms_px: (err / corners as f64).sqrt(),
        station_rms_px,
        iterations: fit.iterations,
        converged: fit.converged,
    })
}

/// The stations with their flange quaternions normalised, or the first with no corners, a
/// pose that is not one, or a corner that is not a finite number.
fn checked_corner_stations(stations: &[CornerStation]) -> Result<Vec<CornerStation>, HandEyeError> {
    stations
        .iter()
        .enumerate()
        .map(|(station, s)| {
            let bad = |what: String| HandEyeError::BadStation { station, what };
            if s.corners.is_empty() {
                return Err(bad("no board corner was seen".into()));
            }
            let flange_in_base =
                checked_pose(&s.flange_in_base, "the flange's pose").map_err(bad)?;
            if let Some(k) = s
                .corners
                .iter()
                .position(|c| !c.on_board_m.is_finite() || !c.seen_px.iter().all(|v| v.is_finite()))
            {
                return Err(bad(format!("corner {k} is not a finite number")));
            }
            Ok(CornerStation {
                flange_in_base,
                corners: s.corners.clone(),
            })
        })
        .collect()
}

/// X and Z turned by p's rotation vectors and shifted by its translations (m).
fn moved(base: &(Pose, Pose), p: &[f64; PARAMETERS]) -> (Pose, Pose) {
    (nudged(&base.0, &p[..6]), nudged(&base.1, &p[6..]))
}

/// Each corner's projection through X^-1 F_i Z less its seen pixel, station by station.
fn residuals(
    stations: &[CornerStation],
    intrinsics: &CameraIntrinsics,
    (camera_in_base, board_in_flange): &(Pose, Pose),
) -> Vec<f64> {
    let base_in_camera = camera_in_base.inverse();
    let mut out = Vec::new();
    for s in stations {
        let board_in_camera = base_in_camera.compose(&s.flange_in_base.compose(board_in_flange));
        push_reprojection(&mut out, &s.corners, intrinsics, &board_in_camera);
    }
    out
}
