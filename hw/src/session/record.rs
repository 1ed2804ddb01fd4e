//! Recording: wrappers around any backend's devices that pass every call through and write
//! what came back into the session directory.

use super::format::{
    ArmRecord, CameraRecord, DEPTH_SCALE_M, FORMAT, MANIFEST, Manifest, MoveRecord, RgbdRecord,
    SessionError, TactileFrameRecord, TactileRecord, TwinRecord, partial_dir,
};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, MutexGuard};
use tactex_core::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use tactex_core::frames::{DepthImage, RgbdFrame, TactileFrame};
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::image::{ImageBuffer, Luma};
use tactex_core::tactile::spec::TactileSpec;

struct Log {
    partial: PathBuf,
    dir: PathBuf,
    camera: Option<CameraRecord>,
    tactile: Option<TactileRecord>,
    arm: Option<ArmRecord>,
    arm_pose: Pose,
    twin: Option<TwinRecord>,
    finished: bool,
}

/// The session being written. Dropped without `finish`, it removes what it wrote.
pub struct SessionRecorder {
    log: Arc<Mutex<Log>>,
}

fn lock(log: &Mutex<Log>) -> MutexGuard<'_, Log> {
    log.lock().unwrap_or_else(|e| e.into_inner())
}

fn recorder_error(path: &Path, e: impl std::fmt::Display) -> DeviceError {
    DeviceError::Failure {
        device: "session recorder".into(),
        message: format!("{}: {e}", path.display()),
    }
}

/// Depth as the session stores it: 0.1 mm steps, 0 for invalid or out of range.
pub fn depth_to_u16(depth: &DepthImage) -> ImageBuffer<Luma<u16>, Vec<u16>> {
    let max = f64::from(u16::MAX) * DEPTH_SCALE_M;
    ImageBuffer::from_fn(depth.width(), depth.height(), |x, y| {
        let d = f64::from(depth.get_pixel(x, y)[0]);
        Luma([if d.is_finite() && d > 0.0 && d < max {
            (d / DEPTH_SCALE_M).round() as u16
        } else {
            0
        }])
    })
}

pub fn depth_from_u16(depth: &ImageBuffer<Luma<u16>, Vec<u16>>, scale_m: f64) -> DepthImage {
    ImageBuffer::from_fn(depth.width(), depth.height(), |x, y| {
        Luma([(f64::from(depth.get_pixel(x, y)[0]) * scale_m) as f32])
    })
}

impl SessionRecorder {
    /// Starts a session in `dir`, which must not exist yet. While it records, `DIR.partial`
    /// is this process's: a second recorder into the same directory is refused.
    pub fn create(dir: &Path) -> Result<SessionRecorder, SessionError> {
        if dir.exists() {
            return Err(SessionError::file(
                dir,
                "already exists; a session is recorded into a new directory",
            ));
        }
        let partial = partial_dir(dir);
        tactex_core::dir_claim::claim_dir(&partial, "recording a session")
            .map_err(|e| SessionError::file(&e.path, e.reason))?;
        for sub in ["camera", "tactile"] {
            std::fs::create_dir_all(partial.join(sub))
                .map_err(|e| SessionError::file(&partial, format!("cannot create: {e}")))?;
        }
        Ok(SessionRecorder {
            log: Arc::new(Mutex::new(Log {
                partial,
                dir: dir.to_path_buf(),
                camera: None,
                tactile: None,
                arm: None,
                arm_pose: Pose::IDENTITY,
                twin: None,
                finished: false,
            })),
        })
    }

