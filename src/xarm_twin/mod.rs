//! `tactex twin`: the twin as an xArm 850 controller. A program written against the vendor's
//! Python SDK (`xarm-python-sdk`) connects to its control port and report ports as to a real
//! controller and moves the GelSight pad through the twin's world; the GelSight's and the
//! RealSense's frames come over HTTP, so the user's own reader code needs nothing of this
//! project.

mod arm_joints;
mod control_port;
pub mod controller;
mod frames_http;
pub mod report;

use anyhow::{Context, Result};
use clap::Args;
use controller::{ArmMount, Controller};
use glam::DVec3;
use report::ReportKind;
use std::net::{IpAddr, SocketAddr, TcpListener};
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::{RgbdCamera, TactileSensor};
use tactex_hw::session::{SessionRecorder, TwinRecord};
use tactex_sim::SimDevices;
use tactex_sim::contact::Fidelity;
use tactex_sim::devices::camera::SimCamera;
use tactex_sim::devices::gelsight::SimGelSight;

#[derive(Args)]
pub struct TwinArgs {
    /// Scene file (TOML); default scenes/demo.toml.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Seed of the sensors' noise: the same scene, seed and commands give the same frames.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Sensor profile of the GelSight on the flange; default the built-in GelSight Mini.
    #[arg(long)]
    pub sensor: Option<PathBuf>,
    /// Contact physics of the GelSight's presses (rigid, hertz, halfspace, layer).
    #[arg(long, default_value = "layer")]
    pub fidelity: Fidelity,
    /// Address every port listens on.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: IpAddr,
    /// Control port (the controller's 502; below 1024 needs root: take e.g. 5020 and set
    /// the SDK's `XCONF.SocketConf.TCP_CONTROL_PORT` to it). 0 takes a free port.
    #[arg(long, default_value_t = 502)]
    pub port: u16,
    /// Port of the rich report (the SDK's default report); 0 to 65535, 0 a free port.
    #[arg(long, default_value_t = 30002)]
    pub report_port: u16,
    /// Port of the normal report; 0 to 65535, 0 a free port.
    #[arg(long, default_value_t = 30001)]
    pub normal_report_port: u16,
    /// Port of the real-time report; 0 to 65535, 0 a free port.
    #[arg(long, default_value_t = 30003)]
    pub real_report_port: u16,
    /// Port of the frames over HTTP (GelSight and RealSense PNGs, the controller's state); 0
    /// to 65535, 0 a free port.
    #[arg(long, default_value_t = 8090)]
    pub http_port: u16,
    /// Where the robot's base stands in the table frame, x,y,z in metres (the table's centre
    /// is the origin, its top z = 0).
    #[arg(long, default_value = "-0.45,0,0", value_parser = parse_base)]
    pub base_m: DVec3,
    /// Moves take their twin-clock duration divided by this in wall time (0.01-1000).
    #[arg(long, default_value_t = 1.0)]
    pub time_scale: f64,
    /// Write every GelSight and RealSense frame served (with the pad's pose) and every move
    /// into a new session directory, as `ask --record` does; it is whole once the twin stops
    /// on Ctrl-C or SIGTERM (`tactex compare --session DIR` reads it back).
    #[arg(long, value_name = "DIR")]
    pub record: Option<PathBuf>,
}

fn parse_base(text: &str) -> std::result::Result<DVec3, String> {
    let v: Vec<f64> = text
        .split(',')
        .map(|t| t.trim().parse::<f64>())
        .collect::<std::result::Result<_, _>>()
        .map_err(|e| format!("expected x,y,z in metres: {e}"))?;
    match v.as_slice() {
        [x, y, z] if v.iter().all(|c| c.is_finite() && c.abs() <= 2.0) => {
            Ok(DVec3::new(*x, *y, *z))
        }
        _ => Err(format!(
            "expected three finite numbers x,y,z within 2 m of the table's centre, got {text:?}"
        )),
    }
}

/// The twin's devices the servers share.
pub struct Twin {
    pub controller: Mutex<Controller>,
    pub gelsight: Mutex<SimGelSight>,
    pub camera: Mutex<SimCamera>,
    pub world: tactex_sim::world::SharedWorld,
    pub recorder: Option<Arc<SessionRecorder>>,
}

