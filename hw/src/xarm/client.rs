//! The xArm client: one TCP connection to the controller's port 502, one request in flight,
//! replies matched by transaction id, controller error and warning bits turned into typed
//! errors, moves refused outside the configured workspace box, and a lost connection
//! re-opened on the next request (queries are retried once; moves never are, since a move
//! may have reached the controller).

use super::codes::{error_title, warning_title};
use super::frame::{self, HEADER_LEN, PROTOCOL_ID, Register, Reply, status};
use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::sync::atomic::{AtomicU8, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// A TCP pose as the controller takes it: x, y, z in mm, roll, pitch, yaw in rad (fixed
/// axes X-Y-Z, i.e. R = Rz(yaw) Ry(pitch) Rx(roll)).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TcpPose {
    pub x_mm: f64,
    pub y_mm: f64,
    pub z_mm: f64,
    pub roll_rad: f64,
    pub pitch_rad: f64,
    pub yaw_rad: f64,
}

impl TcpPose {
    pub fn to_array(self) -> [f64; 6] {
        [
            self.x_mm,
            self.y_mm,
            self.z_mm,
            self.roll_rad,
            self.pitch_rad,
            self.yaw_rad,
        ]
    }

    pub fn from_array(a: [f64; 6]) -> TcpPose {
        TcpPose {
            x_mm: a[0],
            y_mm: a[1],
            z_mm: a[2],
            roll_rad: a[3],
            pitch_rad: a[4],
            yaw_rad: a[5],
        }
    }
}

/// The box (in the arm's base frame, mm) that the tool centre may be sent into.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkspaceBox {
    pub min_mm: [f64; 3],
    pub max_mm: [f64; 3],
}

impl WorkspaceBox {
    /// A conservative box in front of an xArm 850 on a table: 100-700 mm ahead, 400 mm to
    /// each side, 50-600 mm above the base. A real cell sets its own.
    pub const TABLE_FRONT: WorkspaceBox = WorkspaceBox {
        min_mm: [100.0, -400.0, 50.0],
        max_mm: [700.0, 400.0, 600.0],
    };

    /// A box from [X0, X1, Y0, Y1, Z0, Z1] in mm, each minimum below its maximum.
    pub fn from_bounds_mm(b: [f64; 6]) -> Result<WorkspaceBox, String> {
        if b.iter().any(|v| !v.is_finite()) || b[0] >= b[1] || b[2] >= b[3] || b[4] >= b[5] {
            return Err(
                "expected [X0, X1, Y0, Y1, Z0, Z1] with each minimum below its maximum".into(),
            );
        }
        Ok(WorkspaceBox {
            min_mm: [b[0], b[2], b[4]],
            max_mm: [b[1], b[3], b[5]],
        })
    }

    /// Why `p` is outside, or None when it is inside.
    pub fn violation(&self, p: &TcpPose) -> Option<String> {
        let v = [p.x_mm, p.y_mm, p.z_mm];
        for (i, axis) in ["x", "y", "z"].iter().enumerate() {
            if !v[i].is_finite() {
                return Some(format!("{axis} = {} mm is not a number", v[i]));
            }
            if v[i] < self.min_mm[i] || v[i] > self.max_mm[i] {
                return Some(format!(
                    "{axis} = {:.1} mm is outside the workspace box [{:.0}, {:.0}] mm",
                    v[i], self.min_mm[i], self.max_mm[i]
                ));
            }
        }
        None
    }
}

#[derive(Clone, Debug)]
pub struct XArmConfig {
    /// HOST:PORT of the controller (the vendor's port is 502).
    pub addr: String,
    /// How long a reply may take.
    pub reply_timeout: Duration,
    /// How long a move may take from its command to the arm at rest.
    pub move_timeout: Duration,
    /// State polling interval while a move runs (the SDK polls every 50 ms).
    pub poll_interval: Duration,
    pub workspace: WorkspaceBox,
    /// Upper limit on Cartesian speed (mm/s); faster requests are refused.
    pub max_speed_mm_s: f64,
    /// Cartesian acceleration sent with every move (mm/s^2; the SDK's default is 2000).
    pub acceleration_mm_s2: f64,
}

