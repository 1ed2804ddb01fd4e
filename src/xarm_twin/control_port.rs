//! The control port and the report ports over TCP, one thread per client, as many clients
//! as connect. Requests are framed as the SDK frames them (`tactex_hw::xarm::frame`); a reply
//! carries the request's transaction and protocol ids (the SDK moves from protocol 2 to 3
//! once connected). A frame the protocol does not allow closes that client's connection and
//! no other.

use super::Twin;
use super::controller::Answer;
use super::report::{self, ReportContext, ReportKind};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::{Duration, Instant};
use tactex_hw::xarm::frame::{self, HEADER_LEN, status};

/// The SDK's heartbeat frame (protocol 1, two zero bytes): nothing to answer.
const HEARTBEAT_PROTOCOL: u16 = 1;
/// The private protocol's ids: 2 while connecting, 3 after.
const PRIVATE_PROTOCOLS: [u16; 2] = [2, 3];
/// The SDK reads replies into a 1024-byte buffer; no request is longer.
const MAX_FRAME_BODY: usize = 1024;

pub(super) fn serve_control(listener: TcpListener, twin: &std::sync::Arc<Twin>) {
    for stream in listener.incoming().flatten() {
        let twin = twin.clone();
        std::thread::spawn(move || {
            if let Err(why) = control_client(stream, &twin) {
                eprintln!("tactex twin: control client closed: {why}");
            }
        });
    }
}

/// Serves one client until it closes or sends a frame the protocol does not allow.
fn control_client(mut stream: TcpStream, twin: &Twin) -> Result<(), String> {
    let _ = stream.set_nodelay(true);
    loop {
        let mut head = [0u8; HEADER_LEN];
        match stream.read_exact(&mut head) {
            Ok(()) => {}
            Err(e) if e.kind() == std::io::ErrorKind::UnexpectedEof => return Ok(()),
            Err(e) => return Err(e.to_string()),
        }
        let h = frame::header(&head);
        let length = usize::from(h.length);
        if length == 0 || length > MAX_FRAME_BODY {
            return Err(format!("a frame with length {length}"));
        }
        let mut body = vec![0u8; length];
        stream
            .read_exact(&mut body)
            .map_err(|e| format!("a frame cut short: {e}"))?;
        if h.protocol == HEARTBEAT_PROTOCOL {
            continue;
        }
        if !PRIVATE_PROTOCOLS.contains(&h.protocol) {
            return Err(format!("protocol id {:#06x}", h.protocol));
        }
        let register = body[0];
        let reply = {
            let mut c = twin
                .controller
                .lock()
                .map_err(|_| "the controller's lock is poisoned".to_string())?;
            let (bits, params) = match c.handle(register, &body[1..], Instant::now()) {
                Some(Answer::Params(p)) => (c.status_bits(), p),
                Some(Answer::Refused(p)) => (c.status_bits() | status::INVALID, p),
                Some(Answer::Invalid) | None => (c.status_bits() | status::INVALID, Vec::new()),
            };
            for notice in c.take_notices() {
                eprintln!("tactex twin: {notice}");
            }
            frame::reply(h.transaction, h.protocol, register, bits, &params)
        };
        stream.write_all(&reply).map_err(|e| e.to_string())?;
    }
}

pub(super) fn serve_reports(listener: TcpListener, kind: ReportKind, twin: &std::sync::Arc<Twin>) {
    for stream in listener.incoming().flatten() {
        let twin = twin.clone();
        std::thread::spawn(move || report_client(stream, kind, &twin));
    }
}

/// Streams reports of `kind` at the controller's rate until the client goes.
fn report_client(mut stream: TcpStream, kind: ReportKind, twin: &Twin) {
    let _ = stream.set_nodelay(true);
    let period = Duration::from_secs_f64(1.0 / kind.rate_hz());
    let mut next = Instant::now();
    let mut counter = 0u32;
    let firmware = match twin.controller.lock() {
        Ok(c) => c.mount().firmware().to_string(),
        Err(_) => return,
    };
    loop {
        let bytes = {
            let Ok(mut c) = twin.controller.lock() else {
                return;
            };
            let snapshot = c.snapshot(Instant::now());
            report::encode(
                kind,
                &snapshot,
                &ReportContext {
                    firmware: &firmware,
                    counter,
                },
            )
        };
        if stream.write_all(&bytes).is_err() {
            return;
        }
        counter = counter.wrapping_add(1);
        next += period;
        let now = Instant::now();
        if next > now {
            std::thread::sleep(next - now);
        } else {
            next = now;
        }
    }
}
