//! `tactex serve`: the chat page of the paper's system interface, on the twin. One page
//! (plain HTML and JS, no build step) shows the camera's live view with detection overlays,
//! a chat box, each touched fruit's tactile frames, hardness and ripeness, and the latency
//! of each stage; a running question streams its progress as server-sent events.

mod queries;

use crate::app::detector_choice::DetectorChoice;
use crate::app::parser_choice::ParserChoice;
use crate::app::{OpenedTwin, Twin};
use crate::cli::twin_flags::TwinFlags;
use anyhow::{Context, Result};
use axum::Router;
use axum::body::Bytes;
use axum::extract::rejection::{BytesRejection, PathRejection};
use axum::extract::{DefaultBodyLimit, Path as UrlPath, State};
use axum::http::{HeaderMap, StatusCode, header};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{Html, IntoResponse, Response};
use axum::routing::{get, post};
use clap::Args;
use futures_util::stream::{self, Stream};
use queries::{QueryRun, QueryStore, lock};
use serde::Deserialize;
use std::convert::Infallible;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::explain::Explainer;
use tactex_core::hardness::estimate::HardnessEstimator;
use tactex_core::pipeline::{Language, PipelineConfig};
use tactex_core::query::reader::PromptReader;
use tactex_core::scene::Scene;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::SimDevices;
use tactex_sim::contact::Fidelity;
use tactex_sim::devices::camera::SimCamera;
use tactex_sim::render::scene::SceneRenderer;
use tokio::sync::Semaphore;

const PAGE: &str = include_str!("page.html");

#[derive(Args)]
pub struct ServeArgs {
    /// Scene file (TOML); default scenes/demo.toml.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// Port to listen on; 0 takes a free one (the address is printed on stdout).
    #[arg(long, default_value_t = 8080)]
    pub port: u16,
    /// Address to listen on; 0.0.0.0 serves other machines too.
    #[arg(long, default_value = "127.0.0.1")]
    pub host: std::net::IpAddr,
    /// Seed of every question's sensor noise: the same question gets the same answer.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    #[command(flatten)]
    pub twin: TwinFlags,
    /// Questions answered at once (1-64); more are refused with HTTP 429 until one finishes.
    #[arg(long, default_value_t = 2)]
    pub max_queries: usize,
    /// Longest question accepted, in characters (1-100000).
    #[arg(long, default_value_t = 300)]
    pub max_prompt_chars: usize,
}

struct Served {
    scene: Scene,
    scene_name: String,
    detector_name: String,
    detector: DetectorChoice,
    renderer: Arc<dyn SceneRenderer>,
    parser: Box<dyn PromptReader>,
    /// The rules read the prompts (no model): a prompt they refuse is refused at once.
    rules_read: bool,
    explainer: Box<dyn Explainer>,
    estimator: Box<dyn HardnessEstimator + Send + Sync>,
    fidelity: Fidelity,
    sensor: SensorProfile,
    /// Where the scene camera really stands against the pipeline's belief.
    camera: crate::app::camera_placement::CameraPlacement,
    seed: u64,
    /// The live view's camera: the twin's camera on its own noise stream.
    live: Mutex<SimCamera>,
    queries: Mutex<QueryStore>,
    slots: Arc<Semaphore>,
    max_queries: usize,
    max_prompt_chars: usize,
}

type Shared = Arc<Served>;

pub(crate) fn run(args: &ServeArgs) -> Result<()> {
    if !(1..=64).contains(&args.max_queries) {
        anyhow::bail!("--max-queries: {}, expected 1..=64", args.max_queries);
    }
    if !(1..=100_000).contains(&args.max_prompt_chars) {
        anyhow::bail!(
            "--max-prompt-chars: {}, expected 1..=100000",
            args.max_prompt_chars
        );
    }
    let catalog = FruitCatalog::builtin();
    let path = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    let (scene, _) = crate::app::load_scene(&path, &catalog)?;
    let OpenedTwin {
        detector,
        renderer,
        parser,
        explainer,
        estimator,
        fidelity,
        sensor,
        camera,
    } = args.twin.options().open()?;
    let mut live = SimDevices::from_scene(&scene, args.seed.wrapping_add(1))?.camera;
    live.set_renderer(renderer.clone());
    let served = Arc::new(Served {
        scene_name: scene.name.clone(),
        scene,
        detector_name: args.twin.detector.clone(),
        detector,
        renderer,
        parser,
        rules_read: args.twin.parser == ParserChoice::Rules,
        explainer,
        estimator,
        fidelity,
        sensor,
        camera,
        seed: args.seed,
        live: Mutex::new(live),
        queries: Mutex::default(),
        slots: Arc::new(Semaphore::new(args.max_queries)),
        max_queries: args.max_queries,
        max_prompt_chars: args.max_prompt_chars,
    });
    let runtime = tokio::runtime::Builder::new_multi_thread()
        .enable_all()
        .build()
        .context("starting the server's runtime")?;
    runtime.block_on(serve(served, args.host, args.port, &path))
}

