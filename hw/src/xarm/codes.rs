//! What the controller's error and warning codes mean (the vendor SDK's `x_code.py` and the
//! xArm user manual), so that an error names its cause rather than a number.

/// The controller error code's meaning; None for a code this table does not know.
pub fn error_title(code: u8) -> Option<&'static str> {
    Some(match code {
        1 => "the emergency stop button on the controller is pushed in",
        2 => "the control box's emergency IO is triggered",
        3 => "the three-state switch's emergency stop button is pressed",
        10 => "servo motor error",
        11..=17 => return Some(SERVO[(code - 11) as usize]),
        18 => "force torque sensor communication error",
        19 => "end effector communication error",
        21 => "kinematic error: re-plan the path",
        22 => "self-collision error",
        23 => "joint angle exceeds its limit",
        24 => "speed exceeds its limit",
        25 => "planning error: re-plan the path or reduce the speed",
        26 => "Linux RT error",
        27 => "command reply error",
        28 => "end module communication error",
        30 => "feedback speed exceeds its limit",
        31 => "collision caused abnormal current",
        32 => "three-point circle calculation error",
        33 => "controller GPIO error",
        34 => "recording timeout",
        35 => "safety boundary limit",
        36 => "too many delay commands",
        37 => "abnormal movement in manual mode",
        38 => "abnormal joint angle",
        39 => "power board master/slave IC communication error",
        50..=53 => "six-axis force torque sensor error",
        60 => "linear speed exceeded its limit in servo_j mode",
        110 => "arm base board communication error",
        111 => "control box external RS-485 device communication error",
        _ => return None,
    })
}

const SERVO: [&str; 7] = [
    "servo motor 1 error",
    "servo motor 2 error",
    "servo motor 3 error",
    "servo motor 4 error",
    "servo motor 5 error",
    "servo motor 6 error",
    "servo motor 7 error",
];

/// The controller warning code's meaning.
pub fn warning_title(code: u8) -> Option<&'static str> {
    Some(match code {
        11 => "the controller's command cache is full",
        12 => "a command parameter is out of range",
        13 => "unknown command",
        14 => "the command has no solution (unreachable pose)",
        15 => "Modbus command buffer full",
        _ => return None,
    })
}
