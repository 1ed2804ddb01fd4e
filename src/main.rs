//! `tactex`: the TactEx twin command line. Wires the simulated devices (tactex-sim) into the
//! backend-free pipeline (tactex-core).

mod arm_cli;
mod ask;
mod ball_presses;
mod bench_ask;
mod bench_contact;
mod bench_datagen;
mod bench_render;
mod bench_scene;
mod calibrate;
mod compare;
mod compare_session;
mod contact_circle_score;
mod contact_cli;
mod datagen_ball_presses;
mod datagen_scenes;
mod datagen_tactile;
mod detect_image;
mod detector_choice;
mod estimator_choice;
mod eval_explanations;
mod eval_fruits;
mod eval_grounding;
mod eval_hardness;
mod eval_ripeness;
mod eval_scenarios;
mod flag_range;
mod learned_model;
mod llm_explainer;
mod markers;
mod npz;
mod output;
mod parse_prompt;
mod plot;
mod press;
mod sensor_cli;
mod serve;
mod twin;

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use tactex_core::catalog::FruitCatalog;

// Frames, fields and FFT scratch are allocated and freed by the hundred per press; glibc
// returns blocks this size to the kernel on every free and faults them back in, which cost
// a third of the gel-fields stage (measured with `bench render`).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

#[derive(Parser)]
#[command(
    name = "tactex",
    version,
    about = "TactEx twin: ask a robot with an RGB-D camera and a GelSight Mini about fruit hardness"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Answer a question about the fruit on the table, e.g. "Which fruit is the softest?"
    Ask(ask::AskArgs),
    /// The chat page: live camera view with detections, questions answered with progress,
    /// tactile frames, hardness and ripeness of each touched fruit, latency per stage.
    Serve(serve::ServeArgs),
    /// A real uFactory xArm (or the vendor's simulator) over its TCP protocol: pose, move,
    /// home.
    Arm(arm_cli::ArmArgs),
    /// The twin as an xArm 850 controller: programs written against the vendor's Python SDK
    /// move the GelSight pad through the simulated table; its frames come over HTTP.
    Twin(twin::TwinArgs),
    /// What the prompt parser reads from a question (intent, property, targets, filters).
    Parse(parse_prompt::ParseArgs),
    /// Press the gel into one object and report force, contact and indentation.
    Press(press::PressArgs),
    /// Fit a sensor profile (shading table, background, camera noise) from annotated presses
    /// of a ball of known radius.
    Calibrate(calibrate::CalibrateArgs),
    /// Sensor profiles: print one, check one.
    Sensor {
        #[command(subcommand)]
        command: sensor_cli::SensorCommand,
    },
    /// Render annotated real presses through a calibrated profile and score them against the real
    /// frames (SSIM, mean absolute intensity error); or, with --session, rebuild a recorded
    /// session's presses in the twin (SSIM, marker displacement error, hardness agreement).
    Compare(compare::CompareArgs),
    /// Marker centroids on a tactile frame, and displacements against a reference frame.
    Markers(markers::MarkersArgs),
    /// Contact or not against a no-contact frame (the paper's SSIM criterion), and the
    /// contact circle and region.
    Contact(contact_cli::ContactArgs),
    /// A YOLOv8-seg ONNX model on one colour image: boxes, scores, masks, an overlay PNG.
    Detect(detect_image::DetectArgs),
    /// Evaluations on the twin.
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

#[derive(Subcommand)]
enum BenchCommand {
    /// Speed and accuracy of each contact fidelity level and solver cell.
    Contact(bench_contact::ContactBenchArgs),
    /// Frames per second of full GelSight frames per fidelity level, CPU and GPU paths.
    Render(bench_render::RenderBenchArgs),
    /// Press sequences per second of `datagen tactile` for each fidelity level.
    Datagen(bench_datagen::DatagenBenchArgs),
    /// RGB-D scene rendering (640x480 colour, depth, instance ids), CPU and GPU paths.
    Scene(bench_scene::SceneBenchArgs),
    /// The main job: each pipeline stage's wall time at each fidelity, beside the estimates'
    /// error on the scene's true moduli.
    Ask(bench_ask::AskBenchArgs),
}