impl XArmConfig {
    pub fn new(addr: impl Into<String>) -> Self {
        Self {
            addr: addr.into(),
            reply_timeout: Duration::from_secs(3),
            move_timeout: Duration::from_secs(120),
            poll_interval: Duration::from_millis(50),
            workspace: WorkspaceBox::TABLE_FRONT,
            max_speed_mm_s: 250.0,
            acceleration_mm_s2: 2000.0,
        }
    }
}

/// The controller's motion state (register 13).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotionState {
    Starting,
    Moving,
    /// At rest, ready for the next command (the SDK calls it "sleeping").
    Ready,
    Paused,
    Stopped,
    /// Any other value the controller reports.
    Other(u8),
}

impl MotionState {
    pub fn from_u8(v: u8) -> MotionState {
        match v {
            0 => MotionState::Starting,
            1 => MotionState::Moving,
            2 => MotionState::Ready,
            3 => MotionState::Paused,
            4 => MotionState::Stopped,
            v => MotionState::Other(v),
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum XArmError {
    #[error("xarm {addr}: cannot connect: {message}")]
    Connect { addr: String, message: String },
    #[error("xarm {addr}: no reply to {register:?} within {timeout_s} s")]
    Timeout {
        addr: String,
        register: Register,
        timeout_s: f64,
    },
    #[error("xarm {addr}: connection lost during {register:?}: {message}")]
    Disconnected {
        addr: String,
        register: Register,
        message: String,
    },
    #[error("xarm {addr}: bad reply to {register:?}: {message}")]
    Protocol {
        addr: String,
        register: Register,
        message: String,
    },
    #[error("xarm {addr}: controller error {code}: {title}")]
    Controller {
        addr: String,
        code: u8,
        title: String,
    },
    #[error("xarm {addr}: {register:?} refused with warning {code}: {title}")]
    Warning {
        addr: String,
        register: Register,
        code: u8,
        title: String,
    },
    #[error("xarm {addr}: controller rejected {register:?} as invalid")]
    Invalid { addr: String, register: Register },
    #[error("xarm {addr}: not ready for motion (enable it first: motion enable, mode 0, state 0)")]
    NotReady { addr: String },
    #[error("xarm {addr}: move refused: {reason}")]
    Refused { addr: String, reason: String },
    #[error("xarm {addr}: the arm stopped ({state:?}) before reaching the target")]
    Stopped { addr: String, state: MotionState },
    #[error("xarm {addr}: move not finished within {timeout_s} s")]
    MoveTimeout { addr: String, timeout_s: f64 },
}

/// The connection, behind a lock so that the client is shared by reference (core's
/// `Arm::pose` takes `&self`) with one request in flight at a time.
struct Connection {
    stream: Option<TcpStream>,
    transaction: u16,
}

pub struct XArm {
    config: XArmConfig,
    connection: Mutex<Connection>,
    /// The last warning code the controller reported with a successful reply (0: none).
    last_warning: AtomicU8,
}

impl XArm {
    /// Connects to the controller; nothing is sent until the first request.
    pub fn connect(config: XArmConfig) -> Result<XArm, XArmError> {
        let arm = XArm {
            config,
            connection: Mutex::new(Connection {
                stream: None,
                transaction: 1,
            }),
            last_warning: AtomicU8::new(0),
        };
        arm.reconnect(&mut arm.lock())?;
        Ok(arm)
    }

    pub fn config(&self) -> &XArmConfig {
        &self.config
    }

    pub fn addr(&self) -> &str {
        &self.config.addr
    }

    /// The last warning the controller reported with an accepted request, if any.
    pub fn last_warning(&self) -> Option<u8> {
        Some(self.last_warning.load(Ordering::Relaxed)).filter(|w| *w != 0)
    }

    fn lock(&self) -> MutexGuard<'_, Connection> {
        // A panic while holding the lock leaves at worst a dead stream, which is replaced.
        self.connection.lock().unwrap_or_else(|e| e.into_inner())
    }

    fn reconnect(&self, conn: &mut Connection) -> Result<(), XArmError> {
        conn.stream = None;
        let connect_error = |message: String| XArmError::Connect {
            addr: self.config.addr.clone(),
            message,
        };
        let addrs: Vec<SocketAddr> = self
            .config
            .addr
            .to_socket_addrs()
            .map_err(|e| connect_error(e.to_string()))?
            .collect();
        let mut last = "the address resolves to nothing".to_string();
        for a in addrs {
            match TcpStream::connect_timeout(&a, self.config.reply_timeout) {
                Ok(s) => {
                    let _ = s.set_nodelay(true);
                    conn.stream = Some(s);
                    return Ok(());
                }
                Err(e) => last = e.to_string(),
            }
        }
        Err(connect_error(last))
    }

    /// One request and its reply's parameters. A query is retried once on a fresh
    /// connection when the old one turns out dead; a command is not.
    fn call(&self, register: Register, params: &[u8]) -> Result<Vec<u8>, XArmError> {
        let query = matches!(
            register,
            Register::GetState | Register::GetError | Register::GetTcpPose
        );
        let reply = {
            let mut conn = self.lock();
            match self.exchange(&mut conn, register, params) {
                Err(XArmError::Disconnected { .. }) if query => {
                    self.reconnect(&mut conn)?;
                    self.exchange(&mut conn, register, params)
                }
                other => other,
            }
        };
        self.check(register, reply?)
    }

    fn exchange(
        &self,
        conn: &mut Connection,
        register: Register,
        params: &[u8],
    ) -> Result<Reply, XArmError> {
        if conn.stream.is_none() {
            self.reconnect(conn)?;
        }
        let transaction = conn.transaction;
        // Transaction ids run 1..=65535 and wrap, as the SDK's do.
        conn.transaction = conn.transaction % u16::MAX + 1;
        let request = frame::request(transaction, register, params);
        let stream = conn.stream.as_mut().expect("connected above");
        let result = self.send_and_receive(stream, register, transaction, &request);
        if result.is_err() {
            // A late reply would answer the wrong request: start over on a new connection.
            conn.stream = None;
        }
        result
    }

    fn send_and_receive(
        &self,
        stream: &mut TcpStream,
        register: Register,
        transaction: u16,
        request: &[u8],
    ) -> Result<Reply, XArmError> {
        let addr = self.config.addr.clone();
        let timeout = self.config.reply_timeout;
        let lost = |e: std::io::Error| XArmError::Disconnected {
            addr: addr.clone(),
            register,
            message: e.to_string(),
        };
        stream.write_all(request).map_err(lost)?;
        let deadline = Instant::now() + timeout;
        loop {
            let mut head = [0u8; HEADER_LEN];
            read_until(stream, &mut head, deadline)
                .map_err(|e| io_failure(e, &addr, register, timeout))?;
            let h = frame::header(&head);
            let mut body = vec![0u8; usize::from(h.length)];
            read_until(stream, &mut body, deadline)
                .map_err(|e| io_failure(e, &addr, register, timeout))?;
            let protocol = |message: String| XArmError::Protocol {
                addr: addr.clone(),
                register,
                message,
            };
            if h.protocol != PROTOCOL_ID {
                return Err(protocol(format!(
                    "protocol id {:#06x}, expected {PROTOCOL_ID:#06x}",
                    h.protocol
                )));
            }
            if h.transaction != transaction {
                // A reply to an earlier request that timed out: skip it, as the SDK does.
                continue;
            }
            if body.len() < 2 {
                return Err(protocol(format!("length {} is too short", h.length)));
            }
            if body[0] != register as u8 {
                return Err(protocol(format!("reply names register {}", body[0])));
            }
            return Ok(Reply {
                register: body[0],
                status: body[1],
                params: body[2..].to_vec(),
            });
        }
    }

    /// The status byte: errors and (for moves) warnings become typed errors.
    fn check(&self, register: Register, reply: Reply) -> Result<Vec<u8>, XArmError> {
        let addr = self.config.addr.clone();
        if reply.status & status::INVALID != 0 {
            return Err(XArmError::Invalid { addr, register });
        }
        if reply.status & status::WARNING == 0 && register != Register::GetError {
            self.last_warning.store(0, Ordering::Relaxed);
        }
        let moving = matches!(register, Register::MoveLine | Register::MoveHome);
        if reply.status & (status::ERROR | status::WARNING) != 0 && register != Register::GetError {
            let (error, warning) = self.error_warning()?;
            if error != 0 {
                return Err(XArmError::Controller {
                    addr,
                    code: error,
                    title: error_title(error).unwrap_or("unknown error").into(),
                });
            }
            self.last_warning.store(warning, Ordering::Relaxed);
            if moving && warning != 0 {
                return Err(XArmError::Warning {
                    addr,
                    register,
                    code: warning,
                    title: warning_title(warning).unwrap_or("unknown warning").into(),
                });
            }
        }
        if moving && reply.status & status::NOT_READY != 0 {
            return Err(XArmError::NotReady { addr });
        }
        let want = register.reply_len();
        if reply.params.len() < want {
            return Err(XArmError::Protocol {
                addr,
                register,
                message: format!("{} parameter bytes, expected {want}", reply.params.len()),
            });
        }
        Ok(reply.params)
    }

    /// Error and warning codes (register 15); 0 is none.
    pub fn error_warning(&self) -> Result<(u8, u8), XArmError> {
        let p = self.call(Register::GetError, &[])?;
        Ok((p[0], p[1]))
    }

    pub fn motion_state(&self) -> Result<MotionState, XArmError> {
        let p = self.call(Register::GetState, &[])?;
        Ok(MotionState::from_u8(p[0]))
    }

    /// Servo power for all joints (axis id 8).
    pub fn motion_enable(&self, enable: bool) -> Result<(), XArmError> {
        self.call(Register::MotionEnable, &[8, u8::from(enable)])
            .map(drop)
    }

    /// 0 position control, 1 servo motion, 2 joint teaching (manual).
    pub fn set_mode(&self, mode: u8) -> Result<(), XArmError> {
        self.call(Register::SetMode, &[mode]).map(drop)
    }

    /// 0 start motion, 3 pause, 4 stop (clears the command queue).
    pub fn set_state(&self, state: u8) -> Result<(), XArmError> {
        self.call(Register::SetState, &[state]).map(drop)
    }

    pub fn clean_error(&self) -> Result<(), XArmError> {
        self.call(Register::CleanError, &[]).map(drop)
    }

    /// What the SDK's examples do before moving: enable, position mode, start.
    pub fn prepare(&self) -> Result<(), XArmError> {
        self.motion_enable(true)?;
        self.set_mode(0)?;
        self.set_state(0)
    }

    pub fn tcp_pose(&self) -> Result<TcpPose, XArmError> {
        let p = frame::f32_values(&self.call(Register::GetTcpPose, &[])?);
        // A controller that reports NaN or infinity knows no pose; moving from one would not
        // be safe, and printing it would hide that.
        if let Some(bad) = p.iter().take(6).find(|v| !v.is_finite()) {
            return Err(XArmError::Protocol {
                addr: self.config.addr.clone(),
                register: Register::GetTcpPose,
                message: format!("the pose has a value that is not a number ({bad})"),
            });
        }
        Ok(TcpPose::from_array([p[0], p[1], p[2], p[3], p[4], p[5]]))
    }

    /// A straight-line move of the tool centre (register 21), returning once the arm is at
    /// rest there. Refused before anything is sent when the target is outside the workspace
    /// box or the speed is not in (0, max].
    pub fn move_line(&self, target: &TcpPose, speed_mm_s: f64) -> Result<(), XArmError> {
        let refused = |reason: String| XArmError::Refused {
            addr: self.config.addr.clone(),
            reason,
        };
        if let Some(reason) = self.config.workspace.violation(target) {
            return Err(refused(reason));
        }
        if !(speed_mm_s > 0.0 && speed_mm_s <= self.config.max_speed_mm_s) {
            return Err(refused(format!(
                "speed {speed_mm_s} mm/s is not in (0, {}] mm/s",
                self.config.max_speed_mm_s
            )));
        }
        if target.to_array()[3..].iter().any(|a| !a.is_finite()) {
            return Err(refused("an orientation angle is not a number".into()));
        }
        let mut values = target.to_array().to_vec();
        values.extend([speed_mm_s, self.config.acceleration_mm_s2, 0.0]);
        self.call(Register::MoveLine, &frame::f32_params(&values))?;
        self.wait_motion()
    }

    /// The joints to the home position (register 25) at `speed_rad_s`, waiting until done.
    pub fn move_home(&self, speed_rad_s: f64) -> Result<(), XArmError> {
        // The SDK's joint defaults: 20 deg/s, 500 deg/s^2.
        let acc = 500f64.to_radians();
        self.call(
            Register::MoveHome,
            &frame::f32_params(&[speed_rad_s, acc, 0.0]),
        )?;
        self.wait_motion()
    }

    /// Polls the state until the arm is at rest, as the SDK's `wait_move` does: done after
    /// two "ready" reads once motion was seen (ten when it was not), an error when the arm
    /// stops or the controller reports an error.
    fn wait_motion(&self) -> Result<(), XArmError> {
        let deadline = Instant::now() + self.config.move_timeout;
        let mut seen_motion = false;
        let mut ready_reads = 0;
        while Instant::now() < deadline {
            match self.motion_state()? {
                MotionState::Starting | MotionState::Moving | MotionState::Paused => {
                    seen_motion = true;
                    ready_reads = 0;
                }
                MotionState::Ready => {
                    ready_reads += 1;
                    if ready_reads >= if seen_motion { 2 } else { 10 } {
                        return Ok(());
                    }
                }
                state => {
                    return Err(XArmError::Stopped {
                        addr: self.config.addr.clone(),
                        state,
                    });
                }
            }
            std::thread::sleep(self.config.poll_interval);
        }
        Err(XArmError::MoveTimeout {
            addr: self.config.addr.clone(),
            timeout_s: self.config.move_timeout.as_secs_f64(),
        })
    }
}

/// Fills `buf` before `deadline`.
fn read_until(stream: &mut TcpStream, buf: &mut [u8], deadline: Instant) -> std::io::Result<()> {
    let mut got = 0;
    while got < buf.len() {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() {
            return Err(ErrorKind::TimedOut.into());
        }
        stream.set_read_timeout(Some(left))?;
        match stream.read(&mut buf[got..]) {
            Ok(0) => return Err(ErrorKind::UnexpectedEof.into()),
            Ok(n) => got += n,
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) => return Err(e),
        }
    }
    Ok(())
}

fn io_failure(e: std::io::Error, addr: &str, register: Register, timeout: Duration) -> XArmError {
    match e.kind() {
        ErrorKind::TimedOut | ErrorKind::WouldBlock => XArmError::Timeout {
            addr: addr.into(),
            register,
            timeout_s: timeout.as_secs_f64(),
        },
        ErrorKind::UnexpectedEof => XArmError::Disconnected {
            addr: addr.into(),
            register,
            message: "the controller closed the connection".into(),
        },
        _ => XArmError::Disconnected {
            addr: addr.into(),
            register,
            message: e.to_string(),
        },
    }
}
