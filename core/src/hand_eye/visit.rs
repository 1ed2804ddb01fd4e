//! The calibration run on any devices: the arm holds the board at each planned station, the
//! camera takes a frame, the detector finds the corners; then every solver is run on what was
//! seen. Stations where too few corners were found are kept in the report as unseen (a
//! station behind the arm's own links is not a failed calibration), and the run is refused
//! only when fewer than three saw the board.

use super::{
    BoardCorner, CornerStation, HandEyeError, HandEyeMethod, HandEyeSolution, MIN_POSE_CORNERS,
    RefinedHandEye, Station, board_pose_from_corners, refine_on_corners, solve_hand_eye,
};
use crate::charuco::{BoardDetector, CharucoBoard};
use crate::devices::{Arm, DeviceError, RgbdCamera};
use crate::geometry::{CameraIntrinsics, Pose};
use serde::Serialize;

/// What one station gave: where the arm said the tool was, and the corners seen there.
#[derive(Clone, Debug)]
pub struct StationSighting {
    pub tool_in_base: Pose,
    /// Markers decoded.
    pub markers: usize,
    pub corners: Vec<BoardCorner>,
    /// The frame the corners were found in, when the run was asked to keep it.
    pub image: Option<image::RgbImage>,
}

/// A device or the detector failing during the run (not a board unseen).
#[derive(Debug, thiserror::Error)]
pub enum VisitError {
    #[error("station {station}: {source}")]
    Device { station: usize, source: DeviceError },
    #[error("station {station}: {source}")]
    Detector {
        station: usize,
        source: crate::charuco::DetectError,
    },
}

/// The stations to visit and how.
#[derive(Clone, Copy, Debug)]
pub struct Visit<'a> {
    pub board: &'a CharucoBoard,
    /// The tool's pose at each station (`plan_stations`).
    pub tool_poses: &'a [Pose],
    pub speed_m_s: f64,
    /// Keep each station's frame in its sighting (a report's images).
    pub keep_images: bool,
}

/// Moves through the visit's stations, capturing and detecting at each; `progress` is told
/// after each station.
pub fn visit_stations(
    arm: &mut dyn Arm,
    camera: &mut dyn RgbdCamera,
    detector: &dyn BoardDetector,
    visit: &Visit,
    mut progress: impl FnMut(usize),
) -> Result<Vec<StationSighting>, VisitError> {
    let Visit {
        board,
        tool_poses,
        speed_m_s,
        keep_images,
    } = *visit;
    let on_board = board.corners();
    let mut out = Vec::with_capacity(tool_poses.len());
    for (station, pose) in tool_poses.iter().enumerate() {
        let device = |source| VisitError::Device { station, source };
        arm.move_linear(pose, speed_m_s).map_err(device)?;
        let tool_in_base = arm.pose().map_err(device)?;
        let frame = camera.capture().map_err(device)?;
        let sighting = detector
            .detect(&frame.color, board)
            .map_err(|source| VisitError::Detector { station, source })?;
        let corners = sighting
            .corners
            .iter()
            .filter_map(|c| {
                on_board.get(c.id).map(|p| BoardCorner {
                    on_board_m: *p,
                    seen_px: c.px,
                })
            })
            .collect();
        out.push(StationSighting {
            tool_in_base,
            markers: sighting.markers,
            corners,
            image: keep_images.then_some(frame.color),
        });
        progress(station + 1);
    }
    Ok(out)
}

/// One station in the report: how much of the board was seen and how well each solution
/// explains it.
#[derive(Clone, Debug, Serialize)]
pub struct StationReport {
    pub station: usize,
    pub markers: usize,
    pub corners: usize,
    /// Why the station was left out (too few corners for a pose), if it was.
    pub unseen: Option<String>,
    /// The board's pose from this station's corners alone: its reprojection error (px RMS).
    pub board_pose_rms_px: Option<f64>,
    /// The refined solution's reprojection error over this station's corners (px RMS).
    pub refined_rms_px: Option<f64>,
}

/// Every solver's answer side by side, and the one kept: the closed forms (Tsai-Lenz,
/// Park-Martin) on the boards' poses, and the refinement on the corners started from the
/// closed form that explains the stations best.
#[derive(Clone, Debug, Serialize)]
pub struct HandEyeRun {
    pub tsai_lenz: HandEyeSolution,
    pub park_martin: HandEyeSolution,
    pub refined_from: HandEyeMethod,
    pub refined: RefinedHandEye,
    pub stations: Vec<StationReport>,
}

/// Solves the camera's pose from the stations' sightings.
pub fn solve_sightings(
    sightings: &[StationSighting],
    intrinsics: &CameraIntrinsics,
) -> Result<HandEyeRun, HandEyeError> {
    let mut reports = Vec::with_capacity(sightings.len());
    let (mut stations, mut corner_stations, mut used) = (Vec::new(), Vec::new(), Vec::new());
    for (i, s) in sightings.iter().enumerate() {
        let mut report = StationReport {
            station: i,
            markers: s.markers,
            corners: s.corners.len(),
            unseen: None,
            board_pose_rms_px: None,
            refined_rms_px: None,
        };
        if s.corners.len() < MIN_POSE_CORNERS {
            report.unseen = Some(format!(
                "{} corners found, a pose needs {MIN_POSE_CORNERS}",
                s.corners.len()
            ));
        } else {
            match board_pose_from_corners(&s.corners, intrinsics) {
                Ok(pose) => {
                    report.board_pose_rms_px = Some(pose.rms_px);
                    stations.push(Station {
                        flange_in_base: s.tool_in_base,
                        board_in_camera: pose.board_in_camera,
                    });
                    corner_stations.push(CornerStation {
                        flange_in_base: s.tool_in_base,
                        corners: s.corners.clone(),
                    });
                    used.push(i);
                }
                Err(e @ HandEyeError::BadIntrinsics(_)) => return Err(e),
                Err(e) => report.unseen = Some(e.to_string()),
            }
        }
        reports.push(report);
    }
    if stations.len() < 3 {
        return Err(HandEyeError::BoardUnseen {
            seen: stations.len(),
            stations: sightings.len(),
        });
    }
    let tsai_lenz = solve_hand_eye(&stations, HandEyeMethod::TsaiLenz)?;
    let park_martin = solve_hand_eye(&stations, HandEyeMethod::ParkMartin)?;
    let worst = |s: &HandEyeSolution| {
        s.residuals
            .iter()
            .map(|r| r.translation_mm)
            .fold(0.0, f64::max)
    };
    let start = if worst(&park_martin) <= worst(&tsai_lenz) {
        &park_martin
    } else {
        &tsai_lenz
    };
    let refined = refine_on_corners(&corner_stations, intrinsics, start)?;
    for (rms, i) in refined.station_rms_px.iter().zip(&used) {
        reports[*i].refined_rms_px = Some(*rms);
    }
    Ok(HandEyeRun {
        refined_from: start.method,
        tsai_lenz,
        park_martin,
        refined,
        stations: reports,
    })
}
