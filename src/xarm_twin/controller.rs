//! The xArm 850 controller the twin plays: the registers the vendor's Python SDK uses to
//! connect, enable, set mode and state, read and clear errors, read the TCP pose and move,
//! answered over the twin's world. A linear move is checked as a real controller checks it
//! (the safety boundary round the table, the table itself, the crush limit of whatever the
//! pad presses) and then run by the sim arm in the twin's clock; the controller reports it
//! moving for the move's duration in wall time, divided by the time scale.

use super::arm_joints;
use glam::{DQuat, DVec3, EulerRot};
use std::collections::VecDeque;
use std::sync::Arc;
use std::time::{Duration, Instant};
use tactex_core::devices::{Arm, DeviceError};
use tactex_core::geometry::Pose;
use tactex_hw::session::SessionRecorder;
use tactex_hw::session::format::MoveRecord;
use tactex_hw::xarm::frame::{f32_params, f32_values, status};
use tactex_sim::devices::arm::SimArm;
use tactex_sim::world::SharedWorld;

mod joint_moves;

/// The controller's registers the twin answers (`XCONF.UxbusReg` in the SDK).
pub mod reg {
    pub const GET_VERSION: u8 = 1;
    pub const GET_ROBOT_SN: u8 = 2;
    pub const MOTION_EN: u8 = 11;
    pub const SET_STATE: u8 = 12;
    pub const GET_STATE: u8 = 13;
    pub const GET_CMDNUM: u8 = 14;
    pub const GET_ERROR: u8 = 15;
    pub const CLEAN_ERR: u8 = 16;
    pub const CLEAN_WAR: u8 = 17;
    pub const SET_MODE: u8 = 19;
    pub const MOVE_LINE: u8 = 21;
    pub const MOVE_JOINT: u8 = 23;
    pub const MOVE_HOME: u8 = 25;
    pub const MOVE_SERVOJ: u8 = 29;
    pub const MOVE_SERVO_CART: u8 = 30;
    pub const SET_TCP_JERK: u8 = 31;
    pub const SET_TCP_MAXACC: u8 = 32;
    pub const GET_TCP_POSE: u8 = 41;
    pub const GET_JOINT_POS: u8 = 42;
    pub const GET_IK: u8 = 43;
    pub const GET_FK: u8 = 44;
    pub const GET_REDUCED_MODE: u8 = 49;
    pub const GET_JOINT_TAU: u8 = 55;
    pub const GET_TCP_POSE_AA: u8 = 91;
    pub const MOVE_RELATIVE: u8 = 83;
}

/// The controller's modes (`set_mode`): planned moves run in position mode only, servo
/// targets in servo mode only; a command for another mode is not executed (uFactory's
/// manual), and the twin says so on stderr and in `/state`.
pub mod mode {
    pub const POSITION: u8 = 0;
    pub const SERVO: u8 = 1;
    /// The highest mode uFactory's manual lists (7, Cartesian online trajectory planning).
    pub const LAST: u8 = 7;
}

/// A servo target further than this from the pad is not executed (uFactory's servo mode
/// guide: steps of at most 10 mm).
pub const SERVO_STEP_MAX_MM: f64 = 10.0;
/// A move slower than this that would last longer than `SLOW_MOVE_S` is noted.
const SLOW_SPEED_MM_S: f64 = 1.0;
/// The controller's slowest TCP speed (mm/s): a slower request runs at it, as the SDK sends.
const MIN_SPEED_MM_S: f64 = 0.1;
const SLOW_MOVE_S: f64 = 30.0;
/// The most a joint target may tilt the pad from straight down (degrees): the twin's contact
/// and frames are of a pad parallel to the table.
pub const MAX_TILT_DEG: f64 = 1.0;
/// Servo targets run at the TCP's top speed.
pub const SERVO_SPEED_MM_S: f64 = 1000.0;
/// The pad turns at most this fast in a Cartesian move (rad/s): the joints' top speed.
const MAX_TURN_RAD_S: f64 = std::f64::consts::PI;

/// Controller error codes the twin raises (`x_code.py`; `tactex_hw::xarm::codes`).
pub mod error_code {
    /// Collision caused abnormal current: the pad driven into the table or an object past
    /// the crush limit.
    pub const COLLISION: u8 = 31;
    /// Safety boundary limit: a target outside the box over the table.
    pub const SAFETY_BOUNDARY: u8 = 35;
}

/// Warning codes.
pub mod warn_code {
    /// A command parameter is out of range (a non-finite pose, a speed of zero).
    pub const PARAMETER: u8 = 12;
    /// The command has no solution: a Cartesian target of a joint move the arm cannot reach.
    pub const NO_SOLUTION: u8 = 14;
}

/// Motion states of the report and `get_state`.
pub mod motion {
    pub const MOVING: u8 = 1;
    pub const READY: u8 = 2;
    pub const PAUSED: u8 = 3;
    pub const STOPPED: u8 = 4;
}

/// How the arm stands on the table and what it reports about itself.
#[derive(Clone, Debug)]
pub struct ArmMount {
    /// The robot base's origin in the table frame (m); its axes are the table's.
    pub base_m: DVec3,
    /// The controller's version string (`get_version`): axis, type, serial numbers, firmware.
    pub version: String,
    pub robot_sn: String,
    /// Wall time a move takes is its twin-clock duration divided by this.
    pub time_scale: f64,
}

