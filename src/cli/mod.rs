//! The command line: what `tactex` accepts (clap), which library function each command
//! runs, and [`main`], the whole program. Clap stays here and in the commands' flag
//! structs: the library's functions take typed requests (`AskRequest`, `PressOptions`, ...).

pub mod process;
pub mod twin_flags;

#[cfg(feature = "plots")]
use crate::{bench, eval};
use crate::{commands, datagen, sim2real};
#[cfg(feature = "servers")]
use crate::{serve, xarm_twin};
use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "tactex",
    version,
    about = "TactEx twin: ask a robot with an RGB-D camera and a GelSight Mini about fruit hardness"
)]
pub(crate) struct Cli {
    #[command(subcommand)]
    pub(crate) command: Command,
}

#[derive(Subcommand)]
pub(crate) enum Command {
    /// Answer a question about the fruit on the table, e.g. "Which fruit is the softest?"
    Ask(commands::ask::AskArgs),
    /// The chat page: live camera view with detections, questions answered with progress,
    /// tactile frames, hardness and ripeness of each touched fruit, latency per stage.
    #[cfg(feature = "servers")]
    Serve(serve::ServeArgs),
    /// A real uFactory xArm (or the vendor's simulator) over its TCP protocol: pose, move,
    /// home.
    Arm(commands::arm::ArmArgs),
    /// The twin as an xArm 850 controller: programs written against the vendor's Python SDK
    /// move the GelSight pad through the simulated table; its frames come over HTTP.
    #[cfg(feature = "servers")]
    Twin(xarm_twin::TwinArgs),
    /// What the prompt parser reads from a question (intent, property, targets, filters).
    Parse(commands::parse::ParseArgs),
    /// Press the gel into one object and report force, contact and indentation.
    Press(commands::press::PressArgs),
    /// Fit a sensor profile (shading table, background, camera noise) from annotated presses
    /// of a ball of known radius.
    Calibrate(sim2real::calibrate::CalibrateArgs),
    /// Sensor profiles: print one, check one.
    Sensor {
        #[command(subcommand)]
        command: commands::sensor::SensorCommand,
    },
    /// Render annotated real presses through a calibrated profile and score them against the real
    /// frames (SSIM, mean absolute intensity error); or, with --session, rebuild a recorded
    /// session's presses in the twin (SSIM, marker displacement error, hardness agreement).
    Compare(sim2real::compare::CompareArgs),
    /// The ChArUco calibration board to print (PNG, SVG at true scale: print it at 100%,
    /// landscape on A4) and its description; OpenCV 4.6's layout (not the legacy pattern).
    Board(commands::board::BoardArgs),
    /// Where the scene camera stands in the arm's frame (eye-to-hand): the arm holds a
    /// ChArUco board at planned stations, OpenCV finds its corners, Tsai-Lenz, Park-Martin and
    /// a refinement on the corners place the camera; writes the calibration (TOML).
    Handeye(commands::handeye::HandEyeArgs),
    /// Marker centroids on a tactile frame, and displacements against a reference frame.
    Markers(commands::markers::MarkersArgs),
    /// Contact or not against a no-contact frame (the paper's SSIM criterion), and the
    /// contact circle and region.
    Contact(commands::contact::ContactArgs),
    /// What the twin reads from one tactile frame through a sensor's optics: the gel's
    /// indentation map, the imprint's peak depth and the contact's size.
    Read(commands::read::ReadArgs),
    /// A YOLOv8-seg ONNX model on one colour image: boxes, scores, masks, an overlay PNG.
    Detect(commands::detect::DetectArgs),
    /// Evaluations on the twin.
    #[cfg(feature = "plots")]
    Eval {
        #[command(subcommand)]
        command: EvalCommand,
    },
    /// Synthetic data sets.
    Datagen {
        #[command(subcommand)]
        command: DatagenCommand,
    },
    /// Benchmarks (run them on a release build).
    #[cfg(feature = "plots")]
    Bench {
        #[command(subcommand)]
        command: BenchCommand,
    },
    /// Scene files.
    Scene {
        #[command(subcommand)]
        command: SceneCommand,
    },
}

#[cfg(feature = "plots")]
#[derive(Subcommand)]
pub(crate) enum BenchCommand {
    /// Speed and accuracy of each contact fidelity level and solver cell.
    Contact(bench::contact::ContactBenchArgs),
    /// Frames per second of full GelSight frames per fidelity level, CPU and GPU paths.
    Render(bench::render::RenderBenchArgs),
    /// Press sequences per second of `datagen tactile` for each fidelity level.
    Datagen(bench::datagen::DatagenBenchArgs),
    /// RGB-D scene rendering (640x480 colour, depth, instance ids), CPU and GPU paths.
    Scene(bench::scene::SceneBenchArgs),
    /// The main job: each pipeline stage's wall time at each fidelity, beside the estimates'
    /// error on the scene's true moduli.
    Ask(bench::ask::AskBenchArgs),
}

