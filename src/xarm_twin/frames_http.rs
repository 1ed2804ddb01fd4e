//! The twin's sensors over HTTP, for the user's own reader code:
//!
//! - `GET /gelsight/frame.png`: a new GelSight frame at the pad's pose now (each request is
//!   one capture, with its own noise, as a camera's next frame is);
//! - `GET /gelsight/stream.mjpg`: the GelSight as an IP camera (Motion JPEG at its frame
//!   rate), for readers built on OpenCV's `VideoCapture`;
//! - `GET /camera/color.png`, `GET /camera/depth.png`: a new RealSense frame (depth as 16-bit
//!   PNG in 0.1 mm steps, as `ask --record` writes sessions; the header `X-Depth-Scale-M`
//!   says so);
//! - `GET /state`: the controller's state, pose, error and the twin's clock as JSON.

use super::Twin;
use anyhow::{Context, Result};
use axum::Router;
use axum::extract::State;
use axum::http::{StatusCode, header};
use axum::response::{IntoResponse, Response};
use axum::routing::get;
use std::net::TcpListener;
use std::sync::Arc;
use std::time::Instant;
use tactex_core::devices::{RgbdCamera, TactileSensor};
use tactex_core::frames::TactileFrame;
use tactex_core::geometry::Pose;
use tactex_hw::session::record::depth_to_u16;

type Shared = Arc<Twin>;

pub(super) fn serve(listener: TcpListener, twin: Shared) -> Result<()> {
    listener.set_nonblocking(true)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the frames server's runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        axum::serve(listener, router(twin))
            .with_graceful_shutdown(shutdown())
            .await
            .context("serving frames")
    })
}

/// Set once Ctrl-C or SIGTERM came: open MJPEG streams end at their next part, so that the
/// graceful shutdown, which waits for every response to finish, is not held by a viewer.
static STOPPING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// Ctrl-C or SIGTERM: the server stops and the twin writes its session.
async fn shutdown() {
    wait_for_signal().await;
    STOPPING.store(true, std::sync::atomic::Ordering::SeqCst);
}

async fn wait_for_signal() {
    #[cfg(unix)]
    {
        use tokio::signal::unix::{SignalKind, signal};
        match signal(SignalKind::terminate()) {
            Ok(mut term) => {
                tokio::select! {
                    _ = tokio::signal::ctrl_c() => {}
                    _ = term.recv() => {}
                }
            }
            Err(_) => {
                let _ = tokio::signal::ctrl_c().await;
            }
        }
    }
    #[cfg(not(unix))]
    {
        let _ = tokio::signal::ctrl_c().await;
    }
}

fn router(twin: Shared) -> Router {
    Router::new()
        .route("/gelsight/frame.png", get(gelsight_frame))
        .route("/gelsight/stream.mjpg", get(gelsight_stream))
        .route("/camera/color.png", get(camera_color))
        .route("/camera/depth.png", get(camera_depth))
        .route("/state", get(state))
        .fallback(|| async {
            error(
                StatusCode::NOT_FOUND,
                "no such page: /gelsight/frame.png, /gelsight/stream.mjpg, /camera/color.png, /camera/depth.png, /state",
            )
        })
        .with_state(twin)
}

fn error(status: StatusCode, message: &str) -> Response {
    (status, axum::Json(serde_json::json!({ "error": message }))).into_response()
}