#[derive(Subcommand)]
enum EvalCommand {
    /// The paper's grounding protocol: detectors' success, IoU and centroid error.
    Grounding(eval_grounding::GroundingEvalArgs),
    /// Hardness estimators on held-out synthetic presses of unseen shapes.
    Hardness(eval_hardness::HardnessEvalArgs),
    /// The paper's Table III: ripeness stages of five fruits told apart by pressing.
    Ripeness(eval_ripeness::RipenessEvalArgs),
    /// The paper's four query tiers end to end: object- and scenario-level success, latency.
    Scenarios(eval_scenarios::ScenarioEvalArgs),
    /// The whole pipeline per catalog fruit kind, alone and on crowded tables: located,
    /// measured, ln error and interval coverage (and `--calibrate`: the intervals' file).
    Fruits(eval_fruits::FruitEvalArgs),
    /// The explainer alone: 100 prompts over random scenes, scored for accuracy,
    /// completeness and clarity against the truth.
    Explanations(eval_explanations::ExplanationEvalArgs),
}

#[derive(Subcommand)]
enum DatagenCommand {
    /// Press sequences (8 frames from first contact, 0.25 mm apart) of randomised objects
    /// and sensors, with hardness labels: pretraining data for tactile hardness models.
    Tactile(datagen_tactile::TactileDatagenArgs),
    /// RGB-D scenes of random fruits with YOLO segmentation labels and a data.yaml that
    /// Ultralytics trains on as is; depth, instance masks and ground truth beside them.
    Scenes(datagen_scenes::SceneDatagenArgs),
    /// A sensor's ball-press calibration set made in the twin, as `calibrate` reads a real
    /// one, with each press's truth.
    BallPresses(datagen_ball_presses::BallPressDatagenArgs),
}

#[derive(Subcommand)]
enum SceneCommand {
    /// Validate a scene file (and its meshes) and print a summary.
    Check { file: PathBuf },
}

pub(crate) fn default_scene() -> PathBuf {
    let local = Path::new("scenes/demo.toml");
    if local.is_file() {
        local.to_path_buf()
    } else {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/demo.toml")
    }
}

fn scene_check(file: &Path) -> Result<()> {
    let catalog = FruitCatalog::builtin();
    // Checked whole before anything is printed: a scene is valid or refused, never both.
    let (scene, world) = ask::load_scene(file, &catalog)?;
    println!(
        "{}: scene '{}' is valid: {} objects on a {:.2} x {:.2} m table",
        file.display(),
        scene.name,
        scene.objects.len(),
        scene.table.size_m[0],
        scene.table.size_m[1]
    );
    for (o, s) in scene.objects.iter().zip(&world.objects) {
        let h = tactex_core::hardness::HardnessReport::from(o.hardness);
        let e = h
            .modulus_mpa
            .map_or("rigid".to_string(), |e| format!("{e:.3} MPa"));
        println!(
            "  {:<11} at ({:+.3}, {:+.3}, {:.3}) m  {:>5} triangles  {e} ({:.1} Shore A){}",
            o.label,
            s.centre.x,
            s.centre.y,
            s.centre.z,
            s.mesh.triangles.len(),
            h.shore_a,
            o.ripeness
                .as_ref()
                .map_or(String::new(), |r| format!(", {r}"))
        );
    }
    Ok(())
}