#[cfg(feature = "plots")]
#[derive(Subcommand)]
pub(crate) enum EvalCommand {
    /// The paper's grounding protocol: detectors' success, IoU and centroid error.
    Grounding(eval::grounding::GroundingEvalArgs),
    /// Hand-eye calibration on the twin against the number of stations: each solver's
    /// camera error (mm, degrees) against the twin's truth, plotted.
    Handeye(eval::handeye::HandEyeEvalArgs),
    /// Hardness estimators on held-out synthetic presses of unseen shapes.
    Hardness(eval::hardness::HardnessEvalArgs),
    /// The paper's Table III: ripeness stages of five fruits told apart by pressing.
    Ripeness(eval::ripeness::RipenessEvalArgs),
    /// The paper's four query tiers end to end: object- and scenario-level success, latency.
    Scenarios(eval::scenarios::ScenarioEvalArgs),
    /// The whole pipeline per catalog fruit kind, alone and on crowded tables: located,
    /// measured, ln error and interval coverage (and `--calibrate`: the intervals' file).
    Fruits(eval::fruits::FruitEvalArgs),
    /// The explainer alone: 100 prompts over random scenes, scored for accuracy,
    /// completeness and clarity against the truth.
    Explanations(eval::explanations::ExplanationEvalArgs),
}

#[derive(Subcommand)]
pub(crate) enum DatagenCommand {
    /// Press sequences (8 frames from first contact, 0.25 mm apart) of randomised objects
    /// and sensors, with hardness labels: pretraining data for tactile hardness models.
    Tactile(datagen::tactile::TactileDatagenArgs),
    /// RGB-D scenes of random fruits with YOLO segmentation labels and a data.yaml that
    /// Ultralytics trains on as is; depth, instance masks and ground truth beside them.
    Scenes(datagen::scenes::SceneDatagenArgs),
    /// A sensor's ball-press calibration set made in the twin, as `calibrate` reads a real
    /// one, with each press's truth.
    BallPresses(datagen::ball_presses::BallPressDatagenArgs),
}

#[derive(Subcommand)]
pub(crate) enum SceneCommand {
    /// Validate a scene file (and its meshes) and print a summary.
    Check { file: PathBuf },
}

/// The `tactex` program: parses the command line, runs the command, and prints any error
/// as one line (the binary only sets the allocator and calls this).
pub fn main() -> ExitCode {
    process::ensure_runtime_dir();
    process::one_line_on_stdout_failure();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // Help and the version are what was asked for.
        Err(e)
            if matches!(
                e.kind(),
                clap::error::ErrorKind::DisplayHelp
                    | clap::error::ErrorKind::DisplayVersion
                    | clap::error::ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
            ) =>
        {
            e.exit()
        }
        // A bad value, a flag missing or in conflict: bad input like any other, one line
        // (clap quotes values as given: escape codes and bidirectional overrides shown).
        Err(e) => {
            eprintln!("{}", usage_error_line(&e));
            return ExitCode::FAILURE;
        }
    };
    #[cfg(feature = "servers")]
    let serves = matches!(cli.command, Command::Serve(_) | Command::Twin(_));
    #[cfg(not(feature = "servers"))]
    let serves = false;
    if !serves {
        process::quiet_on_closed_pipe();
    }
    match run(cli.command) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// Runs one parsed command.
