//! `tactex twin` as an xArm controller, met from the client side by this project's own xArm
//! client (which checks every reply frame as the vendor SDK frames it): connect, enable,
//! move, read the pose, faults raised and cleared; frames nobody should send, a client gone
//! mid-move and eight clients at once leave the controller answering; the report streams'
//! framing; the same commands give the same GelSight frame.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::TcpStream;
use std::process::{Child, ChildStdout, Command, Stdio};
use std::time::Duration;
use tactex_hw::xarm::{TcpPose, WorkspaceBox, XArm, XArmConfig, XArmError};

struct Twin {
    child: Child,
    _stdout: BufReader<ChildStdout>,
    control: String,
    rich: String,
    real: String,
    http: String,
}

impl Twin {
    fn start() -> Twin {
        let mut child = Command::new(env!("CARGO_BIN_EXE_tactex"))
            .args(["twin", "--port", "0", "--report-port", "0"])
            .args(["--normal-report-port", "0", "--real-report-port", "0"])
            .args([
                "--http-port",
                "0",
                "--time-scale",
                "20",
                "--fidelity",
                "hertz",
            ])
            .current_dir(env!("CARGO_MANIFEST_DIR"))
            .stdout(Stdio::piped())
            .spawn()
            .expect("starts tactex twin");
        let mut stdout = BufReader::new(child.stdout.take().expect("piped stdout"));
        let mut lines = Vec::new();
        for _ in 0..5 {
            let mut line = String::new();
            stdout.read_line(&mut line).expect("reads a port line");
            lines.push(line);
        }
        let find = |tag: &str| {
            lines
                .iter()
                .find(|l| l.contains(tag))
                .and_then(|l| l.split_whitespace().last())
                .unwrap_or_else(|| panic!("no {tag} line in {lines:?}"))
                .trim_start_matches("http://")
                .trim_end_matches('/')
                .to_string()
        };
        Twin {
            control: find("control"),
            rich: find("report rich"),
            real: find("report real"),
            http: find("frames"),
            child,
            _stdout: stdout,
        }
    }

    fn arm(&self) -> XArm {
        let mut config = XArmConfig::new(self.control.clone());
        // The twin's safety boundary is its own to enforce; the client's box lets all through.
        config.workspace = WorkspaceBox::from_bounds_mm([-5e3, 5e3, -5e3, 5e3, -5e3, 5e3]).unwrap();
        config.move_timeout = Duration::from_secs(60);
        XArm::connect(config).expect("connects to the twin")
    }

    fn get(&self, path: &str) -> Vec<u8> {
        let mut r = ureq::get(&format!("http://{}{path}", self.http))
            .call()
            .expect("GET reaches the twin");
        let mut body = Vec::new();
        r.body_mut()
            .as_reader()
            .read_to_end(&mut body)
            .expect("reads the body");
        body
    }
}

