//! Session files on their own: depth survives the 16-bit PNG within its 0.1 mm step, a
//! recording that is not finished leaves nothing behind, and replayed devices give back
//! exactly what was recorded and refuse what was not.

use tactex_core::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use tactex_core::frames::{DepthImage, RgbdFrame, TactileFrame};
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::glam::DVec3;
use tactex_core::image::{Luma, Rgb, RgbImage};
use tactex_core::tactile::spec::TactileSpec;
use tactex_hw::session::record::{depth_from_u16, depth_to_u16};
use tactex_hw::session::{SessionRecorder, open_session};

/// A camera whose depth ramps across the image, 0.3 to 0.9 m, with an invalid column.
struct RampCamera {
    k: CameraIntrinsics,
    t: f64,
}

impl RgbdCamera for RampCamera {
    fn name(&self) -> &str {
        "ramp"
    }
    fn intrinsics(&self) -> CameraIntrinsics {
        self.k
    }
    fn pose(&self) -> Pose {
        Pose::IDENTITY
    }
    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        self.t += 0.1;
        let (w, h) = (self.k.width, self.k.height);
        Ok(RgbdFrame {
            color: RgbImage::from_fn(w, h, |x, y| Rgb([x as u8, y as u8, 7])),
            depth_m: DepthImage::from_fn(w, h, |x, _| {
                Luma([if x == 0 {
                    0.0
                } else {
                    0.3 + 0.6 * x as f32 / w as f32
                }])
            }),
            timestamp_s: self.t,
        })
    }
}

struct CountingTactile {
    spec: TactileSpec,
    n: u8,
}

impl TactileSensor for CountingTactile {
    fn name(&self) -> &str {
        "counting"
    }
    fn spec(&self) -> &TactileSpec {
        &self.spec
    }
    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        self.n += 1;
        let n = self.n;
        Ok(TactileFrame {
            image: RgbImage::from_pixel(self.spec.width_px, self.spec.height_px, Rgb([n, 0, 0])),
            timestamp_s: f64::from(n),
        })
    }
}

struct PointArm {
    pose: Pose,
}

impl Arm for PointArm {
    fn name(&self) -> &str {
        "point"
    }
    fn pose(&self) -> Result<Pose, DeviceError> {
        Ok(self.pose)
    }
    fn move_linear(&mut self, target: &Pose, _speed_m_s: f64) -> Result<(), DeviceError> {
        self.pose = *target;
        Ok(())
    }
    fn stop(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }
}

fn devices() -> (RampCamera, CountingTactile, PointArm) {
    let mut k = CameraIntrinsics::default();
    (k.width, k.height, k.cx, k.cy) = (64, 48, 32.0, 24.0);
    (
        RampCamera { k, t: 0.0 },
        CountingTactile {
            spec: TactileSpec::gelsight_mini(),
            n: 0,
        },
        PointArm {
            pose: Pose::tool_down(DVec3::new(0.0, 0.0, 0.3)),
        },
    )
}

#[test]
fn depth_survives_the_png_within_half_a_step_and_invalid_stays_invalid() {
    let (mut cam, ..) = devices();
    let depth = cam.capture().unwrap().depth_m;
    let back = depth_from_u16(&depth_to_u16(&depth), 1e-4);
    for (a, b) in depth.pixels().zip(back.pixels()) {
        assert!((a[0] - b[0]).abs() <= 0.5e-4 + 1e-7, "{} vs {}", a[0], b[0]);
    }
    assert_eq!(back.get_pixel(0, 0)[0], 0.0);
}

#[test]
fn an_unfinished_recording_leaves_nothing_behind() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let (mut cam, ..) = devices();
    {
        let recorder = SessionRecorder::create(&dir).unwrap();
        recorder.camera(&mut cam).capture().unwrap();
        assert!(tmp.path().join("s.partial/camera/color-0000.png").is_file());
    }
    assert!(!dir.exists() && !tmp.path().join("s.partial").exists());
}

