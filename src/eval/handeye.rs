//! `tactex eval handeye`: hand-eye calibration on the twin against the number of stations.
//! For each station count and seed the twin's camera is misplaced (directions drawn from the
//! seed), calibrated with `tactex handeye`'s run, and each solver's camera scored against the
//! twin's truth; the medians over seeds per count are plotted (error-vs-poses.png) and every
//! run is kept (handeye.csv, summary.json).

use crate::app::camera_placement::CameraPlacement;
use crate::app::flag_range::{count, within};
use crate::app::hand_eye::{TwinHandEyeRequest, hand_eye_on_twin, pose_error};
use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic};
use crate::report::plot::{self, PlotLine};
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::charuco::CharucoBoard;
use tactex_core::hand_eye::MAX_STATIONS;

#[derive(Args, Debug)]
pub struct HandEyeEvalArgs {
    /// Station counts to calibrate from, each 3 to 100.
    #[arg(long, value_delimiter = ',', default_value = "3,4,6,10,15,25", value_parser = count::<usize>(3, MAX_STATIONS as u64))]
    pub poses: Vec<usize>,
    /// Seeds per count (the camera's noise and the misplacement's directions), 1 to 100.
    #[arg(long, default_value_t = 5, value_parser = count::<u64>(1, 100))]
    pub seeds: u64,
    /// How far the twin's camera stands from where the scene puts it (mm), 0 to 200.
    #[arg(long, default_value_t = 20.0, value_parser = within(0.0, 200.0))]
    pub camera_error_mm: f64,
    /// How far it is turned (degrees), 0 to 20.
    #[arg(long, default_value_t = 2.0, value_parser = within(0.0, 20.0))]
    pub camera_error_deg: f64,
    /// The scene the twin is built from; default the built-in demo scene.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Directory for handeye.csv, summary.json and error-vs-poses.png.
    #[arg(long)]
    pub out: PathBuf,
    /// Print one JSON object on stdout.
    #[arg(long)]
    pub json: bool,
}

const SOLVERS: [&str; 3] = ["Tsai-Lenz", "Park-Martin", "refined"];

/// One solver's camera from one run.
#[derive(Clone, Serialize)]
struct Row {
    poses: usize,
    seed: u64,
    solver: &'static str,
    error_mm: f64,
    error_deg: f64,
    stations_used: usize,
}

/// Medians over seeds at one station count, per solver.
#[derive(Serialize)]
struct CountSummary {
    poses: usize,
    solver: &'static str,
    median_error_mm: f64,
    median_error_deg: f64,
    worst_error_mm: f64,
    worst_error_deg: f64,
    runs: usize,
}

#[derive(Serialize)]
struct Summary {
    camera_error_mm: f64,
    camera_error_deg: f64,
    seeds: u64,
    /// Runs refused (too few stations saw the board, a degenerate set), with why.
    refused: Vec<String>,
    counts: Vec<CountSummary>,
}