async fn serve(
    served: Shared,
    host: std::net::IpAddr,
    port: u16,
    scene: &std::path::Path,
) -> Result<()> {
    let listener = tokio::net::TcpListener::bind((host, port))
        .await
        .with_context(|| format!("--port {port}: cannot listen on {host}:{port}"))?;
    let address = listener.local_addr()?;
    // The first line on stdout is the address: tests and scripts read it when --port is 0.
    println!(
        "tactex serve: http://{address}/ (scene {})",
        scene.display()
    );
    use std::io::Write;
    std::io::stdout().flush()?;
    axum::serve(listener, router(served))
        .with_graceful_shutdown(async {
            let _ = tokio::signal::ctrl_c().await;
        })
        .await
        .context("serving")
}

fn router(served: Shared) -> Router {
    Router::new()
        .route("/", get(|| async { Html(PAGE) }))
        .route("/api/scene", get(scene_info))
        .route("/api/view.png", get(live_view))
        .route("/api/ask", post(ask))
        .route("/api/queries/{id}/events", get(events))
        .route(
            "/api/queries/{id}/objects/{object}/frames/{frame}",
            get(tactile_frame),
        )
        .fallback(|| async { error(StatusCode::NOT_FOUND, "no such page") })
        .method_not_allowed_fallback(|| async {
            error(
                StatusCode::METHOD_NOT_ALLOWED,
                "method not allowed here (questions are POSTed to /api/ask; the rest is GET)",
            )
        })
        // A question is a line of text; anything much bigger is not one.
        .layer(DefaultBodyLimit::max(MAX_BODY_BYTES))
        .with_state(served)
}

const MAX_BODY_BYTES: usize = 16 * 1024;

/// A URL whose parts do not parse (`/api/queries/abc/events`), answered as JSON like every
/// other error.
fn bad_url(e: PathRejection) -> Response {
    error(StatusCode::BAD_REQUEST, &format!("URL: {}", e.body_text()))
}

/// Questions come only from this server's own page or from clients that send no Origin
/// (curl, scripts): a page elsewhere that the user visits cannot queue them. Browsers send
/// Origin on every cross-site POST, and a form or text/plain POST is refused anyway.
fn refuse_foreign(headers: &HeaderMap) -> Option<Response> {
    let origin = headers.get(header::ORIGIN)?;
    let host = headers.get(header::HOST).and_then(|h| h.to_str().ok());
    let authority = origin
        .to_str()
        .ok()
        .and_then(|o| o.split_once("://"))
        .map(|(_, a)| a);
    if authority.is_some() && authority == host {
        return None;
    }
    Some(error(
        StatusCode::FORBIDDEN,
        &format!(
            "Origin {}: questions are taken from this server's own page only",
            tactex_core::printable::printable(&String::from_utf8_lossy(origin.as_bytes()))
        ),
    ))
}

/// An error response: the status and `{"error": message}`.
fn error(status: StatusCode, message: &str) -> Response {
    (status, axum::Json(serde_json::json!({ "error": message }))).into_response()
}

fn png(bytes: Vec<u8>) -> Response {
    (
        [
            (header::CONTENT_TYPE, "image/png"),
            (header::CACHE_CONTROL, "no-store"),
        ],
        bytes,
    )
        .into_response()
}

async fn scene_info(State(s): State<Shared>) -> Response {
    let k = match s.live.lock() {
        Ok(camera) => camera.intrinsics(),
        Err(_) => {
            return error(
                StatusCode::INTERNAL_SERVER_ERROR,
                "live camera lock poisoned",
            );
        }
    };
    axum::Json(serde_json::json!({
        "scene": s.scene_name,
        "objects": s.scene.objects.len(),
        "detector": s.detector_name,
        "explainer": s.explainer.name(),
        "renderer": s.renderer.name(),
        "max_queries": s.max_queries,
        "max_prompt_chars": s.max_prompt_chars,
        "view": { "width": k.width, "height": k.height },
    }))
    .into_response()
}