    pub fn camera<'a, C: RgbdCamera>(&self, camera: &'a mut C) -> RecordingCamera<'a, C> {
        self.start_camera(camera.name(), camera.intrinsics(), camera.pose());
        RecordingCamera {
            inner: camera,
            log: self.log.clone(),
        }
    }

    pub fn tactile<'a, T: TactileSensor>(&self, sensor: &'a mut T) -> RecordingTactile<'a, T> {
        self.start_tactile(sensor.name(), sensor.spec());
        RecordingTactile {
            inner: sensor,
            log: self.log.clone(),
        }
    }

    pub fn arm<'a, A: Arm>(&self, arm: &'a mut A) -> Result<RecordingArm<'a, A>, DeviceError> {
        self.start_arm(arm.name(), arm.pose()?, arm.sim_time_s());
        Ok(RecordingArm {
            inner: arm,
            log: self.log.clone(),
        })
    }

    /// Records a camera's frames from now on (a device that is not wrapped, e.g. one shared
    /// between servers: its frames come through `camera_frame`).
    pub fn start_camera(&self, name: &str, intrinsics: CameraIntrinsics, pose: Pose) {
        lock(&self.log).camera = Some(CameraRecord {
            name: name.into(),
            intrinsics,
            pose,
            depth_scale_m: DEPTH_SCALE_M,
            frames: Vec::new(),
        });
    }

    pub fn start_tactile(&self, name: &str, spec: &TactileSpec) {
        lock(&self.log).tactile = Some(TactileRecord {
            name: name.into(),
            spec: spec.clone(),
            frames: Vec::new(),
        });
    }

    pub fn start_arm(&self, name: &str, start_pose: Pose, start_time_s: Option<f64>) {
        let mut log = lock(&self.log);
        log.arm_pose = start_pose;
        log.arm = Some(ArmRecord {
            name: name.into(),
            start_pose,
            start_time_s,
            moves: Vec::new(),
        });
    }

    /// Writes a camera frame; returns it as the session stores it (depth in 0.1 mm steps).
    pub fn camera_frame(&self, frame: RgbdFrame) -> Result<RgbdFrame, DeviceError> {
        record_camera_frame(&self.log, frame)
    }

    /// Writes a tactile frame taken with the pad at `arm_pose`.
    pub fn tactile_frame(&self, frame: &TactileFrame, arm_pose: Pose) -> Result<(), DeviceError> {
        record_tactile_frame(&self.log, frame, Some(arm_pose))
    }

    /// Notes a move the arm was asked for and how it ended.
    pub fn arm_move(&self, record: MoveRecord) {
        record_move(&self.log, record);
    }

    /// Notes the sim world being recorded, so that the twin can rebuild its presses.
    pub fn twin(&self, twin: TwinRecord) {
        lock(&self.log).twin = Some(twin);
    }

    /// Writes the manifest and moves the session to its directory; frames offered after it
    /// are refused.
    pub fn finish(
        &self,
        backend: &str,
        prompt: &str,
        answer: Option<serde_json::Value>,
    ) -> Result<PathBuf, SessionError> {
        let mut log = lock(&self.log);
        let missing = |what: &str| SessionError::file(&log.dir, format!("no {what} was recorded"));
        let manifest = Manifest {
            format: FORMAT.into(),
            created_by: format!("tactex {}", env!("CARGO_PKG_VERSION")),
            backend: backend.into(),
            prompt: prompt.into(),
            camera: log.camera.clone().ok_or_else(|| missing("camera"))?,
            tactile: log
                .tactile
                .clone()
                .ok_or_else(|| missing("tactile sensor"))?,
            arm: log.arm.clone().ok_or_else(|| missing("arm"))?,
            answer,
            twin: log.twin.clone(),
        };
        if log.finished {
            return Err(SessionError::file(
                &log.dir,
                "the session is already written",
            ));
        }
        let path = log.partial.join(MANIFEST);
        let text =
            serde_json::to_string_pretty(&manifest).map_err(|e| SessionError::file(&path, e))?;
        std::fs::write(&path, text + "\n").map_err(|e| SessionError::file(&path, e))?;
        tactex_core::dir_claim::release_dir(&log.partial);
        std::fs::rename(&log.partial, &log.dir).map_err(|e| {
            SessionError::file(&log.dir, format!("cannot move the session here: {e}"))
        })?;
        log.finished = true;
        Ok(log.dir.clone())
    }
}

impl Drop for SessionRecorder {
    fn drop(&mut self) {
        let log = lock(&self.log);
        if !log.finished {
            let _ = std::fs::remove_dir_all(&log.partial);
        }
    }
}

fn save_png<P, C>(image: &ImageBuffer<P, C>, path: &Path) -> Result<(), DeviceError>
where
    P: tactex_core::image::PixelWithColorType,
    [P::Subpixel]: tactex_core::image::EncodableLayout,
    C: std::ops::Deref<Target = [P::Subpixel]>,
{
    image.save(path).map_err(|e| recorder_error(path, e))
}

