//! The controller's report streams, byte for byte as the vendor SDK parses them
//! (`xarm/x3/report.py` and `_handle_report_data` in `xarm/x3/base.py`): each report starts
//! with its own length (u32 big-endian); state and mode share a byte; cmd_num and the 16-bit
//! fields are big-endian, floats little-endian.
//!
//! - real (port 30003): 135 bytes, state, joints, pose, torques, force sensor.
//! - normal (30001): 145 bytes, adding brakes, enables, error and warning, TCP offset and load.
//! - rich (30002, the SDK's default): 587 bytes, adding the arm's type and firmware, speed
//!   and acceleration limits, servo codes, temperatures and the rest of the 2.x layout.

use super::controller::Snapshot;
use tactex_hw::xarm::frame::f32_params;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ReportKind {
    Real,
    Normal,
    Rich,
}

impl ReportKind {
    /// Bytes in one report of this kind, its length prefix included.
    fn byte_len(self) -> usize {
        match self {
            ReportKind::Real => 135,
            ReportKind::Normal => 145,
            ReportKind::Rich => 587,
        }
    }

    /// Reports a second: the controller sends the real-time report at 100 Hz and the others
    /// at 10 Hz; the SDK's report thread flags gaps over 205 ms.
    pub fn rate_hz(self) -> f64 {
        match self {
            ReportKind::Real => 100.0,
            ReportKind::Normal | ReportKind::Rich => 10.0,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            ReportKind::Real => "real",
            ReportKind::Normal => "normal",
            ReportKind::Rich => "rich",
        }
    }
}

/// What the report says beyond the controller's state: the arm's identity and limits.
pub struct ReportContext<'a> {
    /// Firmware version as the rich report carries it (30 bytes, e.g. "v2.0.0").
    pub firmware: &'a str,
    /// Reports sent on this connection so far (the rich report's counter).
    pub counter: u32,
}

/// An xArm 850: 6 axes, robot type 12.
const AXES: u8 = 6;
const ROBOT_TYPE: u8 = 12;