/// A fresh frame from the live camera (the twin renders once; each frame draws new noise).
async fn live_view(State(s): State<Shared>) -> Response {
    let frame = tokio::task::spawn_blocking(move || -> Result<Vec<u8>> {
        let color = {
            let mut camera = s
                .live
                .lock()
                .map_err(|_| anyhow::anyhow!("live camera lock poisoned"))?;
            camera.capture()?.color
        };
        crate::report::output::png_bytes(&color)
    })
    .await;
    match frame {
        Ok(Ok(bytes)) => png(bytes),
        Ok(Err(e)) => error(
            StatusCode::INTERNAL_SERVER_ERROR,
            &format!("live view: {e:#}"),
        ),
        Err(e) => error(
            StatusCode::INTERNAL_SERVER_ERROR,
            &format!("live view: {e}"),
        ),
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct AskRequest {
    prompt: String,
}

/// Starts a question: 202 with its id and event stream, or an error saying what was wrong
/// with the request (400 body, 422 prompt, 429 busy).
async fn ask(
    State(s): State<Shared>,
    headers: HeaderMap,
    body: Result<Bytes, BytesRejection>,
) -> Response {
    if let Some(refusal) = refuse_foreign(&headers) {
        return refusal;
    }
    let json = headers
        .get(header::CONTENT_TYPE)
        .and_then(|v| v.to_str().ok())
        .and_then(|v| v.split(';').next())
        .is_some_and(|v| v.trim().eq_ignore_ascii_case("application/json"));
    if !json {
        return error(
            StatusCode::UNSUPPORTED_MEDIA_TYPE,
            "request body: Content-Type must be application/json",
        );
    }
    let body = match body {
        Ok(body) => body,
        Err(e) if e.status() == StatusCode::PAYLOAD_TOO_LARGE => {
            return error(
                StatusCode::PAYLOAD_TOO_LARGE,
                &format!("request body: over the limit of {MAX_BODY_BYTES} bytes"),
            );
        }
        Err(e) => return error(e.status(), &format!("request body: {}", e.body_text())),
    };
    let request: AskRequest = match serde_json::from_slice(&body) {
        Ok(r) => r,
        Err(e) => {
            return error(
                StatusCode::BAD_REQUEST,
                &format!("request body: expected {{\"prompt\": \"...\"}}: {e}"),
            );
        }
    };
    let prompt = request.prompt.trim().to_string();
    let chars = prompt.chars().count();
    if chars == 0 {
        return error(
            StatusCode::UNPROCESSABLE_ENTITY,
            "prompt: empty; ask a question",
        );
    }
    if chars > s.max_prompt_chars {
        return error(
            StatusCode::UNPROCESSABLE_ENTITY,
            &format!(
                "prompt: {chars} characters; the limit is {}",
                s.max_prompt_chars
            ),
        );
    }
    if s.rules_read
        && let Err(e) = tactex_core::query::parse(&prompt, &FruitCatalog::builtin())
    {
        // The parser's errors already name the prompt.
        return error(StatusCode::UNPROCESSABLE_ENTITY, &e.to_string());
    }
    let Ok(slot) = s.slots.clone().try_acquire_owned() else {
        return error(
            StatusCode::TOO_MANY_REQUESTS,
            &format!(
                "busy: {} questions are being answered; ask again when one finishes",
                s.max_queries
            ),
        );
    };
    let run = lock(&s.queries).start();
    let id = run.id;
    let worker = s.clone();
    tokio::spawn(async move {
        let job_run = run.clone();
        let answered =
            tokio::task::spawn_blocking(move || answer_question(&worker, &job_run, &prompt)).await;
        if let Err(e) = answered {
            // A panic in the pipeline fails this question only.
            run.failed(&format!("internal error: {e}"));
        }
        drop(slot);
    });
    (
        StatusCode::ACCEPTED,
        axum::Json(serde_json::json!({
            "id": id,
            "events": format!("/api/queries/{id}/events"),
        })),
    )
        .into_response()
}

fn answer_question(s: &Served, run: &QueryRun, prompt: &str) {
    let twin = Twin {
        scene: &s.scene,
        seed: s.seed,
        sensor: &s.sensor,
        detector: &s.detector,
        renderer: &s.renderer,
        language: Language {
            reader: s.parser.as_ref(),
            explainer: s.explainer.as_ref(),
        },
        estimator: s.estimator.as_ref(),
        fidelity: s.fidelity,
        camera: &s.camera,
    };
    let answered = twin.answer(prompt, &PipelineConfig::default(), &|p| run.progress(&p));
    match answered {
        Ok(twin) => run.answered(twin.answer),
        Err(e) => run.failed(&format!("{e:#}")),
    }
}

/// The question's events from the first on, live until it is done.
async fn events(State(s): State<Shared>, id: Result<UrlPath<u64>, PathRejection>) -> Response {
    let UrlPath(id) = match id {
        Ok(id) => id,
        Err(e) => return bad_url(e),
    };
    let Some(run) = lock(&s.queries).get(id) else {
        return error(StatusCode::NOT_FOUND, &format!("question {id}: not found"));
    };
    let log = run.log.subscribe();
    Sse::new(replay(log))
        .keep_alive(KeepAlive::default())
        .into_response()
}

fn replay(
    log: tokio::sync::watch::Receiver<queries::QueryLog>,
) -> impl Stream<Item = Result<Event, Infallible>> {
    stream::unfold((log, 0usize), |(mut log, sent)| async move {
        loop {
            {
                let now = log.borrow_and_update();
                if let Some(e) = now.events.get(sent) {
                    let event = Event::default().event(e.name).data(e.data.clone());
                    drop(now);
                    return Some((Ok(event), (log, sent + 1)));
                }
                if now.done {
                    return None;
                }
            }
            if log.changed().await.is_err() {
                return None;
            }
        }
    })
}

/// A touched object's tactile frame as PNG: frame 0 is the no-contact reference, frames
/// 1.. the press from first contact on, and `imprint` the deepest frame's difference from
/// the reference, amplified, since the raw frames of a soft fruit look alike to the eye.
async fn tactile_frame(
    State(s): State<Shared>,
    parts: Result<UrlPath<(u64, usize, String)>, PathRejection>,
) -> Response {
    let UrlPath((id, object, frame)) = match parts {
        Ok(parts) => parts,
        Err(e) => return bad_url(e),
    };
    let Some(name) = frame.strip_suffix(".png") else {
        return error(
            StatusCode::NOT_FOUND,
            &format!("frame '{frame}': expected N.png or imprint.png"),
        );
    };
    let Some(run) = lock(&s.queries).get(id) else {
        return error(StatusCode::NOT_FOUND, &format!("question {id}: not found"));
    };
    let image = {
        let log = run.log.borrow();
        let press = log.presses.get(object).and_then(Option::as_ref);
        let image = press.and_then(|p| match name {
            "imprint" => p
                .frames
                .last()
                .map(|f| imprint(&p.reference.image, &f.image)),
            _ => match name.parse::<usize>() {
                Ok(0) => Some(p.reference.image.clone()),
                Ok(i) => p.frames.get(i - 1).map(|f| f.image.clone()),
                Err(_) => None,
            },
        });
        match image {
            Some(image) => image,
            None => {
                return error(
                    StatusCode::NOT_FOUND,
                    &format!("question {id}: object {object} has no tactile frame '{name}'"),
                );
            }
        }
    };
    match crate::report::output::png_bytes(&image) {
        Ok(bytes) => png(bytes),
        Err(e) => error(StatusCode::INTERNAL_SERVER_ERROR, &format!("{e:#}")),
    }
}

/// How much the imprint view amplifies a frame's difference from the reference.
const IMPRINT_GAIN: f64 = 4.0;

/// Mid-grey plus the amplified per-channel difference of `frame` from `reference`.
fn imprint(reference: &image::RgbImage, frame: &image::RgbImage) -> image::RgbImage {
    let mut out = frame.clone();
    for (o, r) in out.pixels_mut().zip(reference.pixels()) {
        for c in 0..3 {
            let d = f64::from(o[c]) - f64::from(r[c]);
            o[c] = (128.0 + IMPRINT_GAIN * d).round().clamp(0.0, 255.0) as u8;
        }
    }
    out
}