#[test]
fn replayed_devices_give_back_what_was_recorded_and_refuse_the_rest() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    let (mut cam, mut tac, mut arm) = devices();
    let recorder = SessionRecorder::create(&dir).unwrap();
    let (mut frames, mut touches) = (Vec::new(), Vec::new());
    let goal = Pose::tool_down(DVec3::new(0.1, 0.0, 0.05));
    {
        let mut c = recorder.camera(&mut cam);
        let mut t = recorder.tactile(&mut tac);
        let mut a = recorder.arm(&mut arm).unwrap();
        frames.push(c.capture().unwrap());
        a.move_linear(&goal, 0.01).unwrap();
        touches.push(t.capture().unwrap());
        touches.push(t.capture().unwrap());
    }
    recorder.finish("test", "How hard is it?", None).unwrap();

    let (manifest, mut c, mut t, mut a) = open_session(&dir).unwrap();
    assert_eq!(manifest.backend, "test");
    assert_eq!(manifest.tactile.frames[1].arm_pose, goal);
    let f = c.capture().unwrap();
    assert_eq!(f.color, frames[0].color);
    assert_eq!(
        f.depth_m, frames[0].depth_m,
        "the recorder gave the stored depth"
    );
    let err = a
        .move_linear(&Pose::tool_down(DVec3::new(0.2, 0.0, 0.05)), 0.01)
        .unwrap_err();
    assert!(err.to_string().contains("diverged"), "{err}");
    let mut turned = goal;
    turned.rotation *= tactex_core::glam::DQuat::from_rotation_z(0.1);
    let err = a.move_linear(&turned, 0.01).unwrap_err().to_string();
    assert!(
        err.contains("turned 5.730 degrees") && err.contains("diverged"),
        "{err}"
    );
    a.move_linear(&goal, 0.01).unwrap();
    assert_eq!(a.pose().unwrap(), goal);
    for want in &touches {
        assert_eq!(t.capture().unwrap().image, want.image);
    }
    let err = t.capture().unwrap_err();
    assert!(err.to_string().contains("has 2 tactile frames"), "{err}");
    assert!(c.capture().is_err());
}

/// A finished session in `dir` of one RGB-D frame, one tactile frame and one move.
fn record_one_of_each(dir: &std::path::Path) {
    let (mut cam, mut tac, mut arm) = devices();
    let recorder = SessionRecorder::create(dir).unwrap();
    {
        recorder.camera(&mut cam).capture().unwrap();
        recorder.tactile(&mut tac).capture().unwrap();
        recorder.arm(&mut arm).unwrap();
    }
    recorder.finish("test", "How hard is it?", None).unwrap();
}

/// A manifest naming a file out of its folder (`../../etc/passwd`) is refused for that
/// reason, not reported as a missing frame.
#[test]
fn a_manifest_pointing_out_of_its_session_is_refused_for_that() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    record_one_of_each(&dir);
    let manifest = dir.join("manifest.json");
    let mut m: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&manifest).unwrap()).unwrap();
    m["tactile"]["frames"][0]["image"] = "../../../../etc/passwd".into();
    std::fs::write(&manifest, m.to_string()).unwrap();
    let err = open_session(&dir).err().expect("refused").to_string();
    assert!(
        err.contains("manifest.json") && err.contains("lies outside the session folder"),
        "{err}"
    );
}

