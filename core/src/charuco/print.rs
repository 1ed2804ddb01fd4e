//! A board's printable forms: a greyscale PNG at a chosen resolution (each pixel the share of
//! it that is white, so edges off the pixel grid stay where they are), and an SVG sized in
//! millimetres that prints at true scale.

use super::CharucoBoard;
use image::{GrayImage, Luma};
use std::fmt::Write;

/// Samples per pixel side for a pixel's white share.
const SUPERSAMPLING: usize = 4;

/// The board at `px_per_mm`, with a white margin of `margin_mm` round it.
pub fn board_image(board: &CharucoBoard, px_per_mm: f64, margin_mm: f64) -> GrayImage {
    let (w_mm, h_mm) = board.size_mm();
    let side = |mm: f64| ((mm + 2.0 * margin_mm) * px_per_mm).round().max(1.0) as u32;
    let (w, h) = (side(w_mm), side(h_mm));
    let step = 1.0 / (SUPERSAMPLING as f64 * px_per_mm);
    let face = board.face();
    GrayImage::from_fn(w, h, |x, y| {
        let mut white = 0;
        for j in 0..SUPERSAMPLING {
            for i in 0..SUPERSAMPLING {
                let bx = x as f64 / px_per_mm + (i as f64 + 0.5) * step - margin_mm;
                let by = y as f64 / px_per_mm + (j as f64 + 0.5) * step - margin_mm;
                white += usize::from(face.is_white(bx, by));
            }
        }
        let share = white as f64 / (SUPERSAMPLING * SUPERSAMPLING) as f64;
        Luma([(255.0 * share).round() as u8])
    })
}

/// The board as SVG, its size in millimetres (print at 100%, no fitting to the page), with
/// a white margin of `margin_mm`; the board's description in its title.
pub fn board_svg(board: &CharucoBoard, margin_mm: f64) -> String {
    let (w_mm, h_mm) = board.size_mm();
    // Rounded to a nanometre: 233.1, not 233.09999999999997.
    let round = |v: f64| (v * 1e6).round() / 1e6;
    let (w, h) = (round(w_mm + 2.0 * margin_mm), round(h_mm + 2.0 * margin_mm));
    let mut svg = String::new();
    let _ = writeln!(
        svg,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{w}mm" height="{h}mm" viewBox="0 0 {w} {h}" shape-rendering="crispEdges">"#
    );
    let _ = writeln!(
        svg,
        "<title>ChArUco board {} x {} squares of {} mm, markers {} mm, {}</title>",
        board.squares_x, board.squares_y, board.square_mm, board.marker_mm, board.dictionary
    );
    let _ = writeln!(svg, r#"<rect width="{w}" height="{h}" fill="white"/>"#);
    let _ = writeln!(svg, r#"<g transform="translate({margin_mm} {margin_mm})">"#);
    let s = board.square_mm;
    let rect = |svg: &mut String, x: f64, y: f64, w: f64, h: f64, fill: &str| {
        let _ = writeln!(
            svg,
            r#"<rect x="{x}" y="{y}" width="{w}" height="{h}" fill="{fill}"/>"#
        );
    };
    for row in 0..board.squares_y {
        for col in 0..board.squares_x {
            if col % 2 == row % 2 {
                rect(&mut svg, col as f64 * s, row as f64 * s, s, s, "black");
            }
        }
    }
    let bits = board.dictionary.marker_bits();
    let cell = board.marker_mm / (bits + 2) as f64;
    let inset = (s - board.marker_mm) / 2.0;
    for marker in board.markers() {
        let Some(pattern) = board.dictionary.marker(marker.id) else {
            continue;
        };
        let (x0, y0) = (
            marker.square.0 as f64 * s + inset,
            marker.square.1 as f64 * s + inset,
        );
        rect(&mut svg, x0, y0, board.marker_mm, board.marker_mm, "black");
        // White runs along each row of bits: fewer rectangles, no seams between them.
        for r in 0..bits {
            let mut c = 0;
            while c < bits {
                if !pattern[r * bits + c] {
                    c += 1;
                    continue;
                }
                let start = c;
                while c < bits && pattern[r * bits + c] {
                    c += 1;
                }
                rect(
                    &mut svg,
                    x0 + (start + 1) as f64 * cell,
                    y0 + (r + 1) as f64 * cell,
                    (c - start) as f64 * cell,
                    cell,
                    "white",
                );
            }
        }
    }
    svg.push_str("</g>\n</svg>\n");
    svg
}
