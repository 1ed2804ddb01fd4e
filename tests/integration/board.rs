//! `tactex board`: the printable ChArUco board, its SVG at true scale and its description,
//! and refusals that name the flag and write nothing.

use crate::cli::tactex;

#[test]
fn board_writes_the_png_svg_and_a_description_that_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("board.png");
    let out = tactex(&[
        "board",
        "--out",
        png.to_str().unwrap(),
        "--squares",
        "5x4",
        "--square-mm",
        "40",
        "--marker-mm",
        "28",
        "--px-per-mm",
        "2.5",
        "--margin-mm",
        "0",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(report["corners"], 12);
    assert_eq!(report["png_px"], serde_json::json!([500, 400]));
    // The same board OpenCV drew for core's fixture: the image matches it cell for cell.
    let ours = image::open(&png).unwrap().into_luma8();
    let opencv = image::open(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/core/tests/fixtures/charuco/opencv-charuco-5x4.png"
    ))
    .unwrap()
    .into_luma8();
    for (x, y) in [(120, 20), (140, 60), (50, 50), (320, 120), (420, 370)] {
        assert_eq!(ours.get_pixel(x, y), opencv.get_pixel(x, y), "({x}, {y})");
    }
    let svg = std::fs::read_to_string(dir.path().join("board.svg")).unwrap();
    assert!(svg.contains(r#"width="200mm" height="160mm""#));
    let text = std::fs::read_to_string(dir.path().join("board.toml")).unwrap();
    let board: tactex_core::charuco::CharucoBoard = toml::from_str(&text).unwrap();
    assert_eq!(board.squares_x, 5);
    assert_eq!(board.dictionary.name(), "DICT_5X5_100");
}

#[test]
fn a_board_that_cannot_be_made_is_refused_by_flag_and_nothing_is_written() {
    let dir = tempfile::tempdir().unwrap();
    let png = dir.path().join("b.png");
    let png = png.to_str().unwrap();
    for (args, want) in [
        (
            vec!["--squares", "1x5"],
            "--squares (across) must be 2 to 40",
        ),
        (vec!["--squares", "7by5"], "--squares"),
        (
            vec!["--marker-mm", "30"],
            "--marker-mm (30) must be smaller than --square-mm (30)",
        ),
        (vec!["--square-mm", "nan"], "--square-mm"),
        (vec!["--px-per-mm", "90"], "--px-per-mm: the image would be"),
        (
            vec!["--px-per-mm", "0.1"],
            "--px-per-mm: a marker's bit would be 0.31 px",
        ),
        (
            vec!["--square-mm", "0.5", "--marker-mm", "0.4"],
            "0.5 is outside [1, 1000]",
        ),
        (
            vec!["--squares", "11x10", "--dictionary", "DICT_4X4_50"],
            "11 x 10 squares need 55 markers (--squares); DICT_4X4_50 has 50",
        ),
    ] {
        let mut all = vec!["board", "--out", png];
        all.extend(&args);
        let out = tactex(&all);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success(), "{args:?}: {stderr}");
        assert!(stderr.contains(want), "{args:?}: {stderr}");
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            0,
            "{args:?} wrote files"
        );
    }
    // The SVG's place taken by a folder: refused before the PNG is written.
    std::fs::create_dir(dir.path().join("b.svg")).unwrap();
    let out = tactex(&["board", "--out", png]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("b.svg: is a directory"),
        "{stderr}"
    );
    assert!(!dir.path().join("b.png").exists(), "a PNG without its SVG");
    // The TOML's name too long for the file system: the PNG and SVG written before it go.
    let long = dir.path().join(format!("{}.png", "a".repeat(251)));
    let out = tactex(&["board", "--out", long.to_str().unwrap()]);
    assert!(!out.status.success());
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(left.len(), 1, "only the folder b.svg stays: {left:?}");
}