pub fn encode(kind: ReportKind, s: &Snapshot, ctx: &ReportContext) -> Vec<u8> {
    let mut out = Vec::with_capacity(kind.byte_len());
    out.extend_from_slice(&(kind.byte_len() as u32).to_be_bytes());
    out.push((s.state & 0x0f) | (s.mode << 4));
    out.extend_from_slice(&s.cmd_num.to_be_bytes());
    // Joint angles (the UF850's, a seventh zero), the TCP pose, joint torques.
    let [j1, j2, j3, j4, j5, j6] = s.joints;
    out.extend(f32_params(&[j1, j2, j3, j4, j5, j6, 0.0]));
    out.extend(f32_params(&s.pose));
    out.extend(f32_params(&[0.0; 7]));
    debug_assert_eq!(out.len(), 87);
    if kind == ReportKind::Real {
        // Force-torque sensor: external and raw forces.
        out.extend(f32_params(&[0.0; 12]));
        debug_assert_eq!(out.len(), kind.byte_len());
        return out;
    }
    let motors = if s.enabled { (1u8 << AXES) - 1 } else { 0 };
    // Brakes released and motors enabled together.
    out.extend([motors, motors, s.error, s.warning]);
    // TCP offset (the twin's TCP is the gel's centre), TCP load (mass, centre of mass).
    out.extend(f32_params(&[0.0; 6]));
    out.extend(f32_params(&[0.0; 4]));
    // Collision and teach sensitivity, gravity direction.
    out.extend([3, 3]);
    out.extend(f32_params(&[0.0, 0.0, -1.0]));
    debug_assert_eq!(out.len(), 145);
    if kind == ReportKind::Normal {
        return out;
    }
    // Type, axes, master and slave ids, motor type and firmware ids.
    out.extend([ROBOT_TYPE, AXES, 0, 0, 0, 0]);
    let mut version = ctx.firmware.as_bytes().to_vec();
    version.resize(30, 0);
    out.extend(version);
    // TCP jerk, min and max acceleration (mm/s^2), min and max speed (mm/s).
    out.extend(f32_params(&[10000.0, 1.0, 50000.0, 0.1, 1000.0]));
    // Joint jerk, min and max acceleration, min and max speed (rad).
    out.extend(f32_params(&[500.0, 0.01, 20.0, 0.01, std::f64::consts::PI]));
    // Rotation jerk and max acceleration.
    out.extend(f32_params(&[2.3, 2.3]));
    // Servo error and warning codes (7 joints), tool GPIO codes, temperatures (deg C).
    out.extend([0u8; 14]);
    out.extend([0u8; 2]);
    out.extend([35u8; 7]);
    // Target TCP speed and target joint speeds (the 8th float of the SDK's read).
    out.extend(f32_params(&[s.tcp_speed_mm_s]));
    out.extend(f32_params(&[0.0; 7]));
    out.extend_from_slice(&ctx.counter.to_be_bytes());
    // World offset, controller and tool GPIO reset, not a simulation robot (the twin
    // answers as the real arm does), collision detection on, no collision tool.
    out.extend(f32_params(&[0.0; 6]));
    out.extend([0, 0, 0, 1, 0]);
    out.extend(f32_params(&[0.0; 6]));
    // Joint voltages (centivolts, big-endian) and currents.
    for _ in 0..7 {
        out.extend_from_slice(&4800u16.to_be_bytes());
    }
    out.extend(f32_params(&[0.0; 7]));
    // Control box GPIO: module status and error, 8 big-endian words, 4 x 8 IO configs.
    out.extend([0, 0]);
    out.extend([0u8; 16]);
    out.extend([0u8; 32]);
    debug_assert_eq!(out.len(), 433);
    // Force-torque sensor, identification progress, axis-angle pose.
    out.extend(f32_params(&[0.0; 12]));
    out.push(0);
    out.extend(f32_params(&[0.0; 3]));
    // Configuration bits, reduced mode, its TCP boundary, speeds and joint limits.
    out.push(0);
    out.push(0);
    out.extend([0u8; 12]);
    out.extend(f32_params(&[0.0, 0.0]));
    out.extend(f32_params(&[0.0; 14]));
    // Fence mode, collision rebound, GPIO alarm, switch, monitored device.
    out.extend([0, 0]);
    out.extend_from_slice(&0u32.to_be_bytes());
    out.extend([0, 0, 0]);
    out.extend([0u8; 6]);
    debug_assert_eq!(out.len(), kind.byte_len());
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn snapshot() -> Snapshot {
        Snapshot {
            state: 1,
            mode: 0,
            cmd_num: 2,
            pose: [300.0, -20.0, 150.0, std::f64::consts::PI, 0.0, 0.25],
            joints: [0.1, -0.2, -1.0, 0.0, 1.2, 0.3],
            enabled: true,
            error: 31,
            warning: 0,
            tcp_speed_mm_s: 50.0,
        }
    }

    #[test]
    fn each_report_has_its_sdk_length_and_fields_where_the_sdk_reads_them() {
        let ctx = ReportContext {
            firmware: "v2.0.0",
            counter: 7,
        };
        for kind in [ReportKind::Real, ReportKind::Normal, ReportKind::Rich] {
            let r = encode(kind, &snapshot(), &ctx);
            assert_eq!(r.len(), kind.byte_len());
            assert_eq!(
                u32::from_be_bytes(r[0..4].try_into().unwrap()) as usize,
                r.len()
            );
            assert_eq!(r[4] & 0x0f, 1);
            assert_eq!(u16::from_be_bytes([r[5], r[6]]), 2);
            // Joint 2 where the SDK reads the joints (bytes 7..35).
            let j2 = f32::from_le_bytes(r[11..15].try_into().unwrap());
            assert_eq!(j2, -0.2);
            let z = f32::from_le_bytes(r[43..47].try_into().unwrap());
            assert_eq!(z, 150.0);
        }
        let rich = encode(ReportKind::Rich, &snapshot(), &ctx);
        assert_eq!(&rich[87..91], &[0x3f, 0x3f, 31, 0]);
        assert_eq!(&rich[145..147], &[12, 6]);
        assert_eq!(&rich[151..157], b"v2.0.0");
        assert_eq!(u32::from_be_bytes(rich[284..288].try_into().unwrap()), 7);
        assert_eq!(f32::from_le_bytes(rich[252..256].try_into().unwrap()), 50.0);
    }
}
