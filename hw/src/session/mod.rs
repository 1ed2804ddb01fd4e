//! Recorded sessions: everything one question's devices delivered and were asked to do, in
//! one directory, so that the pipeline can run again from it (`replay`) on any machine.
//!
//! Layout (format "tactex-session/1"):
//!
//! ```text
//! DIR/manifest.json          what follows, the prompt, and the answer given while recording
//! DIR/camera/color-NNNN.png  8-bit RGB
//! DIR/camera/depth-NNNN.png  16-bit grey, depth = value x depth_scale_m (0: invalid)
//! DIR/tactile/NNNN.png       8-bit RGB GelSight frames, each with the arm pose and time
//! ```
//!
//! The manifest holds the camera's intrinsics and extrinsics (camera-to-world pose), the
//! tactile sensor's description, each frame's timestamp, and every arm move (target,
//! speed, the pose reached, the robot clock after it). A recording is written into
//! `DIR.partial` and renamed to `DIR` only when it finished, so a directory that exists is
//! whole. A session recorded on the twin also holds its scene and seed, from which
//! `tactex compare --session` rebuilds every press.

pub mod format;
pub mod presses;
pub mod record;
pub mod replay;

pub use format::{MANIFEST, Manifest, SessionError, TwinRecord};
pub use record::{RecordingArm, RecordingCamera, RecordingTactile, SessionRecorder};
pub use replay::{ReplayArm, ReplayCamera, ReplayTactile, open_session};