impl ArmMount {
    /// The firmware part of the version string (its last field, e.g. "v2.0.0").
    pub fn firmware(&self) -> &str {
        self.version.rsplit(',').next().unwrap_or("")
    }
}

impl Default for ArmMount {
    fn default() -> Self {
        Self {
            base_m: DVec3::new(-0.45, 0.0, 0.0),
            // An xArm 850 (6 axes, type 12), firmware 2.0.0: the SDK polls get_state to wait
            // for moves (feedback frames start at 2.0.102) and takes the 1300-series layout.
            version: "6,12,XF1300TWIN001,AC1300TWIN001,v2.0.0".into(),
            robot_sn: "XF1300TWIN001".into(),
            time_scale: 1.0,
        }
    }
}

/// The SDK's TCP pose: x, y, z in mm in the base frame; roll, pitch, yaw in radians.
pub type TcpPoseMm = [f64; 6];

/// The pose `move_gohome` goes to: the pad pointing down 300 mm in front of and above the
/// base.
pub const HOME: TcpPoseMm = [300.0, 0.0, 300.0, std::f64::consts::PI, 0.0, 0.0];

/// A move accepted: from where, to where, starting when and for how long (wall clock).
#[derive(Clone, Copy, Debug)]
struct Moving {
    from: TcpPoseMm,
    to: TcpPoseMm,
    /// The joints at the move's ends where it runs along the joint path (a joint move's
    /// line); None where the joints are read from the pose.
    joints: Option<([f64; 6], [f64; 6])>,
    started: Instant,
    duration: Duration,
}

/// A part of a joint move's path: the joints at its ends and how long it takes (twin s).
#[derive(Clone, Copy, Debug)]
struct JointSegment {
    from: [f64; 6],
    to: [f64; 6],
    seconds: f64,
}

/// What the report and the control port read of the controller.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub state: u8,
    pub mode: u8,
    pub cmd_num: u16,
    pub pose: TcpPoseMm,
    /// The UF850's joints that hold the pad at `pose` (rad).
    pub joints: [f64; 6],
    pub enabled: bool,
    pub error: u8,
    pub warning: u8,
    pub tcp_speed_mm_s: f64,
}

pub struct Controller {
    arm: SimArm,
    world: SharedWorld,
    mount: ArmMount,
    enabled: bool,
    mode: u8,
    state: u8,
    error: u8,
    warning: u8,
    /// Where the pad is (SDK pose) when no move runs.
    pose: TcpPoseMm,
    /// The UF850's joints last read for the pad's pose (rad): the branch the arm is on.
    joints: [f64; 6],
    /// Moves accepted and not yet ended, in order: the controller's command queue.
    queue: VecDeque<Moving>,
    last_speed_mm_s: f64,
    /// Why the last fault was raised or the last command not executed, for `/state`.
    pub last_notice: Option<String>,
    /// Notices not yet written to the twin's log.
    unlogged: Vec<String>,
    /// The session the moves are written into (`tactex twin --record`).
    recorder: Option<Arc<SessionRecorder>>,
}

/// Where a move goes, as the request gives it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MoveTarget {
    /// A pose in the base frame.
    Base(TcpPoseMm),
    /// An offset in the pad's own frame from where the last move ends (`set_tool_position`).
    Tool(TcpPoseMm),
    /// An offset added in the base frame to where the last move ends (`set_position(...,
    /// relative=True)`): position and roll, pitch, yaw each added.
    Relative(TcpPoseMm),
}

/// Reply to one request: the parameter bytes, or the request was invalid.
pub enum Answer {
    Params(Vec<u8>),
    Invalid,
    /// Refused with the reply's full length (the SDK reads it before it looks at the
    /// status, and raises on a short one): an inverse kinematics with no solution.
    Refused(Vec<u8>),
}

impl Controller {
    /// A controller over `world`, the pad parked at HOME (the world's tool moved there).
    pub fn new(world: SharedWorld, arm: SimArm, mount: ArmMount) -> Result<Self, String> {
        let home = world_pose(&mount, &HOME);
        world.lock().map_err(|_| "world lock poisoned")?.tool = home;
        Ok(Self {
            arm,
            world,
            mount,
            enabled: false,
            mode: 0,
            state: motion::STOPPED,
            error: 0,
            warning: 0,
            pose: HOME,
            joints: arm_joints::HOME_SEED,
            queue: VecDeque::new(),
            last_speed_mm_s: 0.0,
            last_notice: None,
            unlogged: Vec::new(),
            recorder: None,
        })
    }

    /// Writes every move asked for, and how it ended, into `recorder`'s session.
    pub fn record_into(&mut self, recorder: Arc<SessionRecorder>) {
        self.recorder = Some(recorder);
    }

    pub fn mount(&self) -> &ArmMount {
        &self.mount
    }

    /// Ends the moves whose time is up.
    fn advance(&mut self, now: Instant) {
        while let Some(m) = self.queue.front()
            && now >= m.started + m.duration
        {
            self.pose = m.to;
            if let Some((_, to)) = m.joints {
                self.joints = to;
            }
            self.queue.pop_front();
        }
        if self.queue.is_empty() && self.state == motion::MOVING {
            self.state = motion::READY;
        }
    }