/// Software Vulkan (lavapipe) prints an error on every start without a runtime directory;
/// give it a private one when the environment has none.
fn ensure_runtime_dir() {
    let usable = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| Path::new(&d).is_dir());
    if usable {
        return;
    }
    let dir = std::env::temp_dir().join("tactex-xdg-runtime");
    if std::fs::create_dir_all(&dir).is_ok() {
        #[cfg(unix)]
        {
            use std::os::unix::fs::PermissionsExt;
            let _ = std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700));
        }
        // SAFETY: called first thing in main, before any thread exists.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
    }
}

/// A closed stdout (`tactex ask ... | head -1`) ends the program quietly, as it does any Unix
/// filter, instead of println! panicking on the broken pipe. Not for `serve`: a browser
/// that goes away must not end the server.
fn quiet_on_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first thing in main, before any thread exists; restores the default.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() -> ExitCode {
    ensure_runtime_dir();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        // A value out of its flag's range is a bad value like any other: one line, exit 1.
        Err(e) if e.kind() == clap::error::ErrorKind::ValueValidation => {
            let text = e.render().to_string();
            eprintln!("{}", text.lines().next().unwrap_or("error: invalid value"));
            return ExitCode::FAILURE;
        }
        Err(e) => e.exit(),
    };
    if !matches!(cli.command, Command::Serve(_) | Command::Twin(_)) {
        quiet_on_closed_pipe();
    }
    let result = match cli.command {
        Command::Ask(args) => ask::run(&args),
        Command::Serve(args) => serve::run(&args),
        Command::Twin(args) => twin::run(&args),
        Command::Arm(args) => arm_cli::run(&args),
        Command::Parse(args) => parse_prompt::run(&args),
        Command::Press(args) => press::run(&args),
        Command::Calibrate(args) => calibrate::run(&args),
        Command::Sensor { command } => sensor_cli::run(&command),
        Command::Compare(args) => compare::run(&args),
        Command::Markers(args) => markers::run(&args),
        Command::Contact(args) => contact_cli::run(&args),
        Command::Detect(args) => detect_image::run(&args),
        Command::Eval {
            command: EvalCommand::Grounding(args),
        } => eval_grounding::run(&args),
        Command::Eval {
            command: EvalCommand::Hardness(args),
        } => eval_hardness::run(&args),
        Command::Eval {
            command: EvalCommand::Scenarios(args),
        } => eval_scenarios::run(&args),
        Command::Eval {
            command: EvalCommand::Fruits(args),
        } => eval_fruits::run(&args),
        Command::Eval {
            command: EvalCommand::Explanations(args),
        } => eval_explanations::run(&args),
        Command::Eval {
            command: EvalCommand::Ripeness(args),
        } => eval_ripeness::run(&args),
        Command::Datagen {
            command: DatagenCommand::Tactile(args),
        } => datagen_tactile::run(&args),
        Command::Datagen {
            command: DatagenCommand::Scenes(args),
        } => datagen_scenes::run(&args),
        Command::Datagen {
            command: DatagenCommand::BallPresses(args),
        } => datagen_ball_presses::run(&args),
        Command::Bench {
            command: BenchCommand::Contact(args),
        } => bench_contact::run(&args),
        Command::Bench {
            command: BenchCommand::Render(args),
        } => bench_render::run(&args),
        Command::Bench {
            command: BenchCommand::Datagen(args),
        } => bench_datagen::run(&args),
        Command::Bench {
            command: BenchCommand::Scene(args),
        } => bench_scene::run(&args),
        Command::Bench {
            command: BenchCommand::Ask(args),
        } => bench_ask::run(&args),
        Command::Scene {
            command: SceneCommand::Check { file },
        } => scene_check(&file),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {}", error_line(&e));
            ExitCode::FAILURE
        }
    }
}

/// The error and its causes on one line, a cause that only repeats what is already said
/// left out (an I/O error wrapped by a library that prints it too), and any control
/// characters from prompts or files shown as escapes rather than sent to the terminal.
fn error_line(e: &anyhow::Error) -> String {
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

#[cfg(test)]
mod tests {
    use super::error_line;

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
