//! The controller's joint-space moves: `set_servo_angle` absolute and relative (MOVE_JOINT,
//! MOVE_RELATIVE with the joint flag), a Cartesian target reached by joint motion
//! (MOVE_LINE's motion type 2) and servo-joint targets (`set_servo_angle_j`, mode 1). A joint
//! move runs the joints on a straight line in joint space, as the controller plans it: the
//! pad follows the arc their forward kinematics trace, run as `JOINT_PATH_SEGMENTS` checked
//! lines, so the table, the safety box and the crush limit are checked along the arc.

use super::{
    Controller, JointSegment, MAX_TILT_DEG, MoveTarget, SERVO_SPEED_MM_S, SERVO_STEP_MAX_MM,
    TcpPoseMm, arm_joints, describe_pose, distance_mm, mode, resolve, tilt_refusal, warn_code,
};
use std::time::Instant;
use tactex_sim::arm::uf850;

/// Lines a joint move's arc is run as: at most a 1/16 of each joint's turn per line, so
/// the pad's path is within a fraction of a millimetre of the arc for turns of tens of
/// degrees.
const JOINT_PATH_SEGMENTS: usize = 16;

/// The SDK's default joint speed (rad/s), for a joint move to a Cartesian target that only
/// turns the pad (no distance to time it by).
const DEFAULT_JOINT_SPEED_RAD_S: f64 = 0.35;
/// The joints' top speed (rad/s): 180 degrees a second, to which the SDK also clamps.
const MAX_JOINT_SPEED_RAD_S: f64 = std::f64::consts::PI;
/// The joints' slowest speed (rad/s), to which the SDK raises slower ones.
const MIN_JOINT_SPEED_RAD_S: f64 = 1e-4;
/// A joint this close past its limit (rad) is taken at the limit: a limit sent as 32-bit
/// floats rounds a few microradians past it.
const LIMIT_ROUNDING_RAD: f64 = 1e-5;
/// The most any joint may turn in one servo-joint target (degrees): the twin's line, as the
/// 10 mm of a servo Cartesian target (uFactory asks for small, frequent servo steps).
const SERVO_JOINT_STEP_MAX_DEG: f64 = 3.0;

impl Controller {
    /// The joints at the end of the queued moves: where a relative joint move starts.
    pub(super) fn planned_joints(&self) -> [f64; 6] {
        match self.queue.back() {
            None => self.joints,
            Some(last) => match last.joints {
                Some((_, to)) => to,
                None => arm_joints::joints_for(&last.to, self.joints).unwrap_or(self.joints),
            },
        }
    }

    fn refuse_joints(&mut self, command: &str, joints: [f64; 6], code: u8, why: String) {
        let degrees = joints.map(|q| (q.to_degrees() * 100.0).round() / 100.0);
        self.refuse(&format!("{command} to {degrees:?} degrees"), code, why);
    }

    /// Why the pad cannot stand at `joints` (a joint past its limit, a tilt past
    /// `MAX_TILT_DEG`), or None.
    fn joints_refused(joints: [f64; 6]) -> Option<String> {
        if !joints.iter().all(|q| q.is_finite()) {
            return Some("a joint that is not a finite number".into());
        }
        if let Some(j) = uf850::past_limit(joints) {
            return Some(format!("joint {j} past its limit"));
        }
        let tilt = arm_joints::tilt_deg(joints);
        (tilt > MAX_TILT_DEG).then(|| tilt_refusal(tilt))
    }

    /// `set_servo_angle`: a move to `joints` (rad) at `speed_rad_s` of the joint that turns
    /// most (at most the joints' top speed), queued behind the others. Not executed (warning
    /// 12) past a joint's limit, or where the pad would tilt more than `MAX_TILT_DEG` at the
    /// target or on the way.
    pub(super) fn joint_move(&mut self, joints: [f64; 6], speed_rad_s: f64, now: Instant) {
        let command = "set_servo_angle";
        if !(speed_rad_s.is_finite() && speed_rad_s > 0.0) {
            let why = format!("a joint speed of {speed_rad_s} rad/s");
            return self.refuse_joints(command, joints, warn_code::PARAMETER, why);
        }
        let from = self.planned_joints();
        let speed_rad_s = speed_rad_s.clamp(MIN_JOINT_SPEED_RAD_S, MAX_JOINT_SPEED_RAD_S);
        let duration_s = largest_turn(&joints, &from) / speed_rad_s;
        self.joint_path(command, from, joints, duration_s, now);
    }

    /// `set_servo_angle(..., relative=True)`: the offsets added to the joints the queued
    /// moves end on.
    pub(super) fn relative_joint_move(
        &mut self,
        offsets: [f64; 6],
        speed_rad_s: f64,
        now: Instant,
    ) {
        let from = self.planned_joints();
        self.joint_move(
            std::array::from_fn(|i| from[i] + offsets[i]),
            speed_rad_s,
            now,
        );
    }