    pub fn snapshot(&mut self, now: Instant) -> Snapshot {
        self.advance(now);
        let (pose, speed, joints) = match self.queue.front().copied() {
            Some(m) if now >= m.started => {
                let t = (now - m.started).as_secs_f64() / m.duration.as_secs_f64().max(1e-9);
                let t = t.clamp(0.0, 1.0);
                match m.joints {
                    // Along the joint path the joints are known, and the pose is theirs.
                    Some((a, b)) => {
                        let q = std::array::from_fn(|i| a[i] + t * (b[i] - a[i]));
                        self.joints = q;
                        (arm_joints::pose_at(q), self.last_speed_mm_s, q)
                    }
                    None => {
                        let pose = lerp(&m.from, &m.to, t);
                        (pose, self.last_speed_mm_s, self.joints_at(&pose))
                    }
                }
            }
            _ => {
                let pose = self.pose;
                (pose, 0.0, self.joints_at(&pose))
            }
        };
        Snapshot {
            state: self.state,
            mode: self.mode,
            cmd_num: self.queue.len().min(usize::from(u16::MAX)) as u16,
            pose,
            joints,
            enabled: self.enabled,
            error: self.error,
            warning: self.warning,
            tcp_speed_mm_s: speed,
        }
    }

    /// The reply's status byte (`check_private_protocol` in the SDK).
    pub fn status_bits(&self) -> u8 {
        let mut bits = 0;
        if self.error != 0 {
            bits |= status::ERROR;
        }
        if self.warning != 0 {
            bits |= status::WARNING;
        }
        if !self.enabled || self.state >= motion::STOPPED {
            bits |= status::NOT_READY;
        }
        bits
    }

    /// Raises controller error `code`: the arm stops where it is, not enabled for motion.
    pub fn fault(&mut self, code: u8, why: String, now: Instant) {
        self.halt(now);
        self.error = code;
        self.state = motion::STOPPED;
        self.notice(format!("error {code}: {why}"));
    }

    fn notice(&mut self, text: String) {
        self.unlogged.push(text.clone());
        self.last_notice = Some(text);
    }

    /// The notices since the last call, for the twin's log.
    pub fn take_notices(&mut self) -> Vec<String> {
        std::mem::take(&mut self.unlogged)
    }

    /// Puts the world's pad where the controller's clock has it now: the sensors image the
    /// pad mid-move, not at the move's end.
    pub fn place_pad_now(&mut self, now: Instant) -> Pose {
        let here = self.snapshot(now).pose;
        self.place_pad(&here);
        world_pose(&self.mount, &here)
    }

    fn place_pad(&self, pose: &TcpPoseMm) {
        if let Ok(mut w) = self.world.lock() {
            w.tool = world_pose(&self.mount, pose);
        }
    }

    /// Where the pad will be once the queued moves end: where the next move starts.
    fn planned_pose(&self) -> TcpPoseMm {
        self.queue.back().map_or(self.pose, |m| m.to)
    }

    /// Stops a running move where the pad is now and drops the queued ones; the world's
    /// tool goes back there along the path it was checked on.
    fn halt(&mut self, now: Instant) {
        let here = self.snapshot(now).pose;
        if !self.queue.is_empty() {
            self.queue.clear();
            self.pose = here;
            self.place_pad(&here);
        }
    }

