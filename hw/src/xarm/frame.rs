//! The xArm controller's private Modbus-TCP framing (port 502), as the vendor's Python SDK
//! speaks it (`xarm/core/wrapper/uxbus_cmd_tcp.py`):
//!
//! request: transaction id (u16 BE) | protocol id 0x0002 (u16 BE) | length (u16 BE) = 1 +
//! parameter bytes | register (u8) | parameters (f32 little-endian, or bytes)
//!
//! reply: transaction id | protocol id | length = 2 + parameter bytes | register | status
//! byte | parameters

/// The private protocol's identifier (the standard Modbus one is 0).
pub const PROTOCOL_ID: u16 = 0x0002;
/// Bytes before the register: transaction id, protocol id, length.
pub const HEADER_LEN: usize = 6;

/// The controller registers this client speaks (`XCONF.UxbusReg` in the SDK).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
pub enum Register {
    MotionEnable = 11,
    SetState = 12,
    GetState = 13,
    GetError = 15,
    CleanError = 16,
    SetMode = 19,
    MoveLine = 21,
    MoveHome = 25,
    GetTcpPose = 41,
}

impl Register {
    pub fn from_u8(r: u8) -> Option<Register> {
        use Register::*;
        [
            MotionEnable,
            SetState,
            GetState,
            GetError,
            CleanError,
            SetMode,
            MoveLine,
            MoveHome,
            GetTcpPose,
        ]
        .into_iter()
        .find(|x| *x as u8 == r)
    }

    /// Parameter bytes the controller sends back for this register.
    pub fn reply_len(self) -> usize {
        match self {
            Register::GetState => 1,
            Register::GetError => 2,
            Register::GetTcpPose => 24,
            _ => 0,
        }
    }
}

/// Status byte bits of a reply (`check_private_protocol` in the SDK).
pub mod status {
    /// The controller has an error code set.
    pub const ERROR: u8 = 0x40;
    /// The controller has a warning code set.
    pub const WARNING: u8 = 0x20;
    /// Not ready for motion (not enabled, or in a stop state).
    pub const NOT_READY: u8 = 0x10;
    /// The request was invalid (unknown register or bad parameters).
    pub const INVALID: u8 = 0x08;
}

/// One request frame.
pub fn request(transaction: u16, register: Register, params: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + 1 + params.len());
    out.extend_from_slice(&transaction.to_be_bytes());
    out.extend_from_slice(&PROTOCOL_ID.to_be_bytes());
    out.extend_from_slice(&(1 + params.len() as u16).to_be_bytes());
    out.push(register as u8);
    out.extend_from_slice(params);
    out
}

/// f32 parameters, little-endian, as the controller takes them.
pub fn f32_params(values: &[f64]) -> Vec<u8> {
    values
        .iter()
        .flat_map(|v| (*v as f32).to_le_bytes())
        .collect()
}

pub fn f32_values(bytes: &[u8]) -> Vec<f64> {
    bytes
        .chunks_exact(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect()
}

/// The fixed header of any frame: transaction id, protocol id and the length field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Header {
    pub transaction: u16,
    pub protocol: u16,
    /// Bytes after the header.
    pub length: u16,
}

pub fn header(bytes: &[u8; HEADER_LEN]) -> Header {
    Header {
        transaction: u16::from_be_bytes([bytes[0], bytes[1]]),
        protocol: u16::from_be_bytes([bytes[2], bytes[3]]),
        length: u16::from_be_bytes([bytes[4], bytes[5]]),
    }
}

/// A decoded reply body (what follows the header).
#[derive(Clone, Debug, PartialEq)]
pub struct Reply {
    pub register: u8,
    pub status: u8,
    pub params: Vec<u8>,
}

/// One reply frame, carrying the request's transaction and protocol ids (the SDK moves from
/// protocol 2 to 3 once connected), for the fake controller, the twin's controller and tests.
pub fn reply(transaction: u16, protocol: u16, register: u8, status: u8, params: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(HEADER_LEN + 2 + params.len());
    out.extend_from_slice(&transaction.to_be_bytes());
    out.extend_from_slice(&protocol.to_be_bytes());
    out.extend_from_slice(&(2 + params.len() as u16).to_be_bytes());
    out.push(register);
    out.push(status);
    out.extend_from_slice(params);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_linear_move_frame_has_the_sdk_layout() {
        // move_line: 9 f32 (x, y, z mm, roll, pitch, yaw rad, speed, acc, time).
        let params = f32_params(&[
            300.0,
            0.0,
            200.0,
            std::f64::consts::PI,
            0.0,
            0.0,
            100.0,
            2000.0,
            0.0,
        ]);
        let frame = request(7, Register::MoveLine, &params);
        assert_eq!(&frame[..7], &[0, 7, 0, 2, 0, 37, 21]);
        assert_eq!(frame.len(), 6 + 37);
        // 300.0f32 little-endian is 00 00 96 43.
        assert_eq!(&frame[7..11], &[0x00, 0x00, 0x96, 0x43]);
        assert_eq!(f32_values(&frame[7..])[3] as f32, std::f32::consts::PI);
    }

    #[test]
    fn a_query_frame_carries_no_parameters() {
        assert_eq!(
            request(65535, Register::GetTcpPose, &[]),
            [0xff, 0xff, 0, 2, 0, 1, 41]
        );
    }

    #[test]
    fn reply_length_counts_register_and_status() {
        let r = reply(3, PROTOCOL_ID, 13, status::WARNING, &[2]);
        assert_eq!(
            header(r[..6].try_into().unwrap()),
            Header {
                transaction: 3,
                protocol: 2,
                length: 3
            }
        );
        assert_eq!(&r[6..], &[13, 0x20, 2]);
    }
}