fn png(bytes: Vec<u8>, extra: Option<(&'static str, &'static str)>) -> Response {
    let mut r = (
        [
            (header::CONTENT_TYPE, "image/png"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        bytes,
    )
        .into_response();
    if let Some((name, value)) = extra {
        r.headers_mut()
            .insert(name, header::HeaderValue::from_static(value));
    }
    r
}

/// Runs `work` off the server's threads; its error becomes a 500 naming `what`.
async fn blocking(
    what: &'static str,
    work: impl FnOnce() -> Result<Response> + Send + 'static,
) -> Response {
    match tokio::task::spawn_blocking(work).await {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => error(StatusCode::INTERNAL_SERVER_ERROR, &format!("{what}: {e:#}")),
        Err(e) => error(StatusCode::INTERNAL_SERVER_ERROR, &format!("{what}: {e}")),
    }
}

/// Runs `capture` with the world's pad where the controller's clock has it now (its world
/// pose given), holding the controller so that no move accepted meanwhile moves the pad under
/// the sensor.
fn with_pad_placed<T>(twin: &Twin, capture: impl FnOnce(Pose) -> Result<T>) -> Result<T> {
    let mut controller = twin
        .controller
        .lock()
        .map_err(|_| anyhow::anyhow!("lock poisoned"))?;
    let pad = controller.place_pad_now(Instant::now());
    capture(pad)
}

/// The GelSight's next frame, written into the session when the twin records one.
fn gelsight_capture(twin: &Twin) -> Result<TactileFrame> {
    with_pad_placed(twin, |pad| {
        let frame = twin
            .gelsight
            .lock()
            .map_err(|_| anyhow::anyhow!("lock poisoned"))?
            .capture()?;
        if let Some(recorder) = &twin.recorder {
            recorder.tactile_frame(&frame, pad)?;
        }
        Ok(frame)
    })
}

async fn gelsight_frame(State(twin): State<Shared>) -> Response {
    blocking("gelsight", move || {
        let frame = gelsight_capture(&twin)?;
        Ok(png(crate::report::output::png_bytes(&frame.image)?, None))
    })
    .await
}

/// The boundary between the stream's JPEG parts.
const MJPEG_BOUNDARY: &str = "tactexframe";

/// The GelSight as an IP camera: Motion JPEG over HTTP at the sensor's frame rate (or as fast
/// as the contact solver renders, when slower), one capture per part, until the client goes.
async fn gelsight_stream(State(twin): State<Shared>) -> Response {
    let period = {
        let rate = match twin.gelsight.lock() {
            Ok(g) => g.spec().frame_rate_hz,
            Err(_) => return error(StatusCode::INTERNAL_SERVER_ERROR, "gelsight: lock poisoned"),
        };
        std::time::Duration::from_secs_f64(1.0 / rate.clamp(1.0, 240.0))
    };
    let parts = futures_util::stream::unfold(
        (twin, tokio::time::Instant::now()),
        move |(twin, next)| async move {
            tokio::time::sleep_until(next).await;
            if STOPPING.load(std::sync::atomic::Ordering::SeqCst) {
                return None;
            }
            let shared = twin.clone();
            let part = tokio::task::spawn_blocking(move || -> Result<Vec<u8>> {
                let frame = gelsight_capture(&shared)?;
                let mut jpeg = Vec::new();
                image::codecs::jpeg::JpegEncoder::new_with_quality(&mut jpeg, 90)
                    .encode_image(&frame.image)
                    .context("encoding JPEG")?;
                let mut part = format!(
                    "--{MJPEG_BOUNDARY}\r\nContent-Type: image/jpeg\r\nContent-Length: {}\r\n\r\n",
                    jpeg.len()
                )
                .into_bytes();
                part.extend(jpeg);
                part.extend(b"\r\n");
                Ok(part)
            })
            .await;
            // A capture that fails ends the stream (the client sees it close).
            let part = part.ok()?.ok()?;
            let next = (next + period).max(tokio::time::Instant::now());
            Some((Ok::<_, std::io::Error>(part), (twin, next)))
        },
    );
    (
        [
            (
                header::CONTENT_TYPE,
                format!("multipart/x-mixed-replace; boundary={MJPEG_BOUNDARY}"),
            ),
            (header::CACHE_CONTROL, "no-store".to_string()),
        ],
        axum::body::Body::from_stream(parts),
    )
        .into_response()
}

/// The RealSense's next frame (as the session stores it, when the twin records one).
fn camera_frame(twin: &Twin) -> Result<tactex_core::frames::RgbdFrame> {
    with_pad_placed(twin, |_| {
        let frame = twin
            .camera
            .lock()
            .map_err(|_| anyhow::anyhow!("lock poisoned"))?
            .capture()?;
        Ok(match &twin.recorder {
            Some(recorder) => recorder.camera_frame(frame)?,
            None => frame,
        })
    })
}

async fn camera_color(State(twin): State<Shared>) -> Response {
    blocking("camera", move || {
        let frame = camera_frame(&twin)?;
        Ok(png(crate::report::output::png_bytes(&frame.color)?, None))
    })
    .await
}

async fn camera_depth(State(twin): State<Shared>) -> Response {
    blocking("camera", move || {
        let frame = camera_frame(&twin)?;
        let mut bytes = std::io::Cursor::new(Vec::new());
        depth_to_u16(&frame.depth_m)
            .write_to(&mut bytes, image::ImageFormat::Png)
            .context("encoding PNG")?;
        Ok(png(bytes.into_inner(), Some(("x-depth-scale-m", "0.0001"))))
    })
    .await
}

async fn state(State(twin): State<Shared>) -> Response {
    blocking("state", move || {
        let (s, fault) = {
            let mut c = twin
                .controller
                .lock()
                .map_err(|_| anyhow::anyhow!("lock poisoned"))?;
            (c.snapshot(Instant::now()), c.last_notice.clone())
        };
        let time_s = twin
            .world
            .lock()
            .map_err(|_| anyhow::anyhow!("lock poisoned"))?
            .time_s;
        Ok(axum::Json(serde_json::json!({
            "state": s.state,
            "mode": s.mode,
            "cmd_num": s.cmd_num,
            "enabled": s.enabled,
            "error_code": s.error,
            "warn_code": s.warning,
            "last_notice": fault,
            "pose": s.pose,
            "twin_time_s": time_s,
        }))
        .into_response())
    })
    .await
}