    /// Answers register `register` with `params`; None for a register the twin does not
    /// speak (the caller answers it invalid and sets warning 13).
    pub fn handle(&mut self, register: u8, params: &[u8], now: Instant) -> Option<Answer> {
        self.advance(now);
        let u8s = |n: usize| (params.len() == n).then_some(params);
        Some(match register {
            reg::GET_VERSION => Answer::Params(padded(&self.mount.version, 40)),
            reg::GET_ROBOT_SN => Answer::Params(padded(&self.mount.robot_sn, 40)),
            reg::MOTION_EN => match u8s(2) {
                Some(p) => {
                    self.enabled = p[1] != 0;
                    if !self.enabled {
                        self.halt(now);
                        self.state = motion::STOPPED;
                    }
                    Answer::Params(vec![])
                }
                None => Answer::Invalid,
            },
            reg::SET_STATE => match u8s(1) {
                Some(p) => {
                    match p[0] {
                        0 if self.enabled && self.error == 0 && self.state != motion::MOVING => {
                            self.state = if self.queue.is_empty() {
                                motion::READY
                            } else {
                                motion::MOVING
                            };
                        }
                        motion::PAUSED | motion::STOPPED => {
                            self.halt(now);
                            self.state = p[0];
                        }
                        _ => {}
                    }
                    Answer::Params(vec![])
                }
                None => Answer::Invalid,
            },
            reg::GET_STATE => Answer::Params(vec![self.snapshot(now).state]),
            reg::GET_CMDNUM => Answer::Params(self.snapshot(now).cmd_num.to_be_bytes().to_vec()),
            reg::GET_ERROR => Answer::Params(vec![self.error, self.warning]),
            // The notice of what was cleared goes with it.
            reg::CLEAN_ERR => {
                self.error = 0;
                self.last_notice = None;
                Answer::Params(vec![])
            }
            reg::CLEAN_WAR => {
                self.warning = 0;
                self.last_notice = None;
                Answer::Params(vec![])
            }
            reg::SET_MODE => match params.len() {
                1 | 2 if params[0] <= mode::LAST => {
                    self.mode = params[0];
                    Answer::Params(vec![])
                }
                1 | 2 => {
                    self.warning = warn_code::PARAMETER;
                    self.notice(format!(
                        "set_mode({}) was not executed: the controller's modes are 0-{} (0 position, 1 servo, 2 joint teaching, 4-7 velocity and online modes); the mode stays {}",
                        params[0],
                        mode::LAST,
                        self.mode
                    ));
                    Answer::Params(vec![])
                }
                _ => Answer::Invalid,
            },
            reg::SET_TCP_JERK | reg::SET_TCP_MAXACC => match params.len() {
                4 => Answer::Params(vec![]),
                _ => Answer::Invalid,
            },
            reg::GET_TCP_POSE => Answer::Params(f32_params(&self.snapshot(now).pose)),
            reg::GET_JOINT_POS => match params {
                [] | [1] => Answer::Params(arm_joints::params(&self.snapshot(now).joints)),
                // `get_joint_states`: velocities and efforts too, which the twin does not
                // model; refused at the reply's full length so the SDK answers a code.
                [n] => Answer::Refused(vec![0; 28 * usize::from(n & 0x0f)]),
                _ => Answer::Invalid,
            },
            reg::GET_FK => match params.len() {
                28 => {
                    let q = f32_values(params);
                    let q = [q[0], q[1], q[2], q[3], q[4], q[5]];
                    match q.iter().all(|v| v.is_finite()) {
                        true => Answer::Params(f32_params(&arm_joints::pose_at(q))),
                        false => Answer::Refused(vec![0; 24]),
                    }
                }
                _ => Answer::Invalid,
            },
            // The pose with its orientation as an axis-angle vector (rad).
            reg::GET_TCP_POSE_AA => {
                let p = self.snapshot(now).pose;
                let (axis, angle) =
                    DQuat::from_euler(EulerRot::ZYX, p[5], p[4], p[3]).to_axis_angle();
                let r = axis * angle;
                Answer::Params(f32_params(&[p[0], p[1], p[2], r.x, r.y, r.z]))
            }
            // No reduced mode on the twin.
            reg::GET_REDUCED_MODE => Answer::Params(vec![0]),
            // Joint torques are not modelled: refused at the reply's full length.
            reg::GET_JOINT_TAU => Answer::Refused(vec![0; 28]),
            reg::GET_IK => match arm_joints::ik_params(params) {
                Some((target, reference)) => {
                    let from = reference.unwrap_or(self.joints);
                    match arm_joints::joints_for(&target, from) {
                        Ok(q) => Answer::Params(arm_joints::params(&q)),
                        Err(_) => Answer::Refused(arm_joints::params(&[0.0; 6])),
                    }
                }
                None => Answer::Invalid,
            },
            reg::MOVE_LINE => match move_line_params(params) {
                Some((target, speed_mm_s, JOINT_MOTION)) => {
                    self.snapshot(now);
                    self.joint_move_to_pose(target, speed_mm_s, now);
                    Answer::Params(vec![])
                }
                // Motion type 1 runs a line where the line can be run, which over a table
                // it can: the twin refuses the line's failures as a line's.
                Some((target, speed_mm_s, _)) => {
                    self.planned_move(target, speed_mm_s, now);
                    Answer::Params(vec![])
                }
                None => Answer::Invalid,
            },
            reg::MOVE_RELATIVE => match move_relative_params(params) {
                Some(RelativeMove::Cartesian(offset, speed_mm_s, JOINT_MOTION)) => {
                    self.snapshot(now);
                    self.joint_move_to_pose(MoveTarget::Relative(offset), speed_mm_s, now);
                    Answer::Params(vec![])
                }
                Some(RelativeMove::Cartesian(offset, speed_mm_s, _)) => {
                    self.planned_move(MoveTarget::Relative(offset), speed_mm_s, now);
                    Answer::Params(vec![])
                }
                Some(RelativeMove::Joints(offsets, speed_rad_s)) => {
                    self.snapshot(now);
                    self.relative_joint_move(offsets, speed_rad_s, now);
                    Answer::Params(vec![])
                }
                None => Answer::Invalid,
            },
            reg::MOVE_JOINT => match params.len() {
                40 | 41 => {
                    let v = f32_values(&params[..40]);
                    // A check-only request (the SDK's only_check_type) is not spoken, as
                    // for MOVE_LINE.
                    if params.get(40).is_some_and(|&check| check != 0) {
                        return Some(Answer::Invalid);
                    }
                    self.snapshot(now);
                    self.joint_move([v[0], v[1], v[2], v[3], v[4], v[5]], v[7], now);
                    Answer::Params(vec![])
                }
                _ => Answer::Invalid,
            },
            // Seven joints, speed, acceleration and time: the target runs at once.
            reg::MOVE_SERVOJ => match params.len() {
                40 => {
                    let v = f32_values(params);
                    self.snapshot(now);
                    self.servo_joints([v[0], v[1], v[2], v[3], v[4], v[5]], now);
                    Answer::Params(vec![])
                }
                _ => Answer::Invalid,
            },
            reg::MOVE_HOME => match params.len() {
                12 | 13 => {
                    // Speed in rad/s of the joints: a Cartesian twin moves home at 100 mm/s
                    // per 0.35 rad/s (the SDK's default joint speed).
                    let v = f32_values(&params[..12]);
                    let speed = (v[0] / 0.35 * 100.0).clamp(1.0, 1000.0);
                    self.planned_move(MoveTarget::Base(HOME), speed, now);
                    Answer::Params(vec![])
                }
                _ => Answer::Invalid,
            },
            // Pose, speed and acceleration (not used: servo targets run at top speed), and
            // where the SDK puts its time the tool-frame flag.
            reg::MOVE_SERVO_CART => match params.len() {
                36 => {
                    let v = f32_values(params);
                    let pose = [v[0], v[1], v[2], v[3], v[4], v[5]];
                    let target = if v[8] >= 0.5 {
                        MoveTarget::Tool(pose)
                    } else {
                        MoveTarget::Base(pose)
                    };
                    self.servo_to(target, now);
                    Answer::Params(vec![])
                }
                _ => Answer::Invalid,
            },
            _ => return None,
        })
    }

