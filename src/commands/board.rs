//! `tactex board`: the ChArUco calibration board to print, as a PNG at a chosen resolution and
//! an SVG at true scale, with the board's description as TOML beside them (what hand-eye
//! calibration and the twin's camera read).

use crate::app::flag_range::{above, choice, within};
use crate::report::output::{check_png_path, write_bytes_atomic};
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result, bail};
use clap::Args;
use serde::Serialize;
use std::path::{Path, PathBuf};
use tactex_core::charuco::{ArucoDictionary, CharucoBoard, board_image, board_svg};

#[derive(Args, Debug)]
pub struct BoardArgs {
    /// The board image to write (PNG); its SVG at true scale and its description (TOML) go
    /// beside it, named alike (.svg, .toml).
    #[arg(long)]
    pub out: PathBuf,
    /// Squares across and down, e.g. 7x5 (2 to 40 each).
    #[arg(long, default_value = "7x5", value_parser = squares)]
    pub squares: (usize, usize),
    /// A square's side (mm), 1 to 1000.
    #[arg(long, default_value_t = 30.0, value_parser = within(1.0, 1000.0))]
    pub square_mm: f64,
    /// A marker's side (mm), 0.5 to 1000 and smaller than a square's.
    #[arg(long, default_value_t = 22.0, value_parser = within(0.5, 1000.0))]
    pub marker_mm: f64,
    /// OpenCV's predefined ArUco dictionary the markers come from.
    #[arg(long, default_value = "DICT_5X5_100", value_parser = choice::<ArucoDictionary>(&DICTIONARY_NAMES))]
    pub dictionary: ArucoDictionary,
    /// The PNG's resolution (pixels per mm; 11.811 is 300 dpi), in (0, 100].
    #[arg(long, default_value_t = 11.811, value_parser = above(0.0, 100.0))]
    pub px_per_mm: f64,
    /// White margin round the board (mm), in [0, 1000].
    #[arg(long, default_value_t = 10.0, value_parser = within(0.0, 1000.0))]
    pub margin_mm: f64,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

const DICTIONARY_NAMES: [&str; 3] = ["DICT_4X4_50", "DICT_5X5_100", "DICT_6X6_250"];

/// The largest PNG side written (px).
const MAX_SIDE_PX: f64 = 20_000.0;

fn squares(text: &str) -> Result<(usize, usize), String> {
    let bad = || format!("expected squares across x down, e.g. 7x5; got {text:?}");
    let (x, y) = text.trim().split_once(['x', 'X']).ok_or_else(bad)?;
    Ok((
        x.trim().parse().map_err(|_| bad())?,
        y.trim().parse().map_err(|_| bad())?,
    ))
}

#[derive(Serialize)]
struct BoardReport<'a> {
    board: &'a CharucoBoard,
    corners: usize,
    markers: usize,
    size_mm: [f64; 2],
    png: String,
    png_px: [u32; 2],
    svg: String,
    toml: String,
}

pub fn run(args: &BoardArgs) -> Result<()> {
    let board = CharucoBoard {
        squares_x: args.squares.0,
        squares_y: args.squares.1,
        square_mm: args.square_mm,
        marker_mm: args.marker_mm,
        dictionary: args.dictionary,
    };
    board
        .check()
        .map_err(|e| anyhow::anyhow!(flag_words(&e.to_string())))?;
    check_png_path(&args.out)?;
    let (w_mm, h_mm) = board.size_mm();
    let side_px = (w_mm.max(h_mm) + 2.0 * args.margin_mm) * args.px_per_mm;
    if side_px > MAX_SIDE_PX {
        bail!(
            "--px-per-mm: the image would be {side_px:.0} px a side; at most {MAX_SIDE_PX:.0} (lower --px-per-mm or --margin-mm, or make the board smaller: --squares, --square-mm)"
        );
    }
    let cell_px = board.marker_mm / (board.dictionary.marker_bits() + 2) as f64 * args.px_per_mm;
    if cell_px < 1.0 {
        bail!(
            "--px-per-mm: a marker's bit would be {cell_px:.2} px in the PNG; at least 1 (raise --px-per-mm)"
        );
    }
    let (svg_path, toml_path) = (
        args.out.with_extension("svg"),
        args.out.with_extension("toml"),
    );
    // All three or none: a path that cannot take a file is refused before any is written.
    for path in [&args.out, &svg_path, &toml_path] {
        if path.is_dir() {
            bail!(
                "{}: is a directory; the board writes a file there",
                path.display()
            );
        }
    }
    let image = board_image(&board, args.px_per_mm, args.margin_mm);
    let mut png = std::io::Cursor::new(Vec::new());
    image
        .write_to(&mut png, image::ImageFormat::Png)
        .context("encoding PNG")?;
    let toml = format!(
        "# ChArUco board written by `tactex board`: print {} at 100% ({} x {} mm without its margin)\n{}",
        file_name(&svg_path),
        mm(w_mm),
        mm(h_mm),
        toml::to_string(&board).context("writing the board's TOML")?
    );
    write_all_or_none(&[
        (&args.out, png.get_ref().as_slice()),
        (&svg_path, board_svg(&board, args.margin_mm).as_bytes()),
        (&toml_path, toml.as_bytes()),
    ])?;
    let report = BoardReport {
        board: &board,
        corners: board.corners().len(),
        markers: board.marker_count(),
        size_mm: [w_mm, h_mm],
        png: args.out.display().to_string(),
        png_px: [image.width(), image.height()],
        svg: svg_path.display().to_string(),
        toml: toml_path.display().to_string(),
    };
    print_json_or_text(&report, args.json, || {
        println!(
            "{}: ChArUco board, {} x {} squares of {} mm, {} mm markers from {}; {} corners, {} x {} mm",
            report.png,
            board.squares_x,
            board.squares_y,
            board.square_mm,
            board.marker_mm,
            board.dictionary,
            report.corners,
            mm(w_mm),
            mm(h_mm)
        );
        println!(
            "{} x {} px at {} px/mm; print {} at 100% (no fit to page), and measure a square: it must be {} mm; description in {}",
            report.png_px[0],
            report.png_px[1],
            args.px_per_mm,
            report.svg,
            board.square_mm,
            report.toml
        );
        Ok(())
    })
}

/// Each file written whole, and none left when a later one fails (a PNG without its
/// true-scale SVG would be printed at the wrong size); files that were there before stay.
fn write_all_or_none(files: &[(&PathBuf, &[u8])]) -> Result<()> {
    let mut written = Vec::new();
    for (path, bytes) in files {
        let existed = path.exists();
        if let Err(e) = write_bytes_atomic(path, bytes) {
            for created in written {
                let _ = std::fs::remove_file(created);
            }
            return Err(e);
        }
        if !existed {
            written.push(*path);
        }
    }
    Ok(())
}

/// A length in mm as people write it: 233.1, not 233.09999999999997.
fn mm(v: f64) -> String {
    tactex_core::printable::short_number((v * 1e6).round() / 1e6)
}

/// The board's field names as this command's flags.
fn flag_words(message: &str) -> String {
    message
        .replace("squares_x", "--squares (across)")
        .replace("squares_y", "--squares (down)")
        .replace("square_mm", "--square-mm")
        .replace("marker_mm", "--marker-mm")
        .replace("markers; DICT", "markers (--squares); DICT")
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default()
}