    /// A Cartesian target reached by joint motion (`set_position(..., motion_type=2)`): the
    /// joints nearest to where the queue ends that hold the target, run in the time the line
    /// would take at `speed_mm_s`. A target the arm cannot reach is not executed (warning
    /// 14, the controller's "no solution").
    pub(super) fn joint_move_to_pose(&mut self, target: MoveTarget, speed_mm_s: f64, now: Instant) {
        let here = self.planned_pose();
        let target = resolve(target, &here);
        let from = self.planned_joints();
        let what = format!("set_position to {} by joint motion", describe_pose(&target));
        let joints = match arm_joints::joints_for(&target, from) {
            Ok(q) => q,
            Err(e) => return self.refuse(&what, warn_code::NO_SOLUTION, e),
        };
        if !(speed_mm_s.is_finite() && speed_mm_s > 0.0) {
            let why = format!("a speed of {speed_mm_s} mm/s");
            return self.refuse(&what, warn_code::PARAMETER, why);
        }
        let path_mm = distance_mm(&target, &here);
        let turn = largest_turn(&joints, &from);
        // No joint faster than its top speed, however fast the line would be.
        let duration_s = match path_mm > 0.0 {
            true => path_mm / speed_mm_s,
            false => turn / DEFAULT_JOINT_SPEED_RAD_S,
        }
        .max(turn / MAX_JOINT_SPEED_RAD_S);
        self.joint_path("set_position", from, joints, duration_s, now);
    }

    /// Runs the joints from `from` to `to` on a straight line in joint space in
    /// `duration_s`: the pad along their arc, as checked lines; the readings follow the
    /// commanded branch.
    fn joint_path(
        &mut self,
        command: &str,
        from: [f64; 6],
        to: [f64; 6],
        duration_s: f64,
        now: Instant,
    ) {
        if !self.runs_in(command, mode::POSITION) {
            return;
        }
        let to = onto_limits(to);
        let along =
            |t: f64| -> [f64; 6] { std::array::from_fn(|i| from[i] + t * (to[i] - from[i])) };
        if let Some(why) = Self::joints_refused(to) {
            return self.refuse_joints(command, to, warn_code::PARAMETER, why);
        }
        for k in 1..JOINT_PATH_SEGMENTS {
            if let Some(why) = Self::joints_refused(along(k as f64 / JOINT_PATH_SEGMENTS as f64)) {
                let why = format!("on the way: {why}");
                return self.refuse_joints(command, to, warn_code::PARAMETER, why);
            }
        }
        // The joints run at a constant rate (no acceleration ramp), each part of the path
        // a line the sim arm checks, together taking the joint move's time.
        let seconds = duration_s.max(0.0) / JOINT_PATH_SEGMENTS as f64;
        let mut at = (self.planned_pose(), from);
        for k in 1..=JOINT_PATH_SEGMENTS {
            let q = along(k as f64 / JOINT_PATH_SEGMENTS as f64);
            let next = arm_joints::pose_at(q);
            let step_mm = distance_mm(&next, &at.0);
            let speed_mm_s = match seconds > 0.0 && step_mm > 0.0 {
                true => step_mm / seconds,
                false => SERVO_SPEED_MM_S,
            };
            let segment = JointSegment {
                from: at.1,
                to: q,
                seconds,
            };
            if !self.move_along(next, speed_mm_s, Some(segment), now) {
                // Stopped on the way (a fault): the readings are the pad's where it stopped.
                return;
            }
            at = (next, q);
        }
    }

    /// `set_servo_angle_j` (servo mode): the joints' pose at once, replacing whatever runs;
    /// a target whose pad lies more than `SERVO_STEP_MAX_MM` from the pad, past a joint's
    /// limit or tilting the pad, is not executed.
    pub(super) fn servo_joints(&mut self, joints: [f64; 6], now: Instant) {
        if !self.runs_in("a servo-joint target", mode::SERVO) {
            return;
        }
        let joints = onto_limits(joints);
        if let Some(why) = Self::joints_refused(joints) {
            return self.refuse_joints("set_servo_angle_j", joints, warn_code::PARAMETER, why);
        }
        self.halt(now);
        let (here, from) = (self.pose, self.joints_at_rest());
        let target: TcpPoseMm = arm_joints::pose_at(joints);
        let step = distance_mm(&target, &here);
        let turn = largest_turn(&joints, &from);
        if step > SERVO_STEP_MAX_MM || turn.to_degrees() > SERVO_JOINT_STEP_MAX_DEG {
            return self.notice(format!(
                "a servo-joint target {step:.1} mm and {:.1} degrees from where the arm is was not executed: servo steps are at most {SERVO_STEP_MAX_MM} mm and {SERVO_JOINT_STEP_MAX_DEG} degrees a joint",
                turn.to_degrees()
            ));
        }
        let segment = JointSegment {
            from,
            to: joints,
            seconds: (step / SERVO_SPEED_MM_S).max(turn / MAX_JOINT_SPEED_RAD_S),
        };
        self.move_along(target, SERVO_SPEED_MM_S, Some(segment), now);
    }

    /// The joints where the arm stands once halted: the reading that holds its pose.
    fn joints_at_rest(&mut self) -> [f64; 6] {
        let pose = self.pose;
        self.joints_at(&pose)
    }
}

/// Joints within `LIMIT_ROUNDING_RAD` past a limit, put on it.
fn onto_limits(joints: [f64; 6]) -> [f64; 6] {
    std::array::from_fn(|j| {
        let [lo, hi] = uf850::UF850_LIMITS_RAD[j];
        match joints[j] {
            q if q > hi && q <= hi + LIMIT_ROUNDING_RAD => hi,
            q if q < lo && q >= lo - LIMIT_ROUNDING_RAD => lo,
            q => q,
        }
    })
}

/// The largest turn of any joint between two sets of joints (rad).
fn largest_turn(a: &[f64; 6], b: &[f64; 6]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}