    /// The joints that hold the pad at `pose`: those nearest to the last ones read (the
    /// branch the arm is on); where the chain cannot reach the pose (the twin moves the pad
    /// in Cartesian space and may take it past the arm's reach), the last joints.
    fn joints_at(&mut self, pose: &TcpPoseMm) -> [f64; 6] {
        if arm_joints::hold(self.joints, pose) {
            return self.joints;
        }
        if let Ok(q) = arm_joints::joints_for(pose, self.joints) {
            self.joints = q;
        }
        self.joints
    }

    /// Whether `what` can run now: the arm ready to move and in `wanted` mode (planned moves
    /// in position mode, servo targets in servo mode, as uFactory's manual says); else the
    /// notice says why it was not executed (the status byte says so for a stopped or
    /// faulted arm, not for a paused one or one in another mode).
    fn runs_in(&mut self, what: &str, wanted: u8) -> bool {
        let why = match (self.enabled, self.error, self.state, self.mode) {
            (false, ..) => "motion is not enabled (motion_enable(True))".to_string(),
            (_, e, ..) if e != 0 => format!("error {e} is raised (clean_error())"),
            (_, _, motion::PAUSED, _) => "the arm is paused (state 3: set_state(0))".to_string(),
            (_, _, s, _) if !matches!(s, motion::MOVING | motion::READY) => {
                format!("the arm is in state {s} (set_state(0))")
            }
            (.., m) if m != wanted => {
                let runs = match wanted {
                    mode::SERVO => "servo targets",
                    _ => "planned moves",
                };
                format!(
                    "it is in mode {m}: {runs} run in mode {wanted} (set_mode({wanted}), set_state(0))"
                )
            }
            _ => return true,
        };
        self.notice(format!("{what} was not executed: {why}"));
        false
    }

    /// Raises warning `code` for `what`, not executed, saying why.
    fn refuse(&mut self, what: &str, code: u8, why: impl std::fmt::Display) {
        self.warning = code;
        self.notice(format!("{what} was not executed: warning {code}, {why}"));
    }

    /// A planned move (position mode), queued behind the others.
    fn planned_move(&mut self, target: MoveTarget, speed_mm_s: f64, now: Instant) {
        if !self.runs_in("a planned move", mode::POSITION) {
            return;
        }
        let target = resolve(target, &self.planned_pose());
        self.move_to(target, speed_mm_s, now);
    }

    /// A servo target (servo mode): no queue, the latest target replaces whatever runs, at
    /// the TCP's top speed; one more than 10 mm from the pad is not executed.
    fn servo_to(&mut self, target: MoveTarget, now: Instant) {
        if !self.runs_in("a servo target", mode::SERVO) {
            return;
        }
        self.halt(now);
        let here = self.pose;
        let target = resolve(target, &here);
        let step = distance_mm(&target, &here);
        if step > SERVO_STEP_MAX_MM {
            return self.notice(format!(
                "a servo target {step:.1} mm from the pad was not executed: servo steps are at most {SERVO_STEP_MAX_MM} mm"
            ));
        }
        self.move_to(target, SERVO_SPEED_MM_S, now);
    }

    /// A linear move of the pad to `target`, checked as a controller checks it; whether it
    /// was accepted.
    fn move_to(&mut self, target: TcpPoseMm, speed_mm_s: f64, now: Instant) -> bool {
        self.move_along(target, speed_mm_s, None, now)
    }