fn bind(host: IpAddr, port: u16, flag: &str) -> Result<TcpListener> {
    TcpListener::bind((host, port)).with_context(|| {
        let hint = if port < 1024 && port != 0 {
            " (ports below 1024 need root: take another and set it in the SDK's XCONF.SocketConf)"
        } else {
            ""
        };
        format!("{flag} {port}: cannot listen on {host}:{port}{hint}")
    })
}

pub(crate) fn run(args: &TwinArgs) -> Result<()> {
    if !(args.time_scale.is_finite() && (0.01..=1000.0).contains(&args.time_scale)) {
        anyhow::bail!("--time-scale: {}, expected 0.01..=1000", args.time_scale);
    }
    let catalog = FruitCatalog::builtin();
    let path = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    let (scene, _) = crate::app::load_scene(&path, &catalog)?;
    let sensor = crate::app::load_sensor(args.sensor.as_deref())?;
    let sensor_id = sensor.id();
    let sim = SimDevices::with_sensor(&scene, args.seed, sensor, args.fidelity)?;
    let mount = ArmMount {
        base_m: args.base_m,
        time_scale: args.time_scale,
        ..ArmMount::default()
    };
    let mut controller = Controller::new(sim.world.clone(), sim.arm, mount)
        .map_err(|e| anyhow::anyhow!("the twin's controller: {e}"))?;
    let recorder = match &args.record {
        Some(dir) => {
            let recorder = Arc::new(SessionRecorder::create(dir).context("--record")?);
            recorder.start_camera(
                sim.camera.name(),
                sim.camera.intrinsics(),
                sim.camera.pose(),
            );
            recorder.start_tactile(sim.tactile.name(), sim.tactile.spec());
            let (pad, time_s) = {
                let w = sim
                    .world
                    .lock()
                    .map_err(|_| anyhow::anyhow!("world lock"))?;
                (w.tool, w.time_s)
            };
            recorder.start_arm("twin-xarm-850", pad, Some(time_s));
            let scene_toml = tactex_core::text_file::read_to_string(&path)
                .with_context(|| format!("{}: cannot read the scene again", path.display()))?;
            recorder.twin(TwinRecord {
                scene_toml,
                scene_path: std::path::absolute(&path)
                    .unwrap_or(path.clone())
                    .display()
                    .to_string(),
                seed: args.seed,
                fidelity: Some(args.fidelity.name().into()),
                sensor: Some(sensor_id),
            });
            controller.record_into(recorder.clone());
            Some(recorder)
        }
        None => None,
    };
    let twin = Arc::new(Twin {
        controller: Mutex::new(controller),
        gelsight: Mutex::new(sim.tactile),
        camera: Mutex::new(sim.camera),
        world: sim.world,
        recorder,
    });
    let control = bind(args.host, args.port, "--port")?;
    let reports = [
        (ReportKind::Rich, args.report_port, "--report-port"),
        (
            ReportKind::Normal,
            args.normal_report_port,
            "--normal-report-port",
        ),
        (
            ReportKind::Real,
            args.real_report_port,
            "--real-report-port",
        ),
    ]
    .into_iter()
    .map(|(kind, port, flag)| Ok((kind, bind(args.host, port, flag)?)))
    .collect::<Result<Vec<_>>>()?;
    let http = bind(args.host, args.http_port, "--http-port")?;
    let addr = |l: &TcpListener| -> Result<SocketAddr> { Ok(l.local_addr()?) };
    // One line per port on stdout, first the control port: tests and scripts read them when
    // ports are 0.
    println!("tactex twin: control {}", addr(&control)?);
    for (kind, listener) in &reports {
        println!("tactex twin: report {} {}", kind.name(), addr(listener)?);
    }
    println!("tactex twin: frames http://{}/", addr(&http)?);
    println!("tactex twin: scene {} (seed {})", path.display(), args.seed);
    use std::io::Write;
    std::io::stdout().flush()?;
    for (kind, listener) in reports {
        let twin = twin.clone();
        std::thread::spawn(move || control_port::serve_reports(listener, kind, &twin));
    }
    {
        let twin = twin.clone();
        std::thread::spawn(move || control_port::serve_control(control, &twin));
    }
    frames_http::serve(http, twin.clone())?;
    if let (Some(recorder), Some(dir)) = (&twin.recorder, &args.record) {
        // The servers' threads stop with the process; a move or frame after this is refused.
        recorder.finish("twin", "", None).context("--record")?;
        println!("tactex twin: session written to {}", dir.display());
    }
    Ok(())
}
