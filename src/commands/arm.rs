//! `tactex arm`: bring-up of a real xArm (or the vendor's simulator) from the command line,
//! speaking the controller's protocol as the vendor SDK does: read the pose, move in a
//! straight line (mm and degrees), go home.

use anyhow::{Result, bail};
use clap::{Args, Subcommand};
use std::time::Duration;
use tactex_hw::xarm::{TcpPose, WorkspaceBox, XArm, XArmConfig};

#[derive(Args)]
pub struct ArmArgs {
    /// The controller, HOST:PORT (the vendor's port is 502).
    #[arg(long)]
    pub addr: String,
    /// Seconds a reply may take.
    #[arg(long, default_value_t = 3.0)]
    pub timeout_s: f64,
    /// Seconds a move may take.
    #[arg(long, default_value_t = 120.0)]
    pub move_timeout_s: f64,
    /// The box moves must stay in, base frame, mm: X0,X1,Y0,Y1,Z0,Z1 (default 100,700,
    /// -400,400,50,600: in front of the arm, above the table).
    #[arg(long, allow_hyphen_values = true)]
    pub workspace_mm: Option<String>,
    #[command(subcommand)]
    pub command: ArmCommand,
}

#[derive(Subcommand)]
pub enum ArmCommand {
    /// The tool centre's pose in the base frame.
    Pose {
        /// One JSON object: x_mm, y_mm, z_mm, roll_deg, pitch_deg, yaw_deg.
        #[arg(long)]
        json: bool,
    },
    /// A straight-line move of the tool centre: X Y Z in mm, ROLL PITCH YAW in degrees.
    Move {
        #[arg(allow_hyphen_values = true)]
        x_mm: f64,
        #[arg(allow_hyphen_values = true)]
        y_mm: f64,
        #[arg(allow_hyphen_values = true)]
        z_mm: f64,
        #[arg(allow_hyphen_values = true)]
        roll_deg: f64,
        #[arg(allow_hyphen_values = true)]
        pitch_deg: f64,
        #[arg(allow_hyphen_values = true)]
        yaw_deg: f64,
        /// Tool speed in mm/s (at most 250).
        #[arg(long, default_value_t = 50.0)]
        speed: f64,
    },
    /// The joints to their home position.
    Home {
        /// Joint speed in degrees per second.
        #[arg(long, default_value_t = 20.0)]
        speed_deg_s: f64,
    },
}

fn workspace(spec: &str) -> Result<WorkspaceBox> {
    let v: Vec<f64> = spec
        .split(',')
        .map(|s| s.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|e| anyhow::anyhow!("--workspace-mm '{spec}': {e}"))?;
    let bounds: [f64; 6] = v
        .try_into()
        .map_err(|_| anyhow::anyhow!("--workspace-mm '{spec}': expected six numbers"))?;
    WorkspaceBox::from_bounds_mm(bounds)
        .map_err(|e| anyhow::anyhow!("--workspace-mm '{spec}': {e}"))
}

fn seconds(flag: &str, s: f64) -> Result<Duration> {
    if !(s.is_finite() && s > 0.0) {
        bail!("{flag}: {s} is not a positive number of seconds");
    }
    Ok(Duration::from_secs_f64(s))
}

fn print_pose(p: &TcpPose, json: bool) -> Result<()> {
    if json {
        println!(
            "{}",
            serde_json::json!({
                "x_mm": p.x_mm,
                "y_mm": p.y_mm,
                "z_mm": p.z_mm,
                "roll_deg": p.roll_rad.to_degrees(),
                "pitch_deg": p.pitch_rad.to_degrees(),
                "yaw_deg": p.yaw_rad.to_degrees(),
            })
        );
    } else {
        println!(
            "x {:.2} mm  y {:.2} mm  z {:.2} mm  roll {:.2} deg  pitch {:.2} deg  yaw {:.2} deg",
            p.x_mm,
            p.y_mm,
            p.z_mm,
            p.roll_rad.to_degrees(),
            p.pitch_rad.to_degrees(),
            p.yaw_rad.to_degrees()
        );
    }
    Ok(())
}

pub(crate) fn run(args: &ArmArgs) -> Result<()> {
    let mut config = XArmConfig::new(&args.addr);
    config.reply_timeout = seconds("--timeout-s", args.timeout_s)?;
    config.move_timeout = seconds("--move-timeout-s", args.move_timeout_s)?;
    if let Some(spec) = &args.workspace_mm {
        config.workspace = workspace(spec)?;
    }
    let arm = XArm::connect(config)?;
    match &args.command {
        ArmCommand::Pose { json } => print_pose(&arm.tcp_pose()?, *json),
        ArmCommand::Move {
            x_mm,
            y_mm,
            z_mm,
            roll_deg,
            pitch_deg,
            yaw_deg,
            speed,
        } => {
            let target = TcpPose {
                x_mm: *x_mm,
                y_mm: *y_mm,
                z_mm: *z_mm,
                roll_rad: roll_deg.to_radians(),
                pitch_rad: pitch_deg.to_radians(),
                yaw_rad: yaw_deg.to_radians(),
            };
            // Checked before the arm is enabled, so a refused move changes nothing.
            if let Some(reason) = arm.config().workspace.violation(&target) {
                bail!("xarm {}: move refused: {reason}", args.addr);
            }
            arm.prepare()?;
            arm.move_line(&target, *speed)?;
            print_pose(&arm.tcp_pose()?, false)
        }
        ArmCommand::Home { speed_deg_s } => {
            if !(speed_deg_s.is_finite() && *speed_deg_s > 0.0 && *speed_deg_s <= 180.0) {
                bail!("--speed-deg-s: {speed_deg_s} is not in (0, 180]");
            }
            arm.prepare()?;
            arm.move_home(speed_deg_s.to_radians())?;
            print_pose(&arm.tcp_pose()?, false)
        }
    }
}