    /// A linear move of the pad to `target`, or one part of a joint move's path (`segment`:
    /// the joints at its ends and its time), checked as a controller checks it; whether it
    /// was accepted.
    fn move_along(
        &mut self,
        target: TcpPoseMm,
        speed_mm_s: f64,
        segment: Option<JointSegment>,
        now: Instant,
    ) -> bool {
        let what = format!("a move to {}", describe_pose(&target));
        if !(target.iter().all(|v| v.is_finite()) && speed_mm_s.is_finite() && speed_mm_s > 0.0) {
            let why = format!(
                "a pose or a speed ({speed_mm_s} mm/s) that is not a finite positive number"
            );
            self.refuse(&what, warn_code::PARAMETER, why);
            return false;
        }
        let speed_mm_s = speed_mm_s.max(MIN_SPEED_MM_S);
        let tilt = tilt_deg(&world_pose(&self.mount, &target));
        if tilt > MAX_TILT_DEG {
            self.refuse(&what, warn_code::PARAMETER, tilt_refusal(tilt));
            return false;
        }
        let on_path = |why: String| match segment {
            Some(_) => format!("on the joint move's path: {why}"),
            None => why,
        };
        let pose = world_pose(&self.mount, &target);
        let p = pose.position;
        let table = self
            .world
            .lock()
            .map(|w| w.table.size_m)
            .unwrap_or([0.0; 2]);
        if p.z < 0.0 {
            let why = format!(
                "target z {:.1} mm is {:.1} mm into the table",
                target[2],
                -p.z * 1e3
            );
            self.fault(error_code::COLLISION, on_path(why), now);
            return false;
        }
        if p.x.abs() > table[0] / 2.0 || p.y.abs() > table[1] / 2.0 || p.z > self.arm.max_z_m {
            let why = format!(
                "target ({:.1}, {:.1}, {:.1}) mm is outside the safety boundary over the table",
                target[0], target[1], target[2]
            );
            self.fault(error_code::SAFETY_BOUNDARY, on_path(why), now);
            return false;
        }
        // A line's end the arm cannot hold (out of its reach, or a joint past its limit) is
        // refused as the controller refuses it: "no solution".
        if segment.is_none()
            && let Err(e) = arm_joints::joints_for(&target, self.planned_joints())
        {
            self.refuse(&what, warn_code::NO_SOLUTION, e);
            return false;
        }
        // Queued behind the moves not yet ended, from where the last of them ends.
        let (from, started) = match self.queue.back() {
            Some(last) => (last.to, last.started + last.duration),
            None => (self.pose, now),
        };
        // The sim arm checks the target and times the move from where the pad starts it; the
        // world's pad then goes back to where the clock has it now.
        self.place_pad(&from);
        let clock_before = self.world.lock().map(|w| w.time_s).unwrap_or(0.0);
        let checked = self.arm.move_linear(&pose, speed_mm_s * 1e-3);
        let clock_after = self.world.lock().map(|w| w.time_s).unwrap_or(clock_before);
        self.place_pad_now(now);
        if let Some(recorder) = &self.recorder {
            recorder.arm_move(MoveRecord {
                target: pose,
                speed_m_s: speed_mm_s * 1e-3,
                reached: world_pose(&self.mount, if checked.is_ok() { &target } else { &from }),
                time_s: Some(clock_after),
                error: checked.as_ref().err().map(ToString::to_string),
            });
        }
        match checked {
            Ok(()) => {}
            Err(DeviceError::UnsafeMove { reason, .. }) => {
                self.fault(error_code::COLLISION, on_path(reason), now);
                return false;
            }
            Err(e) => {
                self.fault(error_code::COLLISION, on_path(e.to_string()), now);
                return false;
            }
        }
        // A joint move's part takes its share of the joint move's time; a line the sim arm's
        // time, and no less than its turn of the pad takes at the joints' top speed.
        let twin_seconds = match segment {
            Some(part) => part.seconds,
            None => {
                let turn = world_pose(&self.mount, &from)
                    .rotation
                    .angle_between(pose.rotation);
                (clock_after - clock_before).max(turn / MAX_TURN_RAD_S)
            }
        };
        let duration = Duration::try_from_secs_f64(twin_seconds.max(0.0) / self.mount.time_scale);
        if let Ok(mut w) = self.world.lock() {
            w.time_s = clock_before + if duration.is_ok() { twin_seconds } else { 0.0 };
        }
        let Ok(duration) = duration else {
            self.place_pad(&from);
            let why = format!("it would last {twin_seconds:.3e} s");
            self.refuse(&what, warn_code::PARAMETER, why);
            return false;
        };
        let seconds = duration.as_secs_f64();
        // The SDK raises a speed of zero or below to the controller's slowest, 0.1 mm/s, as a
        // real controller then crawls: say so rather than leave a client waiting unexplained.
        if speed_mm_s < SLOW_SPEED_MM_S && seconds > SLOW_MOVE_S {
            self.notice(format!(
                "a move at {speed_mm_s} mm/s takes {seconds:.0} s (the SDK raises a speed of zero or below to 0.1 mm/s)"
            ));
        }
        self.queue.push_back(Moving {
            from,
            to: target,
            joints: segment.map(|part| (part.from, part.to)),
            started,
            duration,
        });
        self.last_speed_mm_s = speed_mm_s;
        self.state = motion::MOVING;
        true
    }
}

/// How far apart two SDK poses' positions are (mm).
fn distance_mm(a: &TcpPoseMm, b: &TcpPoseMm) -> f64 {
    DVec3::new(a[0] - b[0], a[1] - b[1], a[2] - b[2]).length()
}

