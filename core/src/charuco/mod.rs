//! The ChArUco calibration board: a chessboard whose white squares carry ArUco markers, so
//! every inner corner is named (by the markers round it) even when the board is partly
//! hidden. Its geometry (OpenCV 4.6's layout: markers in the squares whose column and row
//! differ in parity, numbered row by row; the board frame x right, y down the printed face,
//! z into the board), what it looks like at any point (for the twin's camera), and its
//! printable forms (`print`: a PNG and an SVG at true scale).

mod detect;
mod dictionary;
mod print;

pub use detect::{BoardDetector, BoardSighting, DetectError, SeenCorner};
pub use dictionary::ArucoDictionary;
pub use print::{board_image, board_svg};

use glam::DVec3;
use serde::{Deserialize, Serialize};

/// A ChArUco board: squares across and down, their side and their markers' side (mm), and
/// the dictionary the markers come from, its first markers in order.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CharucoBoard {
    pub squares_x: usize,
    pub squares_y: usize,
    pub square_mm: f64,
    pub marker_mm: f64,
    pub dictionary: ArucoDictionary,
}

impl Default for CharucoBoard {
    /// 7 x 5 squares of 30 mm with 22 mm markers from DICT_5X5_100: 210 x 150 mm, on an A4
    /// sheet with room for its margins, large enough for the scene camera at a metre.
    fn default() -> Self {
        Self {
            squares_x: 7,
            squares_y: 5,
            square_mm: 30.0,
            marker_mm: 22.0,
            dictionary: ArucoDictionary::Dict5x5_100,
        }
    }
}

/// Why a board cannot be made, naming the field.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum BoardError {
    #[error("{field} must be {range}; got {value}")]
    OutOfRange {
        field: &'static str,
        range: &'static str,
        value: String,
    },
    #[error(
        "marker_mm ({marker_mm}) must be smaller than square_mm ({square_mm}): a marker sits inside its square"
    )]
    MarkerTooLarge { marker_mm: f64, square_mm: f64 },
    #[error(
        "{squares_x} x {squares_y} squares need {needed} markers; {dictionary} has {available}"
    )]
    TooFewMarkers {
        squares_x: usize,
        squares_y: usize,
        needed: usize,
        dictionary: ArucoDictionary,
        available: usize,
    },
}

/// Most squares a side: a board's corners are named by marker ids, at most 250 of them.
const MAX_SQUARES: usize = 40;

/// One marker: its id and the square it sits in (column, row).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BoardMarker {
    pub id: usize,
    pub square: (usize, usize),
}

impl CharucoBoard {
    /// The board if it can be made, else which field is wrong.
    pub fn check(&self) -> Result<(), BoardError> {
        let squares = |field, value: usize| {
            (!(2..=MAX_SQUARES).contains(&value)).then(|| BoardError::OutOfRange {
                field,
                range: "2 to 40",
                value: value.to_string(),
            })
        };
        // A square under a millimetre, or a marker under half of one, is finer than a
        // printer or a camera resolves.
        let length = |field, value: f64, range: &'static str, lo: f64| {
            (!(value.is_finite() && value >= lo && value <= 1000.0)).then(|| {
                BoardError::OutOfRange {
                    field,
                    range,
                    value: value.to_string(),
                }
            })
        };
        let first = squares("squares_x", self.squares_x)
            .or_else(|| squares("squares_y", self.squares_y))
            .or_else(|| length("square_mm", self.square_mm, "1 to 1000 mm", 1.0))
            .or_else(|| length("marker_mm", self.marker_mm, "0.5 to 1000 mm", 0.5));
        if let Some(e) = first {
            return Err(e);
        }
        if self.marker_mm >= self.square_mm {
            return Err(BoardError::MarkerTooLarge {
                marker_mm: self.marker_mm,
                square_mm: self.square_mm,
            });
        }
        let needed = self.marker_count();
        if needed > self.dictionary.marker_count() {
            return Err(BoardError::TooFewMarkers {
                squares_x: self.squares_x,
                squares_y: self.squares_y,
                needed,
                dictionary: self.dictionary,
                available: self.dictionary.marker_count(),
            });
        }
        Ok(())
    }

    /// The board's printed size (mm), across and down.
    pub fn size_mm(&self) -> (f64, f64) {
        (
            self.squares_x as f64 * self.square_mm,
            self.squares_y as f64 * self.square_mm,
        )
    }

    /// Markers on the board: one in every white square.
    pub fn marker_count(&self) -> usize {
        self.squares_x * self.squares_y / 2
    }

    /// Every marker, by id: row by row, left to right, in the white squares (the top-left
    /// square is black).
    pub fn markers(&self) -> Vec<BoardMarker> {
        (0..self.squares_y)
            .flat_map(|y| (0..self.squares_x).map(move |x| (x, y)))
            .filter(|(x, y)| x % 2 != y % 2)
            .enumerate()
            .map(|(id, square)| BoardMarker { id, square })
            .collect()
    }

    /// The inner chessboard corners in the board frame (m), corner id k at index k: row by
    /// row, `(squares_x - 1) * (squares_y - 1)` of them.
    pub fn corners(&self) -> Vec<DVec3> {
        let s = self.square_mm / 1000.0;
        (1..self.squares_y)
            .flat_map(|y| {
                (1..self.squares_x).map(move |x| DVec3::new(x as f64 * s, y as f64 * s, 0.0))
            })
            .collect()
    }

    /// The printed face, its markers' bits looked up once.
    pub fn face(&self) -> BoardFace {
        BoardFace {
            board: *self,
            markers: (0..self.marker_count())
                .map(|id| self.dictionary.marker(id).unwrap_or_default())
                .collect(),
        }
    }
}

/// A board's printed face: what colour it is at any point.
#[derive(Clone, Debug)]
pub struct BoardFace {
    board: CharucoBoard,
    markers: Vec<Vec<bool>>,
}

impl BoardFace {
    /// The board this is the face of.
    pub fn board(&self) -> &CharucoBoard {
        &self.board
    }

    /// Whether the face is white at (x, y) mm in the board frame; the paper round the board
    /// is white.
    pub fn is_white(&self, x_mm: f64, y_mm: f64) -> bool {
        let b = &self.board;
        let (w, h) = b.size_mm();
        if !(0.0..w).contains(&x_mm) || !(0.0..h).contains(&y_mm) {
            return true;
        }
        let (col, row) = ((x_mm / b.square_mm) as usize, (y_mm / b.square_mm) as usize);
        if col % 2 == row % 2 {
            return false;
        }
        let inset = (b.square_mm - b.marker_mm) / 2.0;
        let (u, v) = (
            x_mm - col as f64 * b.square_mm - inset,
            y_mm - row as f64 * b.square_mm - inset,
        );
        if !(0.0..b.marker_mm).contains(&u) || !(0.0..b.marker_mm).contains(&v) {
            return true;
        }
        let bits = b.dictionary.marker_bits();
        let cells = bits + 2;
        let cell = |t: f64| ((t / b.marker_mm * cells as f64) as usize).min(cells - 1);
        let (cx, cy) = (cell(u), cell(v));
        if cx == 0 || cy == 0 || cx == cells - 1 || cy == cells - 1 {
            return false;
        }
        // White squares alternate in row-major order, so a square's marker id is its index / 2.
        let id = (row * b.squares_x + col) / 2;
        self.markers
            .get(id)
            .is_some_and(|m| m[(cy - 1) * bits + (cx - 1)])
    }
}

#[cfg(test)]
mod tests;
