//! The runtime behind every learned model (ONNX through `ort`): the pure-Rust tract backend by
//! default, ONNX Runtime when `ORT_DYLIB_PATH` names its shared library (`libonnxruntime.so`,
//! e.g. from PyPI's `onnxruntime` wheel, >= 1.24). `ort` holds one backend per process, so
//! the choice is made once, at the first model load, and reported with every estimate.

use ort::session::Session;
use std::path::{Path, PathBuf};

use std::sync::OnceLock;

/// The environment variable that switches learned models to ONNX Runtime.
pub const ORT_DYLIB_PATH: &str = "ORT_DYLIB_PATH";

#[derive(Clone, Debug, PartialEq)]
pub enum OnnxBackend {
    Tract,
    OnnxRuntime { library: PathBuf, version: String },
}

impl OnnxBackend {
    pub fn name(&self) -> String {
        match self {
            OnnxBackend::Tract => "tract".into(),
            OnnxBackend::OnnxRuntime { version, .. } => format!("onnxruntime {version}"),
        }
    }
}

#[derive(Debug, Clone, thiserror::Error)]
pub enum OnnxError {
    #[error("{ORT_DYLIB_PATH}={path}: {reason}")]
    Runtime { path: String, reason: String },
    #[error("{path}: {reason}")]
    Model { path: String, reason: String },
}

/// The bytes of the ONNX file at `path`: a regular file within `MAX_MODEL_BYTES`.
pub fn read_model_file(path: &Path) -> Result<Vec<u8>, OnnxError> {
    tactex_core::text_file::read_bytes(path, tactex_core::text_file::MAX_MODEL_BYTES).map_err(|e| {
        OnnxError::Model {
            path: path.display().to_string(),
            reason: format!("cannot read: {e}"),
        }
    })
}

struct Runtime {
    backend: OnnxBackend,
    environment: ort::environment::Environment,
}

static RUNTIME: OnceLock<Result<Runtime, OnnxError>> = OnceLock::new();

fn runtime() -> Result<&'static Runtime, OnnxError> {
    RUNTIME
        .get_or_init(|| {
            let backend = match std::env::var(ORT_DYLIB_PATH) {
                Ok(path) if !path.is_empty() => load_onnxruntime(Path::new(&path))?,
                _ => {
                    ort::set_api(ort_tract::api());
                    OnnxBackend::Tract
                }
            };
            let environment =
                ort::init()
                    .with_name("tactex")
                    .build()
                    .map_err(|e| OnnxError::Runtime {
                        path: backend.name(),
                        reason: format!("cannot create the environment: {e}"),
                    })?;
            Ok(Runtime {
                backend,
                environment,
            })
        })
        .as_ref()
        .map_err(Clone::clone)
}

/// Loads ONNX Runtime from `path` and hands its C API to `ort`; the library stays loaded for
/// the life of the process (the API's function pointers point into it).
fn load_onnxruntime(path: &Path) -> Result<OnnxBackend, OnnxError> {
    let fail = |reason: String| OnnxError::Runtime {
        path: path.display().to_string(),
        reason,
    };
    // Checks that the library loads and is at least the API version ort was built for.
    let _ = ort::init_from(path).map_err(|e| fail(e.to_string()))?;
    // SAFETY: the library passed ort's version check above; OrtGetApiBase is its C entry
    // point, and the handle is leaked so that the API table stays valid.
    unsafe {
        let library = libloading::Library::new(path).map_err(|e| fail(e.to_string()))?;
        let get_base: libloading::Symbol<unsafe extern "C" fn() -> *const ort::sys::OrtApiBase> =
            library
                .get(b"OrtGetApiBase")
                .map_err(|_| fail("does not export OrtGetApiBase".into()))?;
        let base = get_base();
        if base.is_null() {
            return Err(fail("OrtGetApiBase returned null".into()));
        }
        let version = std::ffi::CStr::from_ptr(((*base).GetVersionString)())
            .to_string_lossy()
            .into_owned();
        let api = ((*base).GetApi)(ort::MINOR_VERSION);
        if api.is_null() {
            return Err(fail(format!(
                "ONNX Runtime {version} does not offer API version {}",
                ort::MINOR_VERSION
            )));
        }
        ort::set_api((*api).clone());
        std::mem::forget(library);
        Ok(OnnxBackend::OnnxRuntime {
            library: path.to_path_buf(),
            version,
        })
    }
}

/// The backend this process runs learned models on (choosing it if no model was loaded yet).
pub fn backend() -> Result<OnnxBackend, OnnxError> {
    Ok(runtime()?.backend.clone())
}

/// An inference session for the ONNX model `bytes` (from `label`, a path or a name for errors).
pub fn open_session(label: &str, bytes: &[u8]) -> Result<Session, OnnxError> {
    let runtime = runtime()?;
    let bad = |reason: String| OnnxError::Model {
        path: label.to_string(),
        reason,
    };
    let mut builder = Session::builder(&runtime.environment)
        .map_err(|e| bad(format!("cannot start a session: {e}")))?;
    builder
        .commit_from_memory(bytes)
        .map_err(|e| bad(format!("not a model this runtime can run: {e}")))
}