/// Why a pose tilted `tilt_deg` from straight down is not run.
fn tilt_refusal(tilt_deg: f64) -> String {
    format!(
        "it tilts the pad {tilt_deg:.1} degrees from straight down; the twin presses with the pad down (at most {MAX_TILT_DEG} degrees)"
    )
}

/// How far a world pose tilts the pad's axis from straight down (degrees).
fn tilt_deg(pose: &Pose) -> f64 {
    let down = -pose.transform_vector(DVec3::Z).z;
    down.clamp(-1.0, 1.0).acos().to_degrees()
}

/// An SDK pose as a person reads it: mm and degrees, one decimal.
fn describe_pose(p: &TcpPoseMm) -> String {
    format!(
        "({:.1}, {:.1}, {:.1}) mm, roll/pitch/yaw ({:.1}, {:.1}, {:.1}) degrees",
        p[0],
        p[1],
        p[2],
        p[3].to_degrees(),
        p[4].to_degrees(),
        p[5].to_degrees()
    )
}

/// The world pose of the pad at SDK pose `p`: the base's axes are the table's, the
/// orientation is the SDK's roll-pitch-yaw (fixed axes x, y, z).
fn world_pose(mount: &ArmMount, p: &TcpPoseMm) -> Pose {
    Pose::new(
        mount.base_m + DVec3::new(p[0], p[1], p[2]) * 1e-3,
        DQuat::from_euler(EulerRot::ZYX, p[5], p[4], p[3]),
    )
}

/// The SDK pose of a pad at world pose `pose`.
#[cfg(test)]
fn sdk_pose(mount: &ArmMount, pose: &Pose) -> TcpPoseMm {
    let p = (pose.position - mount.base_m) * 1e3;
    let (yaw, pitch, roll) = pose.rotation.to_euler(EulerRot::ZYX);
    [p.x, p.y, p.z, roll, pitch, yaw]
}

/// The base-frame pose `target` names, from `planned` (where the last move ends).
pub fn resolve(target: MoveTarget, planned: &TcpPoseMm) -> TcpPoseMm {
    match target {
        MoveTarget::Base(p) => p,
        MoveTarget::Relative(d) => std::array::from_fn(|i| planned[i] + d[i]),
        MoveTarget::Tool(d) => {
            let frame = |p: &TcpPoseMm| DQuat::from_euler(EulerRot::ZYX, p[5], p[4], p[3]);
            let rotation = frame(planned);
            let at = DVec3::new(planned[0], planned[1], planned[2])
                + rotation * DVec3::new(d[0], d[1], d[2]);
            let (yaw, pitch, roll) = (rotation * frame(&d)).to_euler(EulerRot::ZYX);
            [at.x, at.y, at.z, roll, pitch, yaw]
        }
    }
}

fn lerp(a: &TcpPoseMm, b: &TcpPoseMm, t: f64) -> TcpPoseMm {
    let mut out = *a;
    for i in 0..3 {
        out[i] = a[i] + (b[i] - a[i]) * t;
    }
    // Orientation jumps at the end: a press keeps it, and the report's angles stay valid.
    if t >= 1.0 {
        out[3..].copy_from_slice(&b[3..]);
    }
    out
}

/// MOVE_LINE's motion type that reaches its Cartesian target by joint motion.
const JOINT_MOTION: u8 = 2;

/// The target, speed and motion type of a MOVE_LINE request in any of the layouts the SDK
/// sends: 9 f32 (pose, speed, acceleration, time), with 1-2 bytes of check and motion type,
/// or 10 f32 (with a blend radius) and 3-4 bytes (coordinate frame, axis-angle, check,
/// motion type). Motion type 0 is a line, 1 a line where one can be run (else joint motion),
/// 2 joint motion.
fn move_line_params(params: &[u8]) -> Option<(MoveTarget, f64, u8)> {
    let (floats, tool_frame) = match params.len() {
        36..=38 => (9, false),
        43 | 44 => {
            // Axis-angle targets are not spoken.
            if params[41] != 0 || params[40] > 1 {
                return None;
            }
            (10, params[40] == 1)
        }
        _ => return None,
    };
    let v = f32_values(&params[..floats * 4]);
    // Only a check of the move (only_check_type > 0) is not a move.
    let (check, motion_type) = match floats {
        9 => (
            params.get(36).copied().unwrap_or(0),
            params.get(37).copied().unwrap_or(0),
        ),
        _ => (params[42], params.get(43).copied().unwrap_or(0)),
    };
    if check != 0 || motion_type > JOINT_MOTION {
        return None;
    }
    let pose = [v[0], v[1], v[2], v[3], v[4], v[5]];
    let target = if tool_frame {
        MoveTarget::Tool(pose)
    } else {
        MoveTarget::Base(pose)
    };
    Some((target, v[6], motion_type))
}

/// A MOVE_RELATIVE request: Cartesian offsets (mm, rad) at a speed in mm/s, or joint
/// offsets (rad) at a joint speed in rad/s.
#[derive(Clone, Copy, Debug, PartialEq)]
enum RelativeMove {
    /// Offsets, speed and motion type (as MOVE_LINE's).
    Cartesian(TcpPoseMm, f64, u8),
    Joints([f64; 6], f64),
}

