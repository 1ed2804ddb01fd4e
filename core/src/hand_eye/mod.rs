//! Hand-eye calibration, eye-to-hand: where a fixed camera stands in the robot's base frame,
//! from stations at which the arm holds a calibration board on its flange and the camera
//! sees it (TactEx calibrates its RealSense to the xArm so with a ChArUco board). At station
//! i the flange's pose F_i (the arm's kinematics) and the board's pose C_i in the camera
//! (from its corners) close a loop with the two unknowns, the camera in the base X and the
//! board on the flange Z: F_i Z = X C_i. Between stations i and j that is A X = X B, with
//! A = F_j F_i^-1 (the flange's motion, base frame) and B = C_j C_i^-1 (the board's motion,
//! camera frame).
//!
//! The rotation comes from either closed form (`HandEyeMethod`), the translation from the
//! stacked (R_A - I) t_X = R_X t_B - t_A by least squares; each station's residual is the
//! board's pose predicted from X and Z against the one seen. `refine_on_corners` then
//! refines X and Z together on the board corners' reprojection error.

mod board_pose;
pub mod calibration_file;
mod least_squares;
mod plan;
mod refine;
mod rotation_fit;
mod visit;

pub use board_pose::{BoardPose, MIN_POSE_CORNERS, board_pose_from_corners};
pub use plan::{MAX_STATIONS, StationRequest, plan_stations};
pub use refine::{BoardCorner, CornerStation, RefinedHandEye, refine_on_corners};
pub use visit::{
    HandEyeRun, StationReport, StationSighting, Visit, VisitError, solve_sightings, visit_stations,
};

use crate::geometry::Pose;
use glam::{DMat3, DQuat, DVec3};
use serde::Serialize;

/// One station: the flange in the base frame and the board as the camera saw it (positions
/// in metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Station {
    pub flange_in_base: Pose,
    pub board_in_camera: Pose,
}

/// How the camera's rotation is solved from the stations' motions.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum HandEyeMethod {
    /// Tsai and Lenz (1989): modified Rodrigues vectors, linear least squares.
    TsaiLenz,
    /// Park and Martin (1994): rotation logarithms aligned by orthogonal Procrustes.
    ParkMartin,
}

/// The calibration: the camera in the base, the board on the flange, and how well they
/// explain each station.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HandEyeSolution {
    pub method: HandEyeMethod,
    pub camera_in_base: Pose,
    pub board_in_flange: Pose,
    pub residuals: Vec<StationResidual>,
}

/// A station's board pose predicted by the solution against the one seen.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct StationResidual {
    pub rotation_deg: f64,
    pub translation_mm: f64,
}

/// Station sets that cannot fix the camera's pose, each named for what is missing.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum HandEyeError {
    #[error("hand-eye needs at least 3 stations; got {0}")]
    TooFewStations(usize),
    #[error(
        "no pair of stations turns the flange by 2 to 175 degrees (pure translations fix no camera rotation); turn the flange between stations"
    )]
    NoRotation,
    #[error(
        "the corners' refinement needs at least 12 corners over all stations (6 unknowns each for the camera and the board); got {0}"
    )]
    TooFewCorners(usize),
    #[error(
        "every motion turns the flange about one axis, so the camera's turn about it and its offset along it are unknown; turn it about at least two axes"
    )]
    OneAxis,
    #[error("a board's pose needs at least 6 of its corners seen; got {0}")]
    TooFewBoardCorners(usize),
    #[error("the board's corners lie on one line, which fixes no pose")]
    CornersOnALine,
    #[error("a board corner's position or pixel is not a finite number")]
    BoardCornersNotFinite,
    #[error("station {station}: {what}")]
    BadStation { station: usize, what: String },
    #[error("the camera's intrinsics: {0}")]
    BadIntrinsics(String),
    #[error("a station plan holds 3 to {max} stations; asked for {0}", max = plan::MAX_STATIONS)]
    StationCount(usize),
    #[error(
        "only {planned} of {asked} stations could be planned: of {tried} places for the board, about {distance_m:.2} m from the camera and half the image wide, {out_of_view} left part of it out of the image, {out_of_reach} put the tool or the board where the arm cannot hold it, {one_axis} added no second axis of turn; check the camera's pose and the board's size"
    )]
    StationsOutOfReach {
        planned: usize,
        asked: usize,
        tried: usize,
        distance_m: f64,
        out_of_view: usize,
        out_of_reach: usize,
        one_axis: usize,
    },
    #[error(
        "the board was seen at {seen} of {stations} stations; the camera's pose needs at least 3 (is the board in view and lit, the dictionary the printed one, and the camera near where it is believed to stand?)"
    )]
    BoardUnseen { seen: usize, stations: usize },
}

/// The smallest turn (degrees) a pair of stations must make to count as a rotation: below
/// it, a pose estimate's noise is the motion's axis.
const MIN_TURN_DEG: f64 = 2.0;
/// The largest turn (degrees) a pair may make: near a half turn the motion's axis keeps its
/// line but loses its sign (Park-Martin's logarithm) and Tsai-Lenz's tan(angle/2) runs off.
const MAX_TURN_DEG: f64 = 175.0;
/// How far from 1 a station's quaternion's length may be (rounding in a file) before it is
/// taken for a mistake rather than normalised.
const UNIT_QUATERNION_TOLERANCE: f64 = 1e-3;
/// The second rotation axis must carry at least this share of the first's weight.
const MIN_SECOND_AXIS_SHARE: f64 = 1e-3;

