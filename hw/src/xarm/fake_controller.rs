//! A fake xArm controller on 127.0.0.1 for tests and for bring-up of the tools without an
//! arm: it checks every frame against the protocol (protocol id, length field, register,
//! parameter count), keeps a motion state machine (enable, mode, state, moves that take
//! distance / speed of wall time), and can be told to misbehave: stay silent, drop the
//! connection mid-move, or raise a controller error.

use super::client::TcpPose;
use super::frame::{self, HEADER_LEN, PROTOCOL_ID, Register, status};
use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Ways the fake misbehaves, set by tests.
#[derive(Clone, Debug, Default)]
pub struct Faults {
    /// Never answer requests to this register.
    pub silent: Option<Register>,
    /// Close the connection once a move has been accepted (the arm keeps moving).
    pub drop_after_move: bool,
    /// Raise this controller error when a move is accepted (the arm stops, state 4).
    pub error_on_move: Option<u8>,
    /// Answer with this warning code when a move is asked for (the move is not done).
    pub warning_on_move: Option<u8>,
}

#[derive(Clone, Debug)]
pub struct FakeState {
    pub pose: TcpPose,
    pub enabled: bool,
    pub mode: u8,
    /// 0 starting, 1 moving, 2 ready, 3 paused, 4 stopped.
    pub state: u8,
    pub error: u8,
    pub warning: u8,
    /// The pose at which the running move ends, and when.
    pub moving_to: Option<(TcpPose, Instant)>,
    /// Every well-formed request received: register and parameter bytes.
    pub requests: Vec<(u8, Vec<u8>)>,
    /// What was wrong with each malformed frame received.
    pub violations: Vec<String>,
    pub connections: usize,
    pub faults: Faults,
    /// Multiplies every move's duration (0 finishes moves at the next state read).
    pub time_scale: f64,
}

/// The joints' home, as a TCP pose: the tool pointing down above the base's front.
pub const HOME: TcpPose = TcpPose {
    x_mm: 300.0,
    y_mm: 0.0,
    z_mm: 300.0,
    roll_rad: std::f64::consts::PI,
    pitch_rad: 0.0,
    yaw_rad: 0.0,
};

pub struct FakeController {
    pub addr: SocketAddr,
    pub state: Arc<Mutex<FakeState>>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
}

impl FakeController {
    /// Listens on a free port of 127.0.0.1, one connection at a time.
    pub fn start() -> std::io::Result<FakeController> {
        let listener = TcpListener::bind("127.0.0.1:0")?;
        let addr = listener.local_addr()?;
        let state = Arc::new(Mutex::new(FakeState {
            pose: HOME,
            enabled: false,
            mode: 0,
            state: 4,
            error: 0,
            warning: 0,
            moving_to: None,
            requests: Vec::new(),
            violations: Vec::new(),
            connections: 0,
            faults: Faults::default(),
            time_scale: 1.0,
        }));
        let stop = Arc::new(AtomicBool::new(false));
        let thread = {
            let (state, stop) = (state.clone(), stop.clone());
            std::thread::spawn(move || {
                for stream in listener.incoming() {
                    if stop.load(Ordering::SeqCst) {
                        break;
                    }
                    if let Ok(stream) = stream {
                        lock(&state).connections += 1;
                        serve_connection(stream, &state, &stop);
                    }
                }
            })
        };
        Ok(FakeController {
            addr,
            state,
            stop,
            thread: Some(thread),
        })
    }

    pub fn with<R>(&self, f: impl FnOnce(&mut FakeState) -> R) -> R {
        f(&mut lock(&self.state))
    }
}

impl Drop for FakeController {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        // Wake the accept loop.
        let _ = TcpStream::connect(self.addr);
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn lock(state: &Mutex<FakeState>) -> std::sync::MutexGuard<'_, FakeState> {
    state.lock().unwrap_or_else(|e| e.into_inner())
}

fn serve_connection(mut stream: TcpStream, state: &Mutex<FakeState>, stop: &AtomicBool) {
    let _ = stream.set_read_timeout(Some(Duration::from_millis(100)));
    loop {
        if stop.load(Ordering::SeqCst) {
            return;
        }
        let mut head = [0u8; HEADER_LEN];
        match read_frame_part(&mut stream, &mut head, stop) {
            Some(true) => {}
            Some(false) => continue,
            None => return,
        }
        let h = frame::header(&head);
        let mut body = vec![0u8; usize::from(h.length)];
        if body.is_empty() || read_frame_part(&mut stream, &mut body, stop) != Some(true) {
            lock(state)
                .violations
                .push(format!("frame with length {}", h.length));
            return;
        }
        let (reply, close) = answer(state, h.transaction, h.protocol, &body);
        if let Some(reply) = reply
            && stream.write_all(&reply).is_err()
        {
            return;
        }
        if close {
            return;
        }
    }
}

