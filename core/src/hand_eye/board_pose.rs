//! The board's pose in the camera from its corners (planar PnP): the homography from the
//! board's plane to the normalised image by linear least squares (points centred and scaled
//! first, Hartley's conditioning), split into a rotation and a translation (Zhang 2000), then
//! refined on the corners' reprojection error.

use super::least_squares::{levenberg_marquardt, nudged, solve};
use super::{BoardCorner, HandEyeError};
use crate::geometry::{CameraIntrinsics, Pose};
use glam::{DMat3, DQuat, DVec3};
use serde::Serialize;

/// A board's pose seen from its corners, with its reprojection error (px, RMS per corner).
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct BoardPose {
    pub board_in_camera: Pose,
    pub rms_px: f64,
}

/// Fewest corners a pose is taken from: four fix a homography; six leave a check.
pub const MIN_POSE_CORNERS: usize = 6;

/// The board's pose from its corners on a flat board (every `on_board_m` with z = 0), seen
/// through `intrinsics`.
pub fn board_pose_from_corners(
    corners: &[BoardCorner],
    intrinsics: &CameraIntrinsics,
) -> Result<BoardPose, HandEyeError> {
    intrinsics.check().map_err(HandEyeError::BadIntrinsics)?;
    if corners.len() < MIN_POSE_CORNERS {
        return Err(HandEyeError::TooFewBoardCorners(corners.len()));
    }
    let finite = corners
        .iter()
        .all(|c| c.on_board_m.is_finite() && c.seen_px.iter().all(|v| v.is_finite()));
    if !finite {
        return Err(HandEyeError::BoardCornersNotFinite);
    }
    let start = homography_pose(corners, intrinsics).ok_or(HandEyeError::CornersOnALine)?;
    let fit = levenberg_marquardt(&|p: &[f64; 6]| {
        let mut r = Vec::with_capacity(2 * corners.len());
        push_reprojection(&mut r, corners, intrinsics, &nudged(&start, p));
        r
    });
    let rms_px = (fit.residuals.iter().map(|r| r * r).sum::<f64>() / corners.len() as f64).sqrt();
    Ok(BoardPose {
        board_in_camera: nudged(&start, &fit.parameters),
        rms_px,
    })
}

/// The pose a homography gives, or None when the corners fix none (on one line).
fn homography_pose(corners: &[BoardCorner], k: &CameraIntrinsics) -> Option<Pose> {
    let n = corners.len() as f64;
    let mean = corners.iter().map(|c| c.on_board_m).sum::<DVec3>() / n;
    let spread = corners
        .iter()
        .map(|c| (c.on_board_m - mean).truncate().length())
        .sum::<f64>()
        / n;
    if spread <= 0.0 {
        return None;
    }
    let scale = std::f64::consts::SQRT_2 / spread;
    // Board (X, Y) conditioned -> normalised image (x, y), h33 = 1: eight unknowns.
    let mut normal = [[0.0f64; 8]; 8];
    let mut rhs = [0.0f64; 8];
    for c in corners {
        let (bx, by) = (
            (c.on_board_m.x - mean.x) * scale,
            (c.on_board_m.y - mean.y) * scale,
        );
        let x = (c.seen_px[0] - k.cx) / k.fx;
        let y = (c.seen_px[1] - k.cy) / k.fy;
        for (row, target) in [
            ([bx, by, 1.0, 0.0, 0.0, 0.0, -x * bx, -x * by], x),
            ([0.0, 0.0, 0.0, bx, by, 1.0, -y * bx, -y * by], y),
        ] {
            for a in 0..8 {
                rhs[a] += row[a] * target;
                for b in 0..8 {
                    normal[a][b] += row[a] * row[b];
                }
            }
        }
    }
    let h = solve(normal, rhs)?;
    // Undo the conditioning: H = H' T with T (X, Y) = scale (X - mean).
    let conditioned = DMat3::from_cols(
        DVec3::new(h[0], h[3], h[6]),
        DVec3::new(h[1], h[4], h[7]),
        DVec3::new(h[2], h[5], 1.0),
    );
    let t = DMat3::from_cols(
        DVec3::new(scale, 0.0, 0.0),
        DVec3::new(0.0, scale, 0.0),
        DVec3::new(-scale * mean.x, -scale * mean.y, 1.0),
    );
    let hm = conditioned * t;
    let (h1, h2, h3) = (hm.x_axis, hm.y_axis, hm.z_axis);
    // H = s [r1 r2 t]; the board lies in front of the camera (t.z > 0).
    let mut s = 2.0 / (h1.length() + h2.length());
    if (h3 * s).z < 0.0 {
        s = -s;
    }
    let r1 = (h1 * s).try_normalize()?;
    let r2 = (h2 * s - r1 * r1.dot(h2 * s)).try_normalize()?;
    let rotation = DQuat::from_mat3(&DMat3::from_cols(r1, r2, r1.cross(r2)));
    Some(Pose::new(h3 * s, rotation))
}

/// Each corner's projection through `board_in_camera` less where it was seen (u then v),
/// appended to `out`; a corner behind the camera counts as far off.
pub(super) fn push_reprojection(
    out: &mut Vec<f64>,
    corners: &[BoardCorner],
    k: &CameraIntrinsics,
    board_in_camera: &Pose,
) {
    for c in corners {
        let (u, v) = k
            .project(board_in_camera.transform_point(c.on_board_m))
            .unwrap_or((1e6, 1e6));
        out.push(u - c.seen_px[0]);
        out.push(v - c.seen_px[1]);
    }
}
