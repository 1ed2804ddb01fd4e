//! The twin's sensors over HTTP, for the user's own reader code:
//!
//! - `GET /gelsight/frame.png`: a new GelSight frame at the pad's pose now (each request is
//!   one capture, with its own noise, as a camera's next frame is);
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
use tactex_hw::session::record::depth_to_u16;

type Shared = Arc<Twin>;

pub fn serve(listener: TcpListener, twin: Shared) -> Result<()> {
    listener.set_nonblocking(true)?;
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .worker_threads(2)
        .enable_all()
        .build()
        .context("starting the frames server's runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::from_std(listener)?;
        axum::serve(listener, router(twin))
            .with_graceful_shutdown(async {
                let _ = tokio::signal::ctrl_c().await;
            })
            .await
            .context("serving frames")
    })
}

fn router(twin: Shared) -> Router {
    Router::new()
        .route("/gelsight/frame.png", get(gelsight_frame))
        .route("/camera/color.png", get(camera_color))
        .route("/camera/depth.png", get(camera_depth))
        .route("/state", get(state))
        .fallback(|| async {
            error(
                StatusCode::NOT_FOUND,
                "no such page: /gelsight/frame.png, /camera/color.png, /camera/depth.png, /state",
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

async fn gelsight_frame(State(twin): State<Shared>) -> Response {
    blocking("gelsight", move || {
        let frame = twin
            .gelsight
            .lock()
            .map_err(|_| anyhow::anyhow!("lock poisoned"))?
            .capture()?;
        Ok(png(crate::output::png_bytes(&frame.image)?, None))
    })
    .await
}

/// The RealSense's next frame.
fn camera_frame(twin: &Twin) -> Result<tactex_core::frames::RgbdFrame> {
    Ok(twin
        .camera
        .lock()
        .map_err(|_| anyhow::anyhow!("lock poisoned"))?
        .capture()?)
}

async fn camera_color(State(twin): State<Shared>) -> Response {
    blocking("camera", move || {
        let frame = camera_frame(&twin)?;
        Ok(png(crate::output::png_bytes(&frame.color)?, None))
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
            (c.snapshot(Instant::now()), c.last_fault.clone())
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
            "last_fault": fault,
            "pose": s.pose,
            "twin_time_s": time_s,
        }))
        .into_response())
    })
    .await
}