/// Fills `buf`: Some(true) when read, Some(false) when nothing arrived yet (poll again),
/// None when the peer closed or the fake stops.
fn read_frame_part(stream: &mut TcpStream, buf: &mut [u8], stop: &AtomicBool) -> Option<bool> {
    let mut got = 0;
    while got < buf.len() {
        if stop.load(Ordering::SeqCst) {
            return None;
        }
        match stream.read(&mut buf[got..]) {
            Ok(0) => return None,
            Ok(n) => got += n,
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                if got == 0 {
                    return Some(false);
                }
            }
            Err(_) => return None,
        }
    }
    Some(true)
}

/// Parameter bytes each register's request carries.
fn request_len(register: Register) -> &'static [usize] {
    match register {
        Register::MotionEnable => &[2],
        Register::SetState => &[1],
        Register::SetMode => &[1, 2],
        Register::MoveLine => &[36],
        Register::MoveHome => &[12],
        Register::GetState | Register::GetError | Register::CleanError | Register::GetTcpPose => {
            &[0]
        }
    }
}

/// The reply to one frame (None: stay silent) and whether to close the connection after it.
fn answer(
    state: &Mutex<FakeState>,
    transaction: u16,
    protocol: u16,
    body: &[u8],
) -> (Option<Vec<u8>>, bool) {
    let mut s = lock(state);
    let raw_register = body[0];
    let params = &body[1..];
    let invalid = |s: &mut FakeState, why: String| {
        s.violations.push(why);
        Some(frame::reply(
            transaction,
            PROTOCOL_ID,
            raw_register,
            status::INVALID,
            &[],
        ))
    };
    if protocol != PROTOCOL_ID {
        return (
            invalid(&mut s, format!("protocol id {protocol:#06x}")),
            false,
        );
    }
    let Some(register) = Register::from_u8(raw_register) else {
        return (
            invalid(&mut s, format!("unknown register {raw_register}")),
            false,
        );
    };
    if !request_len(register).contains(&params.len()) {
        let why = format!("{register:?} with {} parameter bytes", params.len());
        return (invalid(&mut s, why), false);
    }
    s.requests.push((raw_register, params.to_vec()));
    if s.faults.silent == Some(register) {
        return (None, false);
    }
    advance(&mut s);
    let mut out = Vec::new();
    let mut close = false;
    match register {
        Register::MotionEnable => {
            s.enabled = params[1] != 0;
            if !s.enabled {
                s.state = 4;
            }
        }
        Register::SetMode => s.mode = params[0],
        Register::SetState => match params[0] {
            // Starting a moving arm leaves it moving.
            0 if s.enabled && s.error == 0 && s.state != 1 => s.state = 2,
            3 | 4 => {
                s.state = params[0];
                s.moving_to = None;
            }
            _ => {}
        },
        Register::GetState => out.push(s.state),
        Register::GetError => out.extend([s.error, s.warning]),
        Register::CleanError => {
            s.error = 0;
            s.warning = 0;
        }
        Register::GetTcpPose => out = frame::f32_params(&s.pose.to_array()),
        Register::MoveLine | Register::MoveHome => {
            let ready = s.enabled && s.error == 0 && s.mode == 0 && matches!(s.state, 1 | 2);
            if let Some(w) = s.faults.warning_on_move {
                s.warning = w;
            } else if ready {
                let v = frame::f32_values(params);
                let (target, seconds) = if register == Register::MoveLine {
                    let target = TcpPose::from_array([v[0], v[1], v[2], v[3], v[4], v[5]]);
                    let d = ((target.x_mm - s.pose.x_mm).powi(2)
                        + (target.y_mm - s.pose.y_mm).powi(2)
                        + (target.z_mm - s.pose.z_mm).powi(2))
                    .sqrt();
                    (target, d / v[6].max(1e-3))
                } else {
                    (HOME, 0.5 / v[0].max(1e-3))
                };
                let scaled = Duration::from_secs_f64(seconds * s.time_scale);
                s.moving_to = Some((target, Instant::now() + scaled));
                s.state = 1;
                if let Some(code) = s.faults.error_on_move {
                    s.error = code;
                    s.state = 4;
                    s.moving_to = None;
                }
                close = s.faults.drop_after_move;
            }
        }
    }
    let mut bits = 0;
    if s.error != 0 {
        bits |= status::ERROR;
    }
    if s.warning != 0 {
        bits |= status::WARNING;
    }
    if !s.enabled || s.state >= 4 {
        bits |= status::NOT_READY;
    }
    (
        Some(frame::reply(
            transaction,
            PROTOCOL_ID,
            raw_register,
            bits,
            &out,
        )),
        close,
    )
}

/// Ends a move whose time is up.
fn advance(s: &mut FakeState) {
    if let Some((target, at)) = s.moving_to
        && Instant::now() >= at
    {
        s.pose = target;
        s.moving_to = None;
        s.state = 2;
    }
}