pub struct RecordingCamera<'a, C: RgbdCamera> {
    inner: &'a mut C,
    log: Arc<Mutex<Log>>,
}

impl<C: RgbdCamera> RgbdCamera for RecordingCamera<'_, C> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn intrinsics(&self) -> CameraIntrinsics {
        self.inner.intrinsics()
    }
    fn pose(&self) -> Pose {
        self.inner.pose()
    }

    /// The frame as the session stores it (depth in 0.1 mm steps), so that the answer given
    /// while recording is the one a replay gives.
    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        let frame = self.inner.capture()?;
        record_camera_frame(&self.log, frame)
    }
}

fn refuse_finished(log: &Log) -> Result<(), DeviceError> {
    if log.finished {
        return Err(recorder_error(&log.dir, "the session is already written"));
    }
    Ok(())
}

fn record_camera_frame(log: &Mutex<Log>, frame: RgbdFrame) -> Result<RgbdFrame, DeviceError> {
    let mut log = lock(log);
    refuse_finished(&log)?;
    let n = log.camera.as_ref().map_or(0, |c| c.frames.len());
    let (color, depth) = (
        format!("camera/color-{n:04}.png"),
        format!("camera/depth-{n:04}.png"),
    );
    let stored = depth_to_u16(&frame.depth_m);
    save_png(&frame.color, &log.partial.join(&color))?;
    save_png(&stored, &log.partial.join(&depth))?;
    if let Some(c) = log.camera.as_mut() {
        c.frames.push(RgbdRecord {
            color,
            depth,
            timestamp_s: frame.timestamp_s,
        });
    }
    Ok(RgbdFrame {
        color: frame.color,
        depth_m: depth_from_u16(&stored, DEPTH_SCALE_M),
        timestamp_s: frame.timestamp_s,
    })
}

/// Writes `frame`, taken with the pad at `arm_pose` (None: where the last move left it).
fn record_tactile_frame(
    log: &Mutex<Log>,
    frame: &TactileFrame,
    arm_pose: Option<Pose>,
) -> Result<(), DeviceError> {
    let mut log = lock(log);
    refuse_finished(&log)?;
    let n = log.tactile.as_ref().map_or(0, |t| t.frames.len());
    let image = format!("tactile/{n:04}.png");
    save_png::<_, Vec<u8>>(&frame.image, &log.partial.join(&image))?;
    let arm_pose = arm_pose.unwrap_or(log.arm_pose);
    if let Some(t) = log.tactile.as_mut() {
        t.frames.push(TactileFrameRecord {
            image,
            timestamp_s: frame.timestamp_s,
            arm_pose,
        });
    }
    Ok(())
}

fn record_move(log: &Mutex<Log>, record: MoveRecord) {
    let mut log = lock(log);
    log.arm_pose = record.reached;
    if let Some(a) = log.arm.as_mut() {
        a.moves.push(record);
    }
}

pub struct RecordingTactile<'a, T: TactileSensor> {
    inner: &'a mut T,
    log: Arc<Mutex<Log>>,
}

impl<T: TactileSensor> TactileSensor for RecordingTactile<'_, T> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn spec(&self) -> &TactileSpec {
        self.inner.spec()
    }
    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        let frame = self.inner.capture()?;
        record_tactile_frame(&self.log, &frame, None)?;
        Ok(frame)
    }
}

pub struct RecordingArm<'a, A: Arm> {
    inner: &'a mut A,
    log: Arc<Mutex<Log>>,
}

impl<A: Arm> Arm for RecordingArm<'_, A> {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn pose(&self) -> Result<Pose, DeviceError> {
        self.inner.pose()
    }
    fn move_linear(&mut self, target: &Pose, speed_m_s: f64) -> Result<(), DeviceError> {
        let result = self.inner.move_linear(target, speed_m_s);
        let reached = self.inner.pose()?;
        record_move(
            &self.log,
            MoveRecord {
                target: *target,
                speed_m_s,
                reached,
                time_s: self.inner.sim_time_s(),
                error: result.as_ref().err().map(ToString::to_string),
            },
        );
        result
    }
    fn stop(&mut self) -> Result<(), DeviceError> {
        self.inner.stop()
    }
    fn sim_time_s(&self) -> Option<f64> {
        self.inner.sim_time_s()
    }
}