impl Drop for Twin {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The pad pointing down at (x, y, z) mm in the base frame.
fn down(x: f64, y: f64, z: f64) -> TcpPose {
    TcpPose::from_array([x, y, z, std::f64::consts::PI, 0.0, 0.0])
}

fn controller_error(e: &XArmError) -> Option<u8> {
    match e {
        XArmError::Controller { code, .. } => Some(*code),
        _ => None,
    }
}

#[test]
fn a_client_moves_the_pad_and_faults_are_raised_and_cleared_as_the_controller_does() {
    let twin = Twin::start();
    let arm = twin.arm();
    arm.prepare().unwrap();
    let home = arm.tcp_pose().unwrap();
    assert_eq!(
        [home.x_mm, home.y_mm, home.z_mm],
        [300.0, 0.0, 300.0],
        "{home:?}"
    );
    arm.move_line(&down(420.0, -30.0, 150.0), 200.0).unwrap();
    let p = arm.tcp_pose().unwrap();
    assert!(
        (p.x_mm - 420.0).abs() < 1e-3
            && (p.y_mm + 30.0).abs() < 1e-3
            && (p.z_mm - 150.0).abs() < 1e-3,
        "{p:?}"
    );
    // Into the table: the collision error; the arm stays where it was.
    let e = arm.move_line(&down(420.0, -30.0, -5.0), 100.0).unwrap_err();
    let code = controller_error(&e).or_else(|| arm.error_warning().ok().map(|(c, _)| c));
    assert_eq!(code, Some(31), "{e}");
    arm.clean_error().unwrap();
    arm.prepare().unwrap();
    assert_eq!(arm.error_warning().unwrap(), (0, 0));
    assert!((arm.tcp_pose().unwrap().z_mm - 150.0).abs() < 1e-3);
    // Off the table's edge: the safety boundary.
    let e = arm.move_line(&down(1200.0, 0.0, 150.0), 100.0).unwrap_err();
    let code = controller_error(&e).or_else(|| arm.error_warning().ok().map(|(c, _)| c));
    assert_eq!(code, Some(35), "{e}");
    arm.clean_error().unwrap();
    arm.prepare().unwrap();
    arm.move_home(0.35).unwrap();
    let p = arm.tcp_pose().unwrap();
    assert_eq!([p.x_mm, p.y_mm, p.z_mm], [300.0, 0.0, 300.0]);
}

#[test]
fn bad_frames_a_client_gone_mid_move_and_eight_clients_leave_the_controller_answering() {
    let twin = Twin::start();
    // Unknown protocol id, a zero length, an unknown register: each closes or is answered
    // invalid, for that client alone.
    let bad: [&[u8]; 3] = [
        &[0, 1, 0x12, 0x34, 0, 1, 13],
        &[0, 2, 0, 2, 0, 0],
        &[0, 3, 0, 2, 0, 1, 250],
    ];
    for frame in bad {
        let mut s = TcpStream::connect(&twin.control).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        s.write_all(frame).unwrap();
        let mut reply = [0u8; 8];
        match s.read_exact(&mut reply) {
            // Answered: the same transaction and register, flagged invalid.
            Ok(()) => {
                assert_eq!(&reply[..2], &frame[..2]);
                assert_eq!(reply[6], frame[6]);
                assert_ne!(reply[7] & 0x08, 0, "{reply:?}");
            }
            // Or closed.
            Err(e) => assert!(
                matches!(
                    e.kind(),
                    std::io::ErrorKind::UnexpectedEof | std::io::ErrorKind::ConnectionReset
                ),
                "{e}"
            ),
        }
    }
    // A client that starts a long move and goes.
    {
        let mut s = TcpStream::connect(&twin.control).unwrap();
        let arm = twin.arm();
        arm.prepare().unwrap();
        let mut params = Vec::new();
        for v in [
            300.0f32,
            0.0,
            100.0,
            std::f32::consts::PI,
            0.0,
            0.0,
            20.0,
            500.0,
            0.0,
        ] {
            params.extend(v.to_le_bytes());
        }
        let mut frame = vec![0, 9, 0, 2, 0, 37, 21];
        frame.extend(params);
        s.write_all(&frame).unwrap();
        drop(s);
    }
    // Eight clients at once, each reading the pose and the state while that move runs on.
    let handles: Vec<_> = (0..8)
        .map(|_| {
            let addr = twin.control.clone();
            std::thread::spawn(move || {
                let mut config = XArmConfig::new(addr);
                config.reply_timeout = Duration::from_secs(10);
                let arm = XArm::connect(config).unwrap();
                for _ in 0..20 {
                    arm.tcp_pose().unwrap();
                    arm.motion_state().unwrap();
                }
            })
        })
        .collect();
    for h in handles {
        h.join().expect("a client thread");
    }
    let arm = twin.arm();
    let mut settled = false;
    for _ in 0..400 {
        if (arm.tcp_pose().unwrap().z_mm - 100.0).abs() < 1e-3 {
            settled = true;
            break;
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    assert!(settled, "the move of the client that left ran to its end");
}

#[test]
fn reports_are_framed_as_the_sdk_reads_them() {
    let twin = Twin::start();
    for (addr, len) in [(&twin.rich, 587usize), (&twin.real, 135)] {
        let mut s = TcpStream::connect(addr).unwrap();
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        for _ in 0..3 {
            let mut r = vec![0u8; len];
            s.read_exact(&mut r).unwrap();
            assert_eq!(u32::from_be_bytes(r[..4].try_into().unwrap()) as usize, len);
            // Stopped (4) until enabled, mode 0.
            assert_eq!(r[4], 4);
            let z = f32::from_le_bytes(r[43..47].try_into().unwrap());
            assert_eq!(z, 300.0);
        }
    }
}

/// Mean absolute difference of two PNG frames in grey levels.
fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    let a = image::load_from_memory(a).unwrap().to_rgb8();
    let b = image::load_from_memory(b).unwrap().to_rgb8();
    let n = a.as_raw().len() as f64;
    a.as_raw()
        .iter()
        .zip(b.as_raw())
        .map(|(x, y)| (f64::from(*x) - f64::from(*y)).abs())
        .sum::<f64>()
        / n
}

#[test]
fn a_press_through_the_controller_shows_in_the_gelsight_and_repeats_byte_for_byte() {
    // The demo scene's lime stands at (0.03, -0.04) m on the table: 480, -40 mm from the base.
    let press = || {
        let twin = Twin::start();
        let arm = twin.arm();
        arm.prepare().unwrap();
        arm.move_line(&down(480.0, -40.0, 70.0), 200.0).unwrap();
        let mut frames = vec![twin.get("/gelsight/frame.png")];
        let mut z = 60.0;
        while z >= 44.0 {
            arm.move_line(&down(480.0, -40.0, z), 50.0).unwrap();
            frames.push(twin.get("/gelsight/frame.png"));
            z -= 1.0;
        }
        // Far past first contact: the crush limit's collision error, the pad kept clear.
        let e = arm.move_line(&down(480.0, -40.0, 20.0), 50.0).unwrap_err();
        let code = controller_error(&e).or_else(|| arm.error_warning().ok().map(|(c, _)| c));
        assert_eq!(code, Some(31), "{e}");
        let state: serde_json::Value = serde_json::from_slice(&twin.get("/state")).unwrap();
        assert_eq!(state["error_code"], 31, "{state}");
        assert!(
            state["last_notice"].as_str().unwrap().contains("lime"),
            "{state}"
        );
        let depth = image::load_from_memory(&twin.get("/camera/depth.png")).unwrap();
        assert!(matches!(depth, image::DynamicImage::ImageLuma16(_)));
        frames
    };
    let a = press();
    let image = image::load_from_memory(&a[0]).unwrap();
    assert_eq!((image.width(), image.height()), (320, 240));
    let changes: Vec<f64> = a.iter().map(|f| mean_abs_diff(&a[0], f)).collect();
    assert!(
        changes[1] < 3.0,
        "no contact 10 mm above the lime: {changes:?}"
    );
    assert!(
        changes.last().unwrap() > &5.0,
        "the pad pressed into the lime shows: {changes:?}"
    );
    assert_eq!(a, press(), "same scene, seed and commands: the same frames");
}

#[test]
fn the_gelsight_images_the_pad_mid_move_and_streams_as_mjpeg() {
    let twin = Twin::start();
    let arm = twin.arm();
    arm.prepare().unwrap();
    arm.move_line(&down(480.0, -40.0, 60.0), 200.0).unwrap();
    let reference = twin.get("/gelsight/frame.png");
    // A slow descent into the lime (16 mm at 0.5 mm/s: 1.6 s of wall time at --time-scale 20),
    // from a second client; the frame taken early in it is where the pad is then, above the
    // lime, not where the move ends.
    let mover = {
        let control = twin.control.clone();
        std::thread::spawn(move || {
            let mut config = XArmConfig::new(control);
            config.workspace =
                WorkspaceBox::from_bounds_mm([-5e3, 5e3, -5e3, 5e3, -5e3, 5e3]).unwrap();
            let arm = XArm::connect(config).unwrap();
            arm.move_line(&down(480.0, -40.0, 44.0), 0.5).unwrap();
        })
    };
    std::thread::sleep(Duration::from_millis(200));
    let state: serde_json::Value = serde_json::from_slice(&twin.get("/state")).unwrap();
    let mid = twin.get("/gelsight/frame.png");
    let z = state["pose"][2].as_f64().unwrap();
    assert!(state["state"] == 1 && z < 60.0 && z > 50.0, "{state}");
    mover.join().unwrap();
    let end = twin.get("/gelsight/frame.png");
    let (early, late) = (
        mean_abs_diff(&reference, &mid),
        mean_abs_diff(&reference, &end),
    );
    assert!(early < 3.0 && late > 5.0, "{early} {late}");

    // The MJPEG stream: parts framed by the boundary the header names, each a whole JPEG.
    let mut r = ureq::get(&format!("http://{}/gelsight/stream.mjpg", twin.http))
        .call()
        .unwrap();
    let kind = r.headers()["content-type"].to_str().unwrap().to_string();
    let boundary = kind.split("boundary=").nth(1).unwrap().to_string();
    assert!(kind.starts_with("multipart/x-mixed-replace"), "{kind}");
    let mut body = r.body_mut().as_reader();
    for _ in 0..2 {
        let mut head = Vec::new();
        while !head.ends_with(b"\r\n\r\n") {
            let mut byte = [0u8];
            body.read_exact(&mut byte).unwrap();
            head.push(byte[0]);
        }
        let head = String::from_utf8(head).unwrap();
        assert!(head.starts_with(&format!("--{boundary}\r\n")), "{head}");
        let length: usize = head
            .lines()
            .find_map(|l| l.strip_prefix("Content-Length: "))
            .unwrap()
            .parse()
            .unwrap();
        let mut jpeg = vec![0u8; length + 2];
        body.read_exact(&mut jpeg).unwrap();
        let frame =
            image::load_from_memory_with_format(&jpeg[..length], image::ImageFormat::Jpeg).unwrap();
        assert_eq!((frame.width(), frame.height()), (320, 240));
        assert_eq!(&jpeg[length..], b"\r\n");
    }

    // SIGTERM with the stream still open: the stream ends and the twin exits (it was alive
    // 45 s later, a viewer holding its graceful shutdown; now about 1.3 s).
    let mut twin = twin;
    let killed = Command::new("kill")
        .args(["-TERM", &twin.child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    let deadline = std::time::Instant::now() + Duration::from_secs(20);
    let exited = loop {
        if let Some(status) = twin.child.try_wait().unwrap() {
            break Some(status);
        }
        if std::time::Instant::now() > deadline {
            break None;
        }
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(
        exited.is_some(),
        "the twin is still running 20 s after SIGTERM"
    );
    drop(body);
}

#[test]
fn a_mode_the_controller_lacks_is_refused_with_a_warning_and_a_notice() {
    let twin = Twin::start();
    let arm = twin.arm();
    arm.prepare().unwrap();
    // The reply carries warning 12; the client may report it or not.
    let _ = arm.set_mode(99);
    assert_eq!(arm.error_warning().unwrap().1, 12);
    let state: serde_json::Value = serde_json::from_slice(&twin.get("/state")).unwrap();
    assert_eq!(state["mode"], 0, "{state}");
    let notice = state["last_notice"].as_str().unwrap_or_default();
    assert!(notice.contains("set_mode(99)"), "{state}");
}
