//! The controller's joint-space moves: `set_servo_angle` absolute and relative (MOVE_JOINT,
//! MOVE_RELATIVE with the joint flag), a Cartesian target reached by joint motion
//! (MOVE_LINE's motion type 2) and servo-joint targets (`set_servo_angle_j`, mode 1). A joint
//! move runs the joints on a straight line in joint space, as the controller plans it: the
//! pad follows the arc their forward kinematics trace, run as `JOINT_PATH_SEGMENTS` checked
//! lines, so the table, the safety box and the crush limit are checked along the arc.

use super::{
    Controller, MAX_TILT_DEG, MoveTarget, SERVO_SPEED_MM_S, SERVO_STEP_MAX_MM, TcpPoseMm,
    arm_joints, mode, resolve, warn_code,
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

impl Controller {
    /// The joints at the end of the queued moves: where a relative joint move starts.
    fn planned_joints(&self) -> [f64; 6] {
        match self.queue.is_empty() {
            true => self.joints,
            false => {
                arm_joints::joints_for(&self.planned_pose(), self.joints).unwrap_or(self.joints)
            }
        }
    }

    fn refuse_joints(&mut self, command: &str, joints: [f64; 6], code: u8, why: String) {
        self.warning = code;
        self.notice(format!(
            "{command} to {:?} degrees was not executed: warning {code}, {why}",
            joints.map(|q| (q.to_degrees() * 100.0).round() / 100.0),
        ));
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
        (tilt > MAX_TILT_DEG).then(|| {
            format!(
                "it tilts the pad {tilt:.1} degrees from straight down; the twin presses with the pad down (at most {MAX_TILT_DEG} degrees)"
            )
        })
    }

    /// `set_servo_angle`: a move to `joints` (rad) at `speed_rad_s` of the joint that turns
    /// most (at most the joints' top speed), queued behind the others. Not executed (warning 12) past a joint's limit, or
    /// where the pad would tilt more than `MAX_TILT_DEG` at the target or on the way.
    pub(super) fn joint_move(&mut self, joints: [f64; 6], speed_rad_s: f64, now: Instant) {
        let command = "set_servo_angle";
        if !(speed_rad_s.is_finite() && speed_rad_s > 0.0) {
            let why = format!("a joint speed of {speed_rad_s} rad/s");
            return self.refuse_joints(command, joints, warn_code::PARAMETER, why);
        }
        let from = self.planned_joints();
        let turn = joints
            .iter()
            .zip(from)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        let speed_rad_s = speed_rad_s.min(MAX_JOINT_SPEED_RAD_S);
        self.joint_path(command, from, joints, turn / speed_rad_s, now);
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
        let target = resolve(target, &self.planned_pose());
        let from = self.planned_joints();
        let joints = match arm_joints::joints_for(&target, from) {
            Ok(q) => q,
            Err(e) => {
                self.warning = warn_code::NO_SOLUTION;
                return self.notice(format!(
                    "a joint move to {target:?} was not executed: warning {}, {e}",
                    warn_code::NO_SOLUTION
                ));
            }
        };
        if !(speed_mm_s.is_finite() && speed_mm_s > 0.0) {
            let why = format!("a speed of {speed_mm_s} mm/s");
            return self.refuse_joints("set_position", joints, warn_code::PARAMETER, why);
        }
        let here = self.planned_pose();
        let path_mm = (0..3)
            .map(|i| (target[i] - here[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        let turn = joints
            .iter()
            .zip(from)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
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
        if !self.ready() {
            return;
        }
        if self.mode != mode::POSITION {
            let m = self.mode;
            return self.notice(format!(
                "a planned move in mode {m} was not executed: planned moves run in mode 0 (set_mode(0), set_state(0))"
            ));
        }
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
        let per_segment_s = duration_s.max(0.0) / JOINT_PATH_SEGMENTS as f64;
        let mut at = self.planned_pose();
        for k in 1..=JOINT_PATH_SEGMENTS {
            let next = arm_joints::pose_at(along(k as f64 / JOINT_PATH_SEGMENTS as f64));
            let step_mm = (0..3)
                .map(|i| (next[i] - at[i]).powi(2))
                .sum::<f64>()
                .sqrt();
            let speed_mm_s = match per_segment_s > 0.0 && step_mm > 0.0 {
                true => (step_mm / per_segment_s).min(SERVO_SPEED_MM_S),
                false => SERVO_SPEED_MM_S,
            };
            if !self.move_to(next, speed_mm_s, now) {
                // Stopped on the way (a fault): the readings are the pad's where it stopped.
                return;
            }
            at = next;
        }
        self.joints = to;
    }

    /// `set_servo_angle_j` (servo mode): the joints' pose at once, replacing whatever runs;
    /// a target whose pad lies more than `SERVO_STEP_MAX_MM` from the pad, past a joint's
    /// limit or tilting the pad, is not executed.
    pub(super) fn servo_joints(&mut self, joints: [f64; 6], now: Instant) {
        if !self.ready() {
            return;
        }
        if self.mode != mode::SERVO {
            let m = self.mode;
            return self.notice(format!(
                "a servo-joint target in mode {m} was not executed: servo targets run in mode 1 (set_mode(1), set_state(0))"
            ));
        }
        if let Some(why) = Self::joints_refused(joints) {
            return self.refuse_joints("set_servo_angle_j", joints, warn_code::PARAMETER, why);
        }
        self.halt(now);
        let here = self.pose;
        let target: TcpPoseMm = arm_joints::pose_at(joints);
        let step = (0..3)
            .map(|i| (target[i] - here[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        if step > SERVO_STEP_MAX_MM {
            return self.notice(format!(
                "a servo-joint target whose pad is {step:.1} mm from the pad was not executed: servo steps are at most {SERVO_STEP_MAX_MM} mm"
            ));
        }
        if self.move_to(target, SERVO_SPEED_MM_S, now) {
            self.joints = joints;
        }
    }
}