/// A MOVE_RELATIVE request: 11 f32 (7 offsets, of which the six-axis arm reads 6, speed,
/// acceleration, time, radius), then joint-motion and axis-angle flags, optionally check and
/// motion type. Axis-angle offsets are not spoken.
fn move_relative_params(params: &[u8]) -> Option<RelativeMove> {
    if !(46..=48).contains(&params.len()) || params[44] > 1 || params[45] != 0 {
        return None;
    }
    if params.get(46).is_some_and(|&check| check != 0) {
        return None;
    }
    let motion_type = params.get(47).copied().unwrap_or(0);
    if motion_type > JOINT_MOTION {
        return None;
    }
    let v = f32_values(&params[..44]);
    let six = [v[0], v[1], v[2], v[3], v[4], v[5]];
    Some(match params[44] {
        1 => RelativeMove::Joints(six, v[7]),
        _ => RelativeMove::Cartesian(six, v[7], motion_type),
    })
}

fn padded(text: &str, n: usize) -> Vec<u8> {
    let mut out = text.as_bytes().to_vec();
    out.resize(n, 0);
    out.truncate(n);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sdk_and_world_poses_round_trip_and_home_points_the_pad_down() {
        let mount = ArmMount::default();
        let p = [412.5, -80.0, 95.0, std::f64::consts::PI, 0.0, 0.6];
        let back = sdk_pose(&mount, &world_pose(&mount, &p));
        for i in 0..3 {
            assert!((back[i] - p[i]).abs() < 1e-9, "{back:?}");
        }
        let pose = world_pose(&mount, &p);
        let expected = Pose::tool_down_turned(pose.position, 0.6);
        assert!(pose.rotation.angle_between(expected.rotation) < 1e-9);
        let home = world_pose(&mount, &HOME);
        assert!((home.transform_vector(DVec3::Z) - DVec3::NEG_Z).length() < 1e-12);
    }

    #[test]
    fn move_line_takes_every_sdk_layout_and_refuses_checks_and_axis_angles() {
        let mut nine = f32_params(&[300.0, 0.0, 200.0, 3.1, 0.0, 0.0, 50.0, 500.0, 0.0]);
        assert_eq!(move_line_params(&nine).unwrap().1, 50.0);
        nine.push(0);
        assert!(move_line_params(&nine).is_some());
        nine.push(2);
        assert_eq!(move_line_params(&nine).unwrap().2, JOINT_MOTION);
        nine[37] = 3;
        assert!(move_line_params(&nine).is_none(), "no motion type 3");
        nine.pop();
        nine[36] = 1;
        assert!(move_line_params(&nine).is_none(), "only a check");
        let mut ten = f32_params(&[300.0, 0.0, 200.0, 3.1, 0.0, 0.0, 50.0, 500.0, 0.0, -1.0]);
        ten.extend([0, 0, 0]);
        assert!(matches!(move_line_params(&ten).unwrap().0, MoveTarget::Base(p) if p[2] == 200.0));
        ten[40] = 1;
        assert!(matches!(
            move_line_params(&ten).unwrap().0,
            MoveTarget::Tool(_)
        ));
        ten[41] = 1;
        assert!(move_line_params(&ten).is_none(), "axis-angle");
        assert!(move_line_params(&[0; 12]).is_none());
    }

    #[test]
    fn move_relative_reads_cartesian_and_joint_offsets_and_refuses_axis_angles() {
        let mut p = f32_params(&[0.0, 0.0, -0.25, 0.0, 0.0, 0.0, 0.0, 20.0, 500.0, 0.0, -1.0]);
        p.extend([0, 0]);
        let Some(RelativeMove::Cartesian(offset, speed, 0)) = move_relative_params(&p) else {
            panic!("a Cartesian offset");
        };
        assert_eq!((offset[2], speed), (-0.25, 20.0));
        p[44] = 1;
        assert!(matches!(
            move_relative_params(&p),
            Some(RelativeMove::Joints(q, 20.0)) if q[2] == -0.25
        ));
        p[45] = 1;
        assert!(move_relative_params(&p).is_none(), "axis-angle offsets");
    }

    #[test]
    fn a_tool_frame_offset_along_the_downward_pad_goes_down_in_the_base_frame() {
        // The pad points down (roll pi) turned 90 degrees: its +z is the base's -z and its +x
        // the base's +y.
        let planned = [
            400.0,
            20.0,
            100.0,
            std::f64::consts::PI,
            0.0,
            std::f64::consts::FRAC_PI_2,
        ];
        let t = resolve(MoveTarget::Tool([5.0, 0.0, 2.0, 0.0, 0.0, 0.0]), &planned);
        let expected = [400.0, 25.0, 98.0];
        for i in 0..3 {
            assert!((t[i] - expected[i]).abs() < 1e-9, "{t:?}");
        }
        let a = world_pose(&ArmMount::default(), &t).rotation;
        let b = world_pose(&ArmMount::default(), &planned).rotation;
        assert!(a.angle_between(b) < 1e-9);
        let r = resolve(
            MoveTarget::Relative([1.0, 0.0, -0.25, 0.0, 0.0, 0.1]),
            &planned,
        );
        assert!((r[2] - 99.75).abs() < 1e-12 && (r[5] - planned[5] - 0.1).abs() < 1e-12);
    }
}