pub fn run(args: &HandEyeEvalArgs) -> Result<()> {
    let detector = crate::commands::handeye::detector()?;
    let scene = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    crate::app::file_input::present(&scene, "file: cannot read scene")?;
    // A scene that cannot be loaded fails here, by name, rather than in every run.
    crate::app::load_scene(&scene, &tactex_core::catalog::FruitCatalog::builtin())?;
    let mut counts_asked = args.poses.clone();
    counts_asked.sort_unstable();
    counts_asked.dedup();
    let out = OutputDir::create("--out", &args.out)?;
    let runs: Vec<(usize, u64)> = counts_asked
        .iter()
        .flat_map(|&n| (1..=args.seeds).map(move |seed| (n, seed)))
        .collect();
    let bar = ProgressBar::new(runs.len() as u64).with_style(
        ProgressStyle::with_template("eval handeye {bar:30} {pos}/{len} calibrations {elapsed}")
            .context("progress style")?,
    );
    let (mut rows, mut refused) = (Vec::new(), Vec::new());
    for &(poses, seed) in &runs {
        let request = TwinHandEyeRequest {
            scene: &scene,
            board: CharucoBoard::default(),
            stations: poses,
            placement: CameraPlacement {
                error_mm: args.camera_error_mm,
                error_deg: args.camera_error_deg,
                error_seed: seed,
                calibrated: None,
            },
            seed,
            keep_frames: false,
        };
        match hand_eye_on_twin(&request, detector.as_ref(), |_| {}) {
            Ok(twin) => {
                let used = twin
                    .run
                    .stations
                    .iter()
                    .filter(|s| s.unseen.is_none())
                    .count();
                for (solver, camera) in SOLVERS.iter().zip([
                    &twin.run.tsai_lenz.camera_in_base,
                    &twin.run.park_martin.camera_in_base,
                    &twin.run.refined.camera_in_base,
                ]) {
                    let (mm, deg) = pose_error(camera, &twin.truth);
                    rows.push(Row {
                        poses,
                        seed,
                        solver,
                        error_mm: mm,
                        error_deg: deg,
                        stations_used: used,
                    });
                }
            }
            Err(e) => refused.push(format!("{poses} stations, seed {seed}: {e:#}")),
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    if rows.is_empty() {
        anyhow::bail!(
            "every calibration was refused; the first: {}",
            refused.first().map_or("", String::as_str)
        );
    }
    let mut counts = Vec::new();
    for &poses in &counts_asked {
        for solver in SOLVERS {
            let of: Vec<&Row> = rows
                .iter()
                .filter(|r| r.poses == poses && r.solver == solver)
                .collect();
            if of.is_empty() {
                continue;
            }
            let mm: Vec<f64> = of.iter().map(|r| r.error_mm).collect();
            let deg: Vec<f64> = of.iter().map(|r| r.error_deg).collect();
            counts.push(CountSummary {
                poses,
                solver,
                median_error_mm: median(mm.clone()),
                median_error_deg: median(deg.clone()),
                worst_error_mm: mm.iter().copied().fold(0.0, f64::max),
                worst_error_deg: deg.iter().copied().fold(0.0, f64::max),
                runs: of.len(),
            });
        }
    }
    let mut csv = String::from("poses,seed,solver,error_mm,error_deg,stations_used\n");
    for r in &rows {
        csv.push_str(&format!(
            "{},{},{},{:.6},{:.6},{}\n",
            r.poses, r.seed, r.solver, r.error_mm, r.error_deg, r.stations_used
        ));
    }
    write_bytes_atomic(&out.path().join("handeye.csv"), csv.as_bytes())?;
    let summary = Summary {
        camera_error_mm: args.camera_error_mm,
        camera_error_deg: args.camera_error_deg,
        seeds: args.seeds,
        refused,
        counts,
    };
    write_json_atomic(&out.path().join("summary.json"), &summary)?;
    let lines = |pick: fn(&CountSummary) -> f64| -> Vec<PlotLine> {
        SOLVERS
            .iter()
            .map(|solver| PlotLine {
                name: solver.to_string(),
                points: summary
                    .counts
                    .iter()
                    .filter(|c| c.solver == *solver)
                    .map(|c| (c.poses as f64, pick(c)))
                    .collect(),
            })
            .collect()
    };
    plot::lines_log_y(
        &out.path().join("error-vs-poses.png"),
        &format!(
            "Camera position error, twin (misplaced {} mm / {} deg), median of {} seeds",
            args.camera_error_mm, args.camera_error_deg, args.seeds
        ),
        "stations",
        "position error (mm)",
        &lines(|c| c.median_error_mm),
    )?;
    plot::lines_log_y(
        &out.path().join("rotation-error-vs-poses.png"),
        &format!(
            "Camera rotation error, twin (misplaced {} mm / {} deg), median of {} seeds",
            args.camera_error_mm, args.camera_error_deg, args.seeds
        ),
        "stations",
        "rotation error (degrees)",
        &lines(|c| c.median_error_deg),
    )?;
    out.finish()?;
    print_json_or_text(&summary, args.json, || {
        println!(
            "{}: hand-eye on the twin, camera misplaced {} mm / {} deg, median (worst) over the runs at each count",
            args.out.display(),
            args.camera_error_mm,
            args.camera_error_deg,
        );
        println!(
            "{:>6} {:<12} {:>5} {:>18} {:>20}",
            "poses", "solver", "runs", "error mm", "error deg"
        );
        for c in &summary.counts {
            println!(
                "{:>6} {:<12} {:>5} {:>8.3} ({:>7.3}) {:>9.4} ({:>8.4})",
                c.poses,
                c.solver,
                c.runs,
                c.median_error_mm,
                c.worst_error_mm,
                c.median_error_deg,
                c.worst_error_deg
            );
        }
        for r in &summary.refused {
            println!("refused: {r}");
        }
        Ok(())
    })
}
