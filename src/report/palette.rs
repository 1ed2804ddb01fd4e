//! Colours that mark classes in overlays: Ultralytics' first eight, so that a data set's
//! previews and `detect`'s overlays read alike.

use image::Rgb;

/// The overlay colour of class `class`.
pub fn class_colour(class: usize) -> Rgb<u8> {
    const PALETTE: [[u8; 3]; 8] = [
        [255, 56, 56],
        [50, 205, 50],
        [0, 149, 255],
        [255, 178, 29],
        [207, 210, 49],
        [146, 204, 23],
        [255, 55, 199],
        [0, 255, 255],
    ];
    Rgb(PALETTE[class % PALETTE.len()])
}
