use super::*;

/// The board in OpenCV's drawing of `tests/fixtures/charuco/opencv-charuco-5x4.png`.
fn opencv_fixture_board() -> CharucoBoard {
    CharucoBoard {
        squares_x: 5,
        squares_y: 4,
        square_mm: 40.0,
        marker_mm: 28.0,
        dictionary: ArucoDictionary::Dict5x5_100,
    }
}

/// OpenCV 4.6 draws a marker's inset truncated to whole pixels (14 px for 15 here) and
/// scales the markers' span to fit, so its edges stand up to a pixel off true scale: every
/// pixel that differs from ours lies on one of our edges, and every bit and square agrees.
#[test]
fn the_board_is_drawn_as_opencv_draws_it() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/fixtures/charuco/opencv-charuco-5x4.png"
    );
    let opencv = image::open(path).unwrap().into_luma8();
    let ours = board_image(&opencv_fixture_board(), 2.5, 0.0);
    assert_eq!(ours.dimensions(), opencv.dimensions());
    let (w, h) = ours.dimensions();
    let dark = |x: u32, y: u32| ours.get_pixel(x, y).0[0] < 128;
    let on_our_edge = |x: u32, y: u32| {
        (x.saturating_sub(1)..=(x + 1).min(w - 1))
            .any(|i| (y.saturating_sub(1)..=(y + 1).min(h - 1)).any(|j| dark(i, j) != dark(x, y)))
    };
    let mut differing = 0;
    for (x, y, p) in opencv.enumerate_pixels() {
        if (p.0[0] < 128) != dark(x, y) {
            differing += 1;
            assert!(
                on_our_edge(x, y),
                "({x}, {y}) differs from OpenCV's drawing off any edge"
            );
        }
    }
    assert!(differing < w * h / 40, "{differing} pixels differ");
    // Marker cells are 10 px here, starting 15 px into a square: their middles agree.
    let middle = |t: u32| t.is_multiple_of(10) && !t.is_multiple_of(100);
    for (x, y, p) in opencv
        .enumerate_pixels()
        .filter(|(x, y, _)| middle(*x) && middle(*y))
    {
        assert_eq!(p.0[0] < 128, dark(x, y), "cell middle ({x}, {y})");
    }
}

#[test]
fn dictionaries_hold_opencvs_counts_and_sizes() {
    for (d, n, bits) in [
        (ArucoDictionary::Dict4x4_50, 50, 4),
        (ArucoDictionary::Dict5x5_100, 100, 5),
        (ArucoDictionary::Dict6x6_250, 250, 6),
    ] {
        assert_eq!(d.marker_count(), n);
        assert_eq!(d.marker_bits(), bits);
        for id in 0..n {
            assert_eq!(d.marker(id).unwrap().len(), bits * bits, "{d} marker {id}");
        }
        assert!(d.marker(n).is_none());
        assert_eq!(d.name().parse::<ArucoDictionary>(), Ok(d));
    }
    let err = "DICT_7X7_1000".parse::<ArucoDictionary>().unwrap_err();
    assert!(err.contains("DICT_5X5_100"), "{err}");
}

#[test]
fn markers_and_corners_are_numbered_row_by_row() {
    let board = CharucoBoard::default();
    let markers = board.markers();
    assert_eq!(markers.len(), 17);
    assert_eq!(markers[0].square, (1, 0));
    assert_eq!(markers[3].square, (0, 1));
    assert_eq!(markers[16].square, (5, 4));
    let corners = board.corners();
    assert_eq!(corners.len(), 6 * 4);
    assert!((corners[0] - DVec3::new(0.03, 0.03, 0.0)).length() < 1e-12);
    assert!((corners[7] - DVec3::new(0.06, 0.06, 0.0)).length() < 1e-12);
    // A square's colour at its middle: the top-left square is black, its right neighbour
    // white round its marker.
    let face = board.face();
    assert!(!face.is_white(15.0, 15.0));
    assert!(face.is_white(31.0, 1.0));
    assert!(
        face.is_white(-1.0, 10.0),
        "the paper round the board is white"
    );
}

#[test]
fn a_board_that_cannot_be_made_names_its_field() {
    let board = CharucoBoard::default();
    let cases = [
        (
            CharucoBoard {
                squares_x: 1,
                ..board
            },
            "squares_x must be 2 to 40; got 1",
        ),
        (
            CharucoBoard {
                squares_y: 41,
                ..board
            },
            "squares_y must be 2 to 40; got 41",
        ),
        (
            CharucoBoard {
                square_mm: f64::NAN,
                ..board
            },
            "square_mm must be 1 to 1000 mm; got NaN",
        ),
        (
            CharucoBoard {
                marker_mm: 0.0,
                ..board
            },
            "marker_mm must be 0.5 to 1000 mm; got 0",
        ),
        (
            CharucoBoard {
                marker_mm: 30.0,
                ..board
            },
            "marker_mm (30) must be smaller than square_mm (30)",
        ),
        (
            CharucoBoard {
                squares_x: 11,
                squares_y: 10,
                dictionary: ArucoDictionary::Dict4x4_50,
                ..board
            },
            "11 x 10 squares need 55 markers; DICT_4X4_50 has 50",
        ),
    ];
    for (b, want) in cases {
        let err = b.check().unwrap_err().to_string();
        assert!(err.starts_with(want), "{err}");
    }
    assert_eq!(board.check(), Ok(()));
}

#[test]
fn the_svg_prints_at_true_scale_with_the_images_black_area() {
    let board = CharucoBoard::default();
    let svg = board_svg(&board, 10.0);
    assert!(
        svg.contains(r#"width="230mm" height="170mm" viewBox="0 0 230 170""#),
        "{svg:.200}"
    );
    // Black area (mm^2) from the rectangles: black ones add, white ones inside markers take away.
    let mut black = 0.0;
    for line in svg.lines().filter(|l| l.starts_with("<rect x=")) {
        let attr = |name: &str| -> f64 {
            let start = line.find(&format!(r#" {name}=""#)).unwrap() + name.len() + 3;
            line[start..].split('"').next().unwrap().parse().unwrap()
        };
        let area = attr("width") * attr("height");
        black += if line.contains(r#"fill="black""#) {
            area
        } else {
            -area
        };
    }
    let image = board_image(&board, 4.0, 0.0);
    let share = image
        .pixels()
        .map(|p| 1.0 - p.0[0] as f64 / 255.0)
        .sum::<f64>()
        / (image.width() * image.height()) as f64;
    let (w, h) = board.size_mm();
    assert!(
        (black / (w * h) - share).abs() < 0.002,
        "svg {} image {share}",
        black / (w * h)
    );
}
