//! Replay: devices that give back a recorded session's frames in the order they were
//! taken, and an arm that accepts exactly the recorded moves. A pipeline that asks for
//! anything else (another prompt, another detector) has diverged from the recording, and
//! the replay says so instead of inventing data.

use super::format::{
    ArmRecord, CameraRecord, FORMAT, MANIFEST, Manifest, SessionError, TactileRecord, partial_dir,
};
use super::record::depth_from_u16;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};
use tactex_core::devices::{Arm, DeviceError, RgbdCamera, TactileSensor};
use tactex_core::frames::{RgbdFrame, TactileFrame};
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::tactile::spec::TactileSpec;

/// How far a replayed move's target may lie from the recorded one: the depth stored in
/// 0.1 mm steps moves touch points by less than this.
const MOVE_TOLERANCE_M: f64 = 1e-3;

/// The manifest and the three replay devices of the session in `dir`.
pub fn open_session(
    dir: &Path,
) -> Result<(Manifest, ReplayCamera, ReplayTactile, ReplayArm), SessionError> {
    if !dir.is_dir() {
        let why = if partial_dir(dir).is_dir() {
            "no such session (a .partial recording beside it did not finish)"
        } else if dir.exists() {
            "not a folder; a session is the folder `ask --record` wrote"
        } else {
            "no such session directory"
        };
        return Err(SessionError::Missing {
            path: dir.to_path_buf(),
            message: why.into(),
        });
    }
    let path = dir.join(MANIFEST);
    let text =
        tactex_core::text_file::read_to_string(&path).map_err(|e| SessionError::file(&path, e))?;
    let manifest: Manifest = serde_json::from_str(&text).map_err(|e| {
        SessionError::file(&path, tactex_core::file_failure::json_failure(&text, &e))
    })?;
    let field = |field: &str, message: String| SessionError::Field {
        path: path.clone(),
        field: field.into(),
        message,
    };
    if manifest.format != FORMAT {
        return Err(field(
            "format",
            format!("'{}' is not {FORMAT}", manifest.format),
        ));
    }
    // Both are shown in reports: one printable line each.
    tactex_core::printable::check_name(&manifest.backend).map_err(|m| field("backend", m))?;
    if let Some(twin) = &manifest.twin
        && twin
            .scene_path
            .chars()
            .any(|c| c.is_control() || tactex_core::printable::is_hidden(c))
    {
        return Err(field(
            "twin.scene_path",
            format!(
                "'{}' holds control or hidden characters; it is shown in reports",
                tactex_core::printable::excerpt(&twin.scene_path, 60)
            ),
        ));
    }
    manifest
        .camera
        .intrinsics
        .check()
        .map_err(|m| field("camera.intrinsics", m))?;
    // A depth unit is a fraction of a metre (a RealSense's is 1 mm); one of 1e308 m puts
    // the table beyond any pose.
    let scale = manifest.camera.depth_scale_m;
    if !(scale.is_finite() && scale > 0.0 && scale <= 1.0) {
        return Err(field(
            "camera.depth_scale_m",
            format!(
                "{} must be a positive number of metres per depth unit, at most 1",
                tactex_core::printable::short_number(scale)
            ),
        ));
    }
    // The sensor as recorded is what the replay reads the frames through: a scale of zero
    // or a dot of 1e308 mm would size its blurs in gigabytes.
    manifest
        .tactile
        .spec
        .check()
        .map_err(|(f, m)| field(&format!("tactile.spec.{f}"), m))?;
    check_poses(&manifest).map_err(|(f, m)| field(&f, m))?;
    if let Some(sensor) = manifest.twin.as_ref().and_then(|t| t.sensor.as_ref()) {
        sensor
            .check()
            .map_err(|(f, m)| field(&format!("twin.sensor.{f}"), m))?;
    }
    let k = &manifest.camera.intrinsics;
    let spec = &manifest.tactile.spec;
    // Every frame with the size and kind its device gives: (file, size, what says so, kind).
    let files = manifest
        .camera
        .frames
        .iter()
        .flat_map(|f| [(&f.color, FrameKind::Colour), (&f.depth, FrameKind::Depth)])
        .map(|(file, kind)| (file, (k.width, k.height), "the intrinsics say", kind))
        .chain(manifest.tactile.frames.iter().map(|f| {
            (
                &f.image,
                (spec.width_px, spec.height_px),
                "the sensor gives",
                FrameKind::Colour,
            )
        }));
    let listed = manifest.camera.frames.len() + manifest.tactile.frames.len();
    if listed > MAX_SESSION_FRAMES {
        return Err(field(
            "frames",
            format!(
                "{listed} frames listed; a session holds at most {MAX_SESSION_FRAMES} (a whole \
                 question is a few hundred)"
            ),
        ));
    }
    let inside = dir.canonicalize().map_err(|e| SessionError::file(dir, e))?;
    // A file listed again as the same kind of frame is checked once.
    let mut checked = std::collections::HashSet::new();
    for (file, size, says, kind) in files {
        if !checked.insert((file, kind)) {
            continue;
        }
        let p = dir.join(file);
        let outside = Path::new(file).is_absolute()
            || Path::new(file)
                .components()
                .any(|c| matches!(c, std::path::Component::ParentDir));
        if outside {
            // A session is one folder: a recording never points out of it, so a path that
            // does is refused whatever it names, and the file is not looked at.
            return Err(SessionError::Field {
                path: path.clone(),
                field: "frames".into(),
                message: format!(
                    "'{}' lies outside the session folder; a session's files are named relative to it, without '..'",
                    tactex_core::printable::printable(file)
                ),
            });
        }
        // Only a name with nothing behind it is missing: a link looping or leading nowhere
        // is named as such by `regular` below.
        if std::fs::symlink_metadata(&p).is_err() {
            return Err(SessionError::file(&p, "listed in the manifest but missing"));
        }
        tactex_core::text_file::regular(&p).map_err(|e| SessionError::file(&p, e))?;
        if p.is_dir() {
            return Err(SessionError::file(
                &p,
                "a folder, where the manifest lists a frame",
            ));
        }
        // A link inside the folder can still lead out of it.
        if !p.canonicalize().is_ok_and(|c| c.starts_with(&inside)) {
            return Err(SessionError::file(
                &p,
                "a link leading out of the session folder; a session's frames lie in it",
            ));
        }
        // Decoded before the replay starts: a frame found bad halfway would end that press
        // and show as the arm diverging from the recording, not as the frame it is.
        let image = tactex_core::image_file::open(&p)
            .map_err(|e| SessionError::file(&p, format!("not a readable frame: {e}")))?;
        let found = (image.width(), image.height());
        if found != size {
            return Err(SessionError::file(
                &p,
                format!("{}x{} px, {says} {}x{}", found.0, found.1, size.0, size.1),
            ));
        }
        if let Some(why) = kind.fault(&image) {
            return Err(SessionError::file(&p, why));
        }
    }
    let name = |device: &str| format!("replay {device} ({})", dir.display());
    let clock = RobotClock {
        now_s: Arc::new(Mutex::new(manifest.arm.start_time_s)),
        running: manifest.arm.start_time_s.is_some(),
    };
    Ok((
        manifest.clone(),
        ReplayCamera {
            name: name("camera"),
            dir: dir.to_path_buf(),
            record: manifest.camera,
            next: 0,
            clock: clock.clone(),
        },
        ReplayTactile {
            name: name("tactile"),
            dir: dir.to_path_buf(),
            record: manifest.tactile,
            next: 0,
            clock: clock.clone(),
        },
        ReplayArm {
            name: name("arm"),
            pose: manifest.arm.start_pose,
            record: manifest.arm,
            next: 0,
            clock,
        },
    ))
}

