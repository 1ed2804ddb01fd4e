//! `BoardDetector` by OpenCV 4.6's `cv::aruco`: `detectMarkers` with the board's predefined
//! dictionary, then `interpolateCornersCharuco` (the inner corners between two found
//! markers, refined by `cornerSubPix`; OpenCV 4.6 leaves them half a pixel off, so they are
//! refined again in a window inside the gap to the markers).

use opencv::core::{Mat, Point2f, Vector};
use opencv::prelude::*;
use opencv::{aruco, core, imgproc};
use tactex_core::charuco::{
    ArucoDictionary, BoardDetector, BoardSighting, CharucoBoard, DetectError, SeenCorner,
};

/// The ChArUco detector of OpenCV's ArUco module, with its default parameters.
#[derive(Clone, Copy, Debug, Default)]
pub struct CharucoDetector;

/// A corner counts when at least this many markers next to it were found (OpenCV's own
/// default for `interpolateCornersCharuco` is 2: both neighbours).
const MIN_MARKERS: i32 = 2;

/// Samples a side of each marker cell when its bits are read (OpenCV's default is 4).
const PIXELS_PER_CELL: i32 = 8;

fn failed(e: opencv::Error) -> DetectError {
    DetectError(e.to_string())
}

fn dictionary(d: ArucoDictionary) -> aruco::PREDEFINED_DICTIONARY_NAME {
    use aruco::PREDEFINED_DICTIONARY_NAME::*;
    match d {
        ArucoDictionary::Dict4x4_50 => DICT_4X4_50,
        ArucoDictionary::Dict5x5_100 => DICT_5X5_100,
        ArucoDictionary::Dict6x6_250 => DICT_6X6_250,
    }
}

impl BoardDetector for CharucoDetector {
    fn name(&self) -> String {
        let version = core::get_version_string().unwrap_or_else(|_| "?".into());
        format!("OpenCV {version} aruco")
    }

    fn detect(
        &self,
        image: &image::RgbImage,
        board: &CharucoBoard,
    ) -> Result<BoardSighting, DetectError> {
        let (w, h) = image.dimensions();
        if w == 0 || h == 0 {
            return Ok(BoardSighting::default());
        }
        // OpenCV's own grey (BT.601 weights) of the colour image.
        let grey: Vec<u8> = image
            .pixels()
            .map(|p| {
                let [r, g, b] = p.0.map(f64::from);
                (0.299 * r + 0.587 * g + 0.114 * b).round() as u8
            })
            .collect();
        let grey = Mat::new_rows_cols_with_data(h as i32, w as i32, &grey)
            .and_then(|m| m.try_clone())
            .map_err(failed)?;
        let dict =
            aruco::get_predefined_dictionary(dictionary(board.dictionary)).map_err(failed)?;
        let cv_board = aruco::CharucoBoard::create(
            board.squares_x as i32,
            board.squares_y as i32,
            (board.square_mm / 1000.0) as f32,
            (board.marker_mm / 1000.0) as f32,
            &dict,
        )
        .map_err(failed)?;
        let mut params = aruco::DetectorParameters::create().map_err(failed)?;
        // Each marker cell read from 8 x 8 samples instead of OpenCV's 4 x 4: a marker of
        // 3 px cells tilted 35 degrees was lost or kept as the board moved by half a pixel.
        params.set_perspective_remove_pixel_per_cell(PIXELS_PER_CELL);
        let mut marker_corners = Vector::<Mat>::new();
        let mut marker_ids = Mat::default();
        let mut rejected = Vector::<Mat>::new();
        aruco::detect_markers(
            &grey,
            &dict,
            &mut marker_corners,
            &mut marker_ids,
            &params,
            &mut rejected,
        )
        .map_err(failed)?;
        let markers = marker_ids.rows().max(0) as usize;
        if markers == 0 {
            return Ok(BoardSighting::default());
        }
        let mut corners = Mat::default();
        let mut ids = Mat::default();
        let found = aruco::interpolate_corners_charuco(
            &marker_corners,
            &marker_ids,
            &grey,
            &cv_board,
            &mut corners,
            &mut ids,
            &core::no_array(),
            &core::no_array(),
            MIN_MARKERS,
        )
        .map_err(failed)?;
        let mut named = Vec::with_capacity(found.max(0) as usize);
        for i in 0..found {
            let id = *ids.at_2d::<i32>(i, 0).map_err(failed)?;
            let p = *corners.at_2d::<Point2f>(i, 0).map_err(failed)?;
            named.push((id as usize, p));
        }
        let named = refined(&grey, board, named).map_err(failed)?;
        let mut seen: Vec<SeenCorner> = named
            .into_iter()
            .map(|(id, p)| SeenCorner {
                id,
                px: [p.x as f64, p.y as f64],
            })
            .collect();
        seen.sort_by_key(|c| c.id);
        Ok(BoardSighting {
            markers,
            corners: seen,
        })
    }
}

/// The corners refined again by `cornerSubPix` in a window that stays inside the white gap
/// between a corner and its markers: OpenCV 4.6's interpolation refines in a window that
/// reaches the markers' borders, and left the twin's corners half a pixel off along both
/// axes (its own `cornerSubPix` on a bare chessboard corner is exact to 1e-3 px).
fn refined(
    grey: &Mat,
    board: &CharucoBoard,
    named: Vec<(usize, Point2f)>,
) -> opencv::Result<Vec<(usize, Point2f)>> {
    let Some(px_per_mm) = corner_spacing_px(board, &named).map(|s| s / board.square_mm) else {
        return Ok(named);
    };
    let gap_px = (board.square_mm - board.marker_mm) / 2.0 * px_per_mm;
    let half = ((0.7 * gap_px).floor() as i32).clamp(2, 10);
    let mut points: Vector<Point2f> = named.iter().map(|(_, p)| *p).collect();
    imgproc::corner_sub_pix(
        grey,
        &mut points,
        core::Size::new(half, half),
        core::Size::new(-1, -1),
        core::TermCriteria::new(core::TermCriteria_COUNT + core::TermCriteria_EPS, 40, 1e-3)?,
    )?;
    Ok(named
        .iter()
        .zip(points)
        .map(|((id, _), p)| (*id, p))
        .collect())
}

/// The median image distance (px) between corners found side by side on the board.
fn corner_spacing_px(board: &CharucoBoard, named: &[(usize, Point2f)]) -> Option<f64> {
    let across = board.squares_x - 1;
    let at: std::collections::HashMap<usize, Point2f> = named.iter().copied().collect();
    let mut d: Vec<f64> = named
        .iter()
        .flat_map(|(id, p)| {
            let right = (id % across + 1 < across)
                .then(|| at.get(&(id + 1)))
                .flatten();
            let below = at.get(&(id + across));
            [right, below]
                .into_iter()
                .flatten()
                .map(move |q| ((q.x - p.x) as f64).hypot((q.y - p.y) as f64))
        })
        .collect();
    if d.is_empty() {
        return None;
    }
    let k = d.len() / 2;
    Some(*d.select_nth_unstable_by(k, f64::total_cmp).1)
}