/// The camera's pose in the base from the stations, by `method`.
pub fn solve_hand_eye(
    stations: &[Station],
    method: HandEyeMethod,
) -> Result<HandEyeSolution, HandEyeError> {
    if stations.len() < 3 {
        return Err(HandEyeError::TooFewStations(stations.len()));
    }
    let stations = checked_stations(stations)?;
    let stations = stations.as_slice();
    let motions = motions(stations);
    if motions.is_empty() {
        return Err(HandEyeError::NoRotation);
    }
    let rotation = match method {
        HandEyeMethod::TsaiLenz => rotation_fit::tsai_lenz(&motions),
        HandEyeMethod::ParkMartin => rotation_fit::park_martin(&motions),
    }?;
    let position = translation(&motions, rotation)?;
    let camera_in_base = Pose::new(position, rotation);
    let board_in_flange = board_on_flange(stations, &camera_in_base);
    let residuals = stations
        .iter()
        .map(|s| residual(s, &camera_in_base, &board_in_flange))
        .collect();
    Ok(HandEyeSolution {
        method,
        camera_in_base,
        board_in_flange,
        residuals,
    })
}

/// A pair of stations' motions: A (the flange, base frame) and B (the board, camera frame).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Motion {
    pub a: Pose,
    pub b: Pose,
}

/// The stations with their quaternions normalised, or the first whose pose is not a pose:
/// a NaN would otherwise pass through every sum into the answer.
fn checked_stations(stations: &[Station]) -> Result<Vec<Station>, HandEyeError> {
    stations
        .iter()
        .enumerate()
        .map(|(station, s)| {
            let flange_in_base = checked_pose(&s.flange_in_base, "the flange's pose")
                .map_err(|what| HandEyeError::BadStation { station, what })?;
            let board_in_camera = checked_pose(&s.board_in_camera, "the board's pose")
                .map_err(|what| HandEyeError::BadStation { station, what })?;
            Ok(Station {
                flange_in_base,
                board_in_camera,
            })
        })
        .collect()
}

/// `pose` with its quaternion normalised, or why it is not a pose.
pub(crate) fn checked_pose(pose: &Pose, name: &str) -> Result<Pose, String> {
    if !pose.position.is_finite() {
        return Err(format!("{name} has a position that is not a finite number"));
    }
    let length = pose.rotation.length();
    if !length.is_finite() || (length - 1.0).abs() > UNIT_QUATERNION_TOLERANCE {
        return Err(format!(
            "{name} has a rotation quaternion of length {length:.4} (a rotation's is 1)"
        ));
    }
    Ok(Pose::new(pose.position, pose.rotation / length))
}

/// Every pair of stations whose flange turned by at least `MIN_TURN_DEG` and at most
/// `MAX_TURN_DEG`: all pairs, not only consecutive ones, so that no station's noise weighs
/// more than another's.
fn motions(stations: &[Station]) -> Vec<Motion> {
    let mut out = Vec::new();
    for (i, si) in stations.iter().enumerate() {
        for sj in &stations[i + 1..] {
            let a = sj.flange_in_base.compose(&si.flange_in_base.inverse());
            let b = sj.board_in_camera.compose(&si.board_in_camera.inverse());
            if (MIN_TURN_DEG..=MAX_TURN_DEG).contains(&turn_deg(a.rotation)) {
                out.push(Motion { a, b });
            }
        }
    }
    out
}

/// A rotation's angle in degrees, 0 to 180.
fn turn_deg(q: DQuat) -> f64 {
    // atan2 of the vector part's length keeps small turns exact (acos near 1 does not).
    (2.0 * DVec3::new(q.x, q.y, q.z).length().atan2(q.w.abs())).to_degrees()
}

/// t_X from (R_A - I) t_X = R_X t_B - t_A over every motion (normal equations); a motion
/// about one axis leaves t_X's part along it free.
fn translation(motions: &[Motion], rotation: DQuat) -> Result<DVec3, HandEyeError> {
    let mut normal = DMat3::ZERO;
    let mut rhs = DVec3::ZERO;
    for m in motions {
        let c = DMat3::from_quat(m.a.rotation) - DMat3::IDENTITY;
        let d = rotation * m.b.position - m.a.position;
        normal += c.transpose() * c;
        rhs += c.transpose() * d;
    }
    let [largest, _, smallest] = rotation_fit::symmetric_eigen(normal).0;
    if smallest <= MIN_SECOND_AXIS_SHARE * largest {
        return Err(HandEyeError::OneAxis);
    }
    Ok(normal.inverse() * rhs)
}

/// Z = F_i^-1 X C_i averaged over the stations (rotations by their normalised quaternion sum,
/// signs aligned to the first).
fn board_on_flange(stations: &[Station], camera_in_base: &Pose) -> Pose {
    let each: Vec<Pose> = stations
        .iter()
        .map(|s| {
            s.flange_in_base
                .inverse()
                .compose(&camera_in_base.compose(&s.board_in_camera))
        })
        .collect();
    let first = each[0].rotation;
    let mut sum = DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    let mut position = DVec3::ZERO;
    for z in &each {
        let q = if z.rotation.dot(first) < 0.0 {
            -z.rotation
        } else {
            z.rotation
        };
        sum += q;
        position += z.position;
    }
    Pose::new(position / each.len() as f64, sum.normalize())
}

/// The board's pose the solution predicts at a station (X^-1 F_i Z) against the one seen.
fn residual(station: &Station, camera_in_base: &Pose, board_in_flange: &Pose) -> StationResidual {
    let predicted = camera_in_base
        .inverse()
        .compose(&station.flange_in_base.compose(board_in_flange));
    let seen = station.board_in_camera;
    StationResidual {
        rotation_deg: turn_deg(predicted.rotation.inverse() * seen.rotation),
        translation_mm: 1000.0 * (predicted.position - seen.position).length(),
    }
}

#[cfg(test)]
mod tests;