/// What a recorded frame file holds: the recorder writes colour as 8-bit RGB and depth as
/// one 16-bit channel.
#[derive(Clone, Copy, PartialEq, Eq, Hash)]
enum FrameKind {
    Colour,
    Depth,
}

impl FrameKind {
    /// Why `image` cannot be a frame of this kind, if it cannot: replayed, a greyscale image
    /// would be read as colour and a colour image as depth, without a word.
    fn fault(self, image: &tactex_core::image::DynamicImage) -> Option<String> {
        let colour = image.color();
        match self {
            FrameKind::Colour if !colour.has_color() => {
                Some("a greyscale image, where the recording holds a colour frame".into())
            }
            // Alpha would be dropped and 16-bit levels cut to 8 without a word.
            FrameKind::Colour if colour != tactex_core::image::ColorType::Rgb8 => Some(format!(
                "a {colour:?} image, where the recording holds a colour frame: 8-bit RGB"
            )),
            FrameKind::Depth if colour.has_color() || colour.bytes_per_pixel() != 2 => {
                Some(format!(
                    "a {colour:?} image, where the recording holds a depth frame: one 16-bit channel"
                ))
            }
            _ => None,
        }
    }
}

/// Every pose in the recording (the camera, the arm's start, each move and frame) finite with
/// a unit rotation; Err names the first that is not.
fn check_poses(manifest: &Manifest) -> Result<(), (String, String)> {
    let poses = [
        ("camera.pose".to_string(), &manifest.camera.pose),
        ("arm.start_pose".to_string(), &manifest.arm.start_pose),
    ]
    .into_iter()
    .chain(manifest.arm.moves.iter().enumerate().flat_map(|(i, m)| {
        [
            (format!("arm.moves[{i}].target"), &m.target),
            (format!("arm.moves[{i}].reached"), &m.reached),
        ]
    }))
    .chain(
        manifest
            .tactile
            .frames
            .iter()
            .enumerate()
            .map(|(i, f)| (format!("tactile.frames[{i}].arm_pose"), &f.arm_pose)),
    );
    for (field, pose) in poses {
        pose.check().map_err(|m| (field.clone(), m))?;
        if pose.position.length() > MAX_PLACE_M {
            return Err((
                field,
                format!(
                    "position {} is more than {MAX_PLACE_M} m from the world's origin; a \
                     session's poses lie in one workcell",
                    tactex_core::printable::short_numbers(&pose.position.to_array())
                ),
            ));
        }
    }
    let times = [("arm.start_time_s".to_string(), manifest.arm.start_time_s)]
        .into_iter()
        .chain(
            manifest
                .arm
                .moves
                .iter()
                .enumerate()
                .map(|(i, m)| (format!("arm.moves[{i}].time_s"), m.time_s)),
        );
    // The pipeline asks every move at a positive speed; another was edited in, and would
    // only show later as the replay diverging from the recording.
    for (i, m) in manifest.arm.moves.iter().enumerate() {
        if !(m.speed_m_s.is_finite() && m.speed_m_s > 0.0) {
            return Err((
                format!("arm.moves[{i}].speed_m_s"),
                format!(
                    "{} is not a speed a move is asked at (m/s, positive)",
                    tactex_core::printable::short_number(m.speed_m_s)
                ),
            ));
        }
    }
    // A device's frames are listed in the order taken.
    let stamps = [
        (
            "camera.frames",
            manifest
                .camera
                .frames
                .iter()
                .map(|f| f.timestamp_s)
                .collect::<Vec<f64>>(),
        ),
        (
            "tactile.frames",
            manifest
                .tactile
                .frames
                .iter()
                .map(|f| f.timestamp_s)
                .collect(),
        ),
    ];
    for (list, stamps) in stamps {
        for (i, t) in stamps.iter().enumerate() {
            let field = format!("{list}[{i}].timestamp_s");
            if !(t.is_finite() && t.abs() <= MAX_CLOCK_S) {
                return Err((
                    field,
                    format!(
                        "{} is not a frame's time (seconds within 1e10)",
                        tactex_core::printable::short_number(*t)
                    ),
                ));
            }
            if i > 0 && *t < stamps[i - 1] {
                return Err((
                    field,
                    format!(
                        "{} is before the frame listed before it ({}); frames are listed in the order taken",
                        tactex_core::printable::short_number(*t),
                        tactex_core::printable::short_number(stamps[i - 1])
                    ),
                ));
            }
        }
    }
    for (field, time) in times {
        if let Some(t) = time.filter(|t| !(t.is_finite() && t.abs() <= MAX_CLOCK_S)) {
            return Err((
                field,
                format!(
                    "{} is not a robot clock's time (seconds within 1e10)",
                    tactex_core::printable::short_number(t)
                ),
            ));
        }
    }
    Ok(())
}

