//! A sensor's marker grid read from a real frame: how many columns and rows of dots, their
//! pitch, size and darkness, for a sensor profile (`tactex calibrate --markers`). A frame
//! with a press works as well as a flat one: columns and rows are told apart by the pitch,
//! and a press moves dots by far less.

use super::markers::{Dot, detect_dots, grid_pitch_px};
use image::RgbImage;

#[derive(Clone, Debug, PartialEq)]
pub struct MarkerLayout {
    pub cols: u32,
    pub rows: u32,
    pub pitch_px: f64,
    /// Radius of a disc of a dot's median area (dots the frame edge cuts left out).
    pub radius_px: f64,
    /// Median share of the gel's light a dot's centre blocks.
    pub darkness: f64,
    /// Dots found.
    pub count: usize,
}

/// Groups of values closer than `gap` to their neighbour in sorted order, counting only
/// groups of at least a third of the typical group's members (a stray speck is no column).
fn clusters(mut values: Vec<f64>, gap: f64) -> u32 {
    values.sort_by(f64::total_cmp);
    let mut sizes = vec![1usize];
    for w in values.windows(2) {
        if w[1] - w[0] > gap {
            sizes.push(1);
        } else {
            *sizes.last_mut().expect("one group") += 1;
        }
    }
    let typical = median(sizes.iter().map(|&n| n as f64).collect()).unwrap_or(1.0);
    sizes.iter().filter(|&&n| n as f64 >= typical / 3.0).count() as u32
}

fn median(mut values: Vec<f64>) -> Option<f64> {
    values.sort_by(f64::total_cmp);
    values.get(values.len() / 2).copied()
}

/// The grid in `frame`; an error says why there is none to read.
pub fn read_marker_grid(frame: &RgbImage) -> Result<MarkerLayout, String> {
    let dots: Vec<Dot> = detect_dots(frame);
    if dots.len() < 4 {
        return Err(format!(
            "{} marker dots found; a marker grid needs at least 4 (is this a frame of a gel with markers?)",
            dots.len()
        ));
    }
    // Size and darkness from the dots the frame's edge leaves whole.
    let whole: Vec<&Dot> = dots.iter().filter(|d| !d.cut_by_frame).collect();
    let whole_area = median(whole.iter().map(|d| d.area_px as f64).collect())
        .ok_or("every dot is cut by the frame's edge; no dot size to read")?;
    let darkness = median(whole.iter().map(|d| d.darkness).collect()).expect("whole dots");
    // A dot the frame cuts to less than half has its centre outside: not the frame's grid.
    let dots: Vec<Dot> = dots
        .into_iter()
        .filter(|d| !d.cut_by_frame || d.area_px as f64 >= whole_area / 2.0)
        .collect();
    let centres: Vec<(f64, f64)> = dots.iter().map(|d| d.centre_px).collect();
    let pitch_px = grid_pitch_px(&centres).ok_or("fewer than two dots inside the frame")?;
    let cols = clusters(centres.iter().map(|c| c.0).collect(), pitch_px / 2.0);
    let rows = clusters(centres.iter().map(|c| c.1).collect(), pitch_px / 2.0);
    // Dots scattered off a grid fill few of its places.
    if (dots.len() as f64) < 0.6 * f64::from(cols * rows) {
        return Err(format!(
            "{} dots do not form a grid ({cols} columns x {rows} rows at a pitch of {pitch_px:.1} px would hold {})",
            dots.len(),
            cols * rows
        ));
    }
    Ok(MarkerLayout {
        cols,
        rows,
        pitch_px,
        radius_px: (whole_area / std::f64::consts::PI).sqrt(),
        darkness,
        count: dots.len(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use image::Rgb;

    /// A flat grey gel with `cols` x `rows` dark dots of radius `r` at `pitch`.
    fn grid_frame(cols: u32, rows: u32, pitch: f64, r: f64, level: u8) -> RgbImage {
        let (w, h) = (320, 240);
        let x0 = (w as f64 - (cols - 1) as f64 * pitch) / 2.0;
        let y0 = (h as f64 - (rows - 1) as f64 * pitch) / 2.0;
        RgbImage::from_fn(w, h, |x, y| {
            let near = (0..cols).any(|i| {
                (0..rows).any(|j| {
                    let (cx, cy) = (x0 + i as f64 * pitch, y0 + j as f64 * pitch);
                    (x as f64 - cx).hypot(y as f64 - cy) <= r
                })
            });
            if near { Rgb([level; 3]) } else { Rgb([180; 3]) }
        })
    }

    #[test]
    fn a_drawn_grid_is_read_back_with_its_pitch_size_and_darkness() {
        let layout = read_marker_grid(&grid_frame(9, 7, 30.0, 4.0, 45)).unwrap();
        assert_eq!((layout.cols, layout.rows, layout.count), (9, 7, 63));
        assert!((layout.pitch_px - 30.0).abs() < 0.5, "{layout:?}");
        // A pixel disc of radius 4 has 49 pixels: radius sqrt(49 / pi) = 3.95.
        assert!((layout.radius_px - 4.0).abs() < 0.3, "{layout:?}");
        assert!(
            (layout.darkness - (1.0 - 45.0 / 180.0)).abs() < 0.02,
            "{layout:?}"
        );
    }

    #[test]
    fn a_frame_without_dots_says_so() {
        let e = read_marker_grid(&RgbImage::from_pixel(320, 240, Rgb([180; 3]))).unwrap_err();
        assert!(e.contains("0 marker dots found"), "{e}");
    }
}