/// A recorded session whose sensor, poses or frames no device gives is refused when it is
/// opened, naming the field or file: a scale of 0 or a dot of 1e308 mm sized the glow's blur
/// in gigabytes, a zero quaternion turned every pose to the origin, and a greyscale or
/// truncated frame showed halfway through as the arm diverging from the recording.
#[test]
fn a_session_no_device_could_have_recorded_is_refused_when_opened() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("s");
    record_one_of_each(&dir);
    assert!(open_session(&dir).is_ok());
    let manifest = dir.join("manifest.json");
    let text = std::fs::read_to_string(&manifest).unwrap();
    let refused = |edit: &dyn Fn(&mut serde_json::Value)| {
        let mut m: serde_json::Value = serde_json::from_str(&text).unwrap();
        edit(&mut m);
        std::fs::write(&manifest, m.to_string()).unwrap();
        let err = open_session(&dir).err().expect("refused").to_string();
        std::fs::write(&manifest, &text).unwrap();
        err
    };
    for (path, value, says) in [
        (
            "mm_per_px",
            serde_json::json!(0.0),
            "tactile.spec.mm_per_px",
        ),
        ("frame_rate_hz", 0.0.into(), "tactile.spec.frame_rate_hz"),
        (
            "gel/modulus_mpa",
            (-5.0).into(),
            "tactile.spec.gel.modulus_mpa",
        ),
        (
            "gel/thickness_mm",
            0.0.into(),
            "tactile.spec.gel.thickness_mm",
        ),
        (
            "markers/cols",
            4_000_000_000u32.into(),
            "tactile.spec.markers",
        ),
        (
            "markers/radius_mm",
            1e308.into(),
            "tactile.spec.markers.radius_mm",
        ),
        (
            "markers/pitch_mm",
            1.5e308.into(),
            "tactile.spec.markers.pitch_mm",
        ),
        ("model", "a\u{1b}[2Jb".into(), "tactile.spec.model"),
    ] {
        let err = refused(&|m| {
            *m.pointer_mut(&format!("/tactile/spec/{path}")).unwrap() = value.clone();
        });
        assert!(
            err.contains(&format!("manifest.json: {says}:")),
            "{path}: {err}"
        );
    }
    let err = refused(&|m| m["arm"]["start_pose"]["rotation"] = serde_json::json!([0, 0, 0, 0]));
    assert!(err.contains("arm.start_pose: rotation"), "{err}");
    let err = refused(&|m| m["camera"]["pose"]["rotation"] = serde_json::json!([0, 0, 0, 2]));
    assert!(err.contains("camera.pose: rotation"), "{err}");
    let err = refused(&|m| m["camera"]["pose"]["position"] = serde_json::json!([1e308, 0, 0]));
    assert!(err.contains("camera.pose: position"), "{err}");
    let err = refused(&|m| m["camera"]["depth_scale_m"] = 1e308.into());
    assert!(err.contains("camera.depth_scale_m: 1e308"), "{err}");
    let err = refused(&|m| m["arm"]["start_time_s"] = (-1e308).into());
    assert!(err.contains("arm.start_time_s: -1e308"), "{err}");
    let err = refused(&|m| m["camera"]["pose"]["position"] = serde_json::json!([1e300, 0, 0]));
    assert!(err.contains("position [1e300, 0, 0] is more"), "{err}");
    // Frames listed out of the order taken, and a move asked at no speed: edits no device
    // makes, which would show only later as the replay diverging from the recording.
    let err = refused(&|m| {
        let mut late = m["tactile"]["frames"][0].clone();
        late["timestamp_s"] = 2.0.into();
        let mut early = late.clone();
        early["timestamp_s"] = 1.0.into();
        m["tactile"]["frames"] = serde_json::json!([late, early]);
    });
    assert!(
        err.contains("tactile.frames[1].timestamp_s: 1 is before the frame listed before it (2)"),
        "{err}"
    );
    let err = refused(&|m| m["camera"]["frames"][0]["timestamp_s"] = 1e300.into());
    assert!(err.contains("camera.frames[0].timestamp_s: 1e300"), "{err}");
    let err = refused(&|m| {
        let pose = m["arm"]["start_pose"].clone();
        m["arm"]["moves"] = serde_json::json!([{"target": pose, "speed_m_s": -0.05,
            "reached": pose, "time_s": null, "error": null}]);
    });
    assert!(err.contains("arm.moves[0].speed_m_s: -0.05"), "{err}");
    // One frame listed past any question's count is refused before a frame is decoded.
    let err = refused(&|m| {
        let frame = m["tactile"]["frames"][0].clone();
        m["tactile"]["frames"] = serde_json::Value::Array(vec![frame; 100_001]);
    });
    assert!(
        err.contains("manifest.json: frames: 100002 frames listed"),
        "{err}"
    );
    let err = refused(&|m| {
        m["twin"] = serde_json::json!({"scene_toml": "", "scene_path": "x", "seed": 1,
            "sensor": {"name": "GelSight Mini", "sha256": "ééééééééé"}})
    });
    assert!(err.contains("twin.sensor.sha256"), "{err}");
    // Names shown in reports: one printable line.
    let err = refused(&|m| m["backend"] = "sim\u{1b}[2J".into());
    assert!(err.contains("manifest.json: backend:"), "{err}");
    let err = refused(&|m| {
        m["twin"] = serde_json::json!({"scene_toml": "", "scene_path": "x\u{202e}y", "seed": 1})
    });
    assert!(err.contains("manifest.json: twin.scene_path:"), "{err}");

    // Frames: each replaced by one no recorder writes, then put back.
    let frame = |file: &str, bytes: &[u8]| {
        let p = dir.join(file);
        let good = std::fs::read(&p).unwrap();
        std::fs::write(&p, bytes).unwrap();
        let err = open_session(&dir).err().expect("refused").to_string();
        std::fs::write(&p, good).unwrap();
        assert!(err.contains(file), "{err}");
        err
    };
    let png = |image: tactex_core::image::DynamicImage| {
        let mut bytes = std::io::Cursor::new(Vec::new());
        image
            .write_to(&mut bytes, tactex_core::image::ImageFormat::Png)
            .unwrap();
        bytes.into_inner()
    };
    let tactile = std::fs::read(dir.join("tactile/0000.png")).unwrap();
    let err = frame("tactile/0000.png", &tactile[..tactile.len() / 2]);
    assert!(err.contains("not a readable frame"), "{err}");
    let grey = tactex_core::image::GrayImage::new(320, 240);
    let err = frame("tactile/0000.png", &png(grey.into()));
    assert!(err.contains("greyscale"), "{err}");
    let rgba = tactex_core::image::RgbaImage::new(320, 240);
    let err = frame("tactile/0000.png", &png(rgba.into()));
    assert!(
        err.contains("a Rgba8 image") && err.contains("8-bit RGB"),
        "{err}"
    );
    let colour = RgbImage::new(64, 48);
    let err = frame("camera/depth-0000.png", &png(colour.into()));
    assert!(err.contains("depth frame"), "{err}");
    let depth = tactex_core::image::ImageBuffer::<Luma<u16>, Vec<u16>>::new(64, 48);
    let err = frame("camera/color-0000.png", &png(depth.into()));
    assert!(err.contains("greyscale"), "{err}");
    assert!(open_session(&dir).is_ok());

    // A link in the folder that leads out of it.
    #[cfg(unix)]
    {
        let outside = tmp.path().join("elsewhere.png");
        std::fs::copy(dir.join("tactile/0000.png"), &outside).unwrap();
        std::fs::remove_file(dir.join("tactile/0000.png")).unwrap();
        std::os::unix::fs::symlink(&outside, dir.join("tactile/0000.png")).unwrap();
        let err = open_session(&dir).err().expect("refused").to_string();
        assert!(err.contains("out of the session folder"), "{err}");
        // A link that loops is named for what it is, not as a missing frame.
        std::fs::remove_file(dir.join("tactile/0000.png")).unwrap();
        std::os::unix::fs::symlink("0000.png", dir.join("tactile/0000.png")).unwrap();
        let err = open_session(&dir).err().expect("refused").to_string();
        assert!(
            err.contains("tactile/0000.png") && !err.contains("missing"),
            "{err}"
        );
    }
}