/// The most frames a session may list: a question's few hundred, many times over.
const MAX_SESSION_FRAMES: usize = 100_000;

/// How far from the world's origin a recorded pose may lie: a workcell, generously.
const MAX_PLACE_M: f64 = 100.0;
/// The furthest a recorded robot clock may read (s): an epoch clock's 1.7e9 fits.
const MAX_CLOCK_S: f64 = 1e10;

/// The recorded robot clock, where the recorded backend had one of its own (the twin's
/// simulated time): it stands at the time of the last frame or move given back, so a
/// replay reports the recording's robot time per stage.
#[derive(Clone)]
struct RobotClock {
    now_s: Arc<Mutex<Option<f64>>>,
    running: bool,
}

impl RobotClock {
    fn set(&self, t: Option<f64>) {
        if self.running {
            *self.now_s.lock().unwrap_or_else(|e| e.into_inner()) = t;
        }
    }
    fn now(&self) -> Option<f64> {
        *self.now_s.lock().unwrap_or_else(|e| e.into_inner())
    }
}

fn failure(device: &str, message: impl Into<String>) -> DeviceError {
    DeviceError::Failure {
        device: device.into(),
        message: message.into(),
    }
}

fn exhausted(device: &str, what: &str, n: usize) -> DeviceError {
    failure(
        device,
        format!(
            "the recording has {n} {what}; the pipeline asked for more, so this run diverged \
             from the recorded one (another prompt or detector?)"
        ),
    )
}