pub(crate) fn run(command: Command) -> Result<()> {
    match command {
        Command::Ask(args) => commands::ask::run(&args),
        #[cfg(feature = "servers")]
        Command::Serve(args) => serve::run(&args),
        #[cfg(feature = "servers")]
        Command::Twin(args) => xarm_twin::run(&args),
        Command::Arm(args) => commands::arm::run(&args),
        Command::Parse(args) => commands::parse::run(&args),
        Command::Press(args) => commands::press::run(&args),
        Command::Calibrate(args) => sim2real::calibrate::run(&args),
        Command::Sensor { command } => commands::sensor::run(&command),
        Command::Compare(args) => sim2real::compare::run(&args),
        Command::Board(args) => commands::board::run(&args),
        Command::Handeye(args) => commands::handeye::run(&args),
        Command::Markers(args) => commands::markers::run(&args),
        Command::Contact(args) => commands::contact::run(&args),
        Command::Read(args) => commands::read::run(&args),
        Command::Detect(args) => commands::detect::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Grounding(args),
        } => eval::grounding::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Handeye(args),
        } => eval::handeye::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Hardness(args),
        } => eval::hardness::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Scenarios(args),
        } => eval::scenarios::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Fruits(args),
        } => eval::fruits::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Explanations(args),
        } => eval::explanations::run(&args),
        #[cfg(feature = "plots")]
        Command::Eval {
            command: EvalCommand::Ripeness(args),
        } => eval::ripeness::run(&args),
        Command::Datagen {
            command: DatagenCommand::Tactile(args),
        } => datagen::tactile::run(&args),
        Command::Datagen {
            command: DatagenCommand::Scenes(args),
        } => datagen::scenes::run(&args),
        Command::Datagen {
            command: DatagenCommand::BallPresses(args),
        } => datagen::ball_presses::run(&args),
        #[cfg(feature = "plots")]
        Command::Bench {
            command: BenchCommand::Contact(args),
        } => bench::contact::run(&args),
        #[cfg(feature = "plots")]
        Command::Bench {
            command: BenchCommand::Render(args),
        } => bench::render::run(&args),
        #[cfg(feature = "plots")]
        Command::Bench {
            command: BenchCommand::Datagen(args),
        } => bench::datagen::run(&args),
        #[cfg(feature = "plots")]
        Command::Bench {
            command: BenchCommand::Scene(args),
        } => bench::scene::run(&args),
        #[cfg(feature = "plots")]
        Command::Bench {
            command: BenchCommand::Ask(args),
        } => bench::ask::run(&args),
        Command::Scene {
            command: SceneCommand::Check { file },
        } => commands::scene::check(&file),
    }
}

/// The error and its causes on one line, a cause that only repeats what is already said
/// left out (an I/O error wrapped by a library that prints it too), and any control
/// characters from prompts or files shown as escapes rather than sent to the terminal.
pub fn error_line(e: &anyhow::Error) -> String {
    let mut line = String::new();
    for cause in e.chain() {
        let text = cause.to_string();
        if line.contains(&text) {
            continue;
        }
        if !line.is_empty() {
            line.push_str(": ");
        }
        line.push_str(&text);
    }
    tactex_core::printable::printable(&line)
}

/// A command-line parse error as one line: its first paragraph, whose lines (a list of the
/// required flags not given) are joined, without the usage that follows; escapes shown.
pub(crate) fn usage_error_line(e: &clap::Error) -> String {
    let text = e.render().to_string();
    let first: Vec<&str> = text
        .lines()
        .take_while(|l| !l.trim().is_empty())
        .map(str::trim)
        .collect();
    let line = if first.is_empty() {
        "error: invalid arguments".to_string()
    } else {
        first.join(" ")
    };
    tactex_core::printable::printable(&line)
}

#[cfg(test)]
mod tests {
    use super::error_line;

    #[test]
    fn a_parse_error_is_one_line_naming_the_flags() {
        use clap::Parser;
        let missing = crate::cli::Cli::try_parse_from(["tactex", "contact", "frame.png"])
            .err()
            .expect("--reference is required");
        let line = super::usage_error_line(&missing);
        assert!(
            line.starts_with("error: ") && line.contains("--reference") && !line.contains('\n'),
            "{line}"
        );
        let conflict = crate::cli::Cli::try_parse_from([
            "tactex",
            "press",
            "--shape",
            "sphere",
            "--depth-mm",
            "1",
            "--hardness",
            "35A",
            "--modulus-mpa",
            "2",
        ])
        .err()
        .expect("conflicting flags");
        let line = super::usage_error_line(&conflict);
        assert!(
            line.contains("--modulus-mpa") && !line.contains("Usage"),
            "{line}"
        );
    }

    #[test]
    fn an_error_line_says_each_cause_once_and_shows_control_characters() {
        // A library error that prints its I/O source, wrapped again by that source.
        let io = || std::io::Error::new(std::io::ErrorKind::IsADirectory, "Is a directory");
        let e = anyhow::Error::new(io())
            .context(format!("failed to persist temporary file: {}", io()))
            .context("o/tactile.png: cannot write");
        assert_eq!(
            error_line(&e),
            "o/tactile.png: cannot write: failed to persist temporary file: Is a directory"
        );
        let e = anyhow::anyhow!("prompt: names no known fruit in \"\u{1b}[2Jhi\"");
        assert_eq!(
            error_line(&e),
            "prompt: names no known fruit in \"\\u{1b}[2Jhi\""
        );
    }
}