pub struct ReplayCamera {
    name: String,
    dir: PathBuf,
    record: CameraRecord,
    next: usize,
    clock: RobotClock,
}

impl RgbdCamera for ReplayCamera {
    fn name(&self) -> &str {
        &self.name
    }
    fn intrinsics(&self) -> CameraIntrinsics {
        self.record.intrinsics
    }
    fn pose(&self) -> Pose {
        self.record.pose
    }
    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        let Some(f) = self.record.frames.get(self.next) else {
            return Err(exhausted(
                &self.name,
                "RGB-D frames",
                self.record.frames.len(),
            ));
        };
        self.next += 1;
        let read = |file: &str| {
            let path = self.dir.join(file);
            tactex_core::image_file::open(&path)
                .map_err(|e| failure(&self.name, format!("{}: {e}", path.display())))
        };
        // Their sizes were checked against the intrinsics when the session was opened.
        let color = read(&f.color)?.to_rgb8();
        let depth = read(&f.depth)?.to_luma16();
        self.clock.set(Some(f.timestamp_s));
        Ok(RgbdFrame {
            color,
            depth_m: depth_from_u16(&depth, self.record.depth_scale_m),
            timestamp_s: f.timestamp_s,
        })
    }
}

pub struct ReplayTactile {
    name: String,
    dir: PathBuf,
    record: TactileRecord,
    next: usize,
    clock: RobotClock,
}

impl TactileSensor for ReplayTactile {
    fn name(&self) -> &str {
        &self.name
    }
    fn spec(&self) -> &TactileSpec {
        &self.record.spec
    }
    fn capture(&mut self) -> Result<TactileFrame, DeviceError> {
        let Some(f) = self.record.frames.get(self.next) else {
            return Err(exhausted(
                &self.name,
                "tactile frames",
                self.record.frames.len(),
            ));
        };
        self.next += 1;
        let path = self.dir.join(&f.image);
        let image = tactex_core::image_file::open(&path)
            .map_err(|e| failure(&self.name, format!("{}: {e}", path.display())))?
            .to_rgb8();
        // Its size was checked against the sensor when the session was opened.
        self.clock.set(Some(f.timestamp_s));
        Ok(TactileFrame {
            image,
            timestamp_s: f.timestamp_s,
        })
    }
}

pub struct ReplayArm {
    name: String,
    record: ArmRecord,
    next: usize,
    pose: Pose,
    clock: RobotClock,
}

impl Arm for ReplayArm {
    fn name(&self) -> &str {
        &self.name
    }
    fn pose(&self) -> Result<Pose, DeviceError> {
        Ok(self.pose)
    }
    fn move_linear(&mut self, target: &Pose, speed_m_s: f64) -> Result<(), DeviceError> {
        let n = self.next;
        let Some(m) = self.record.moves.get(n) else {
            return Err(exhausted(&self.name, "moves", self.record.moves.len()));
        };
        let off = (m.target.position - target.position).length();
        let turned = m.target.rotation.angle_between(target.rotation);
        if off > MOVE_TOLERANCE_M || turned > 1e-3 {
            let p = |v: tactex_core::glam::DVec3| format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z);
            // Name what differs: two equal positions say nothing of a turned tool.
            let differs = if off > MOVE_TOLERANCE_M {
                format!(
                    "was recorded to {} m but is asked to {} m",
                    p(m.target.position),
                    p(target.position)
                )
            } else {
                format!(
                    "to {} m was recorded with the tool turned {:.3} degrees from the one asked",
                    p(target.position),
                    turned.to_degrees()
                )
            };
            return Err(failure(
                &self.name,
                format!("move {n} {differs}: this run diverged from the recorded one"),
            ));
        }
        if (m.speed_m_s - speed_m_s).abs() > 1e-9 * m.speed_m_s.abs().max(1.0) {
            return Err(failure(
                &self.name,
                format!(
                    "move {n} was recorded at {} m/s but is asked at {speed_m_s} m/s",
                    m.speed_m_s
                ),
            ));
        }
        self.next += 1;
        self.pose = m.reached;
        self.clock.set(m.time_s);
        match &m.error {
            // The recorded device refused or failed this move; the replay does the same.
            // Shown as one short line whatever the file holds.
            Some(e) => Err(failure(
                &self.name,
                format!("recorded: {}", tactex_core::printable::excerpt(e, 200)),
            )),
            None => Ok(()),
        }
    }
    fn stop(&mut self) -> Result<(), DeviceError> {
        Ok(())
    }
    fn sim_time_s(&self) -> Option<f64> {
        self.clock.now()
    }
}
