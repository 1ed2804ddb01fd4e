//! The native half of the `tactex` Python package (`tactex._tactex`): thin calls into the
//! tactex library that the command line runs, so that a press, a generated sample or an
//! answer is the same from Python as from the CLI, byte for byte.
//!
//! Arguments arrive as the CLI's own flags (the Python layer, python/tactex/, builds them
//! from keyword arguments), so they are checked by the same parser with the same one-line
//! messages. Long calls release the GIL and run on the Rust thread pool; frames are handed
//! to numpy without a copy.

use anyhow::Context;
use clap::Parser;
use numpy::ndarray::{Array2, Array3, Array4};
use numpy::{IntoPyArray, PyArray4};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use tactex::app::tactile_samples::{TactileSample, TactileSampleSource};
use tactex::cli::{Cli, Command, error_line};
use tactex_sim::contact::ContactSolver;
use tactex_sim::render::gel::open_renderer;

/// An error as a Python exception carrying the CLI's one-line message: FileNotFoundError
/// when a file is missing, ValueError when an argument is bad, RuntimeError otherwise.
fn to_py(e: anyhow::Error) -> PyErr {
    let line = error_line(&e);
    let missing = e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::NotFound)
    }) || line.contains("No such file or directory");
    if missing {
        PyFileNotFoundError::new_err(line)
    } else if line.starts_with("--") || line.starts_with("prompt") || is_input_error(&line) {
        PyValueError::new_err(line)
    } else {
        PyRuntimeError::new_err(line)
    }
}

/// Messages that name what was given wrong rather than a failure of the machinery.
fn is_input_error(line: &str) -> bool {
    [
        "invalid value",
        "unexpected argument",
        "required",
        "cannot be used with",
        "names no known fruit",
        "is not",
        "must be",
    ]
    .iter()
    .any(|p| line.contains(p))
}

/// The CLI parses `argv` (without the program name); a parse error is one line, as
/// `tactex` prints it.
fn parse(argv: Vec<String>) -> PyResult<Command> {
    let all = std::iter::once("tactex".to_string()).chain(argv);
    match Cli::try_parse_from(all) {
        Ok(cli) => Ok(cli.command),
        Err(e) => {
            let text = e.render().to_string();
            let line = text.lines().next().unwrap_or("invalid arguments");
            Err(PyValueError::new_err(
                line.trim_start_matches("error: ").to_string(),
            ))
        }
    }
}

fn frame_array(image: image::RgbImage) -> Array3<u8> {
    let (w, h) = image.dimensions();
    Array3::from_shape_vec((h as usize, w as usize, 3), image.into_raw())
        .expect("an RGB image is height x width x 3")
}

fn field_array(values: &[f64], nx: usize, ny: usize) -> Array2<f32> {
    Array2::from_shape_vec((ny, nx), values.iter().map(|v| *v as f32).collect())
        .expect("a field has one value per grid cell")
}

/// One press: `argv` are `tactex press` flags. Returns the report (JSON text), the pressed
/// frame and the no-contact frame (H x W x 3 uint8), and the gel's fields over the pad and
/// the pressure over the solver grid (float32, rows x columns) with their grids.
#[pyfunction]
fn press(py: Python<'_>, argv: Vec<String>) -> PyResult<Bound<'_, PyDict>> {
    let Command::Press(args) = parse(std::iter::once("press".into()).chain(argv).collect())? else {
        unreachable!("the argv starts with press")
    };
    let device = args.device();
    let solved = py.detach(|| -> anyhow::Result<_> {
        let request = tactex::commands::press::request(&args)?;
        let mut press = request.solve()?;
        let mut renderer = open_renderer(device)?.renderer;
        let fields = press.pad_fields();
        let (frame, reference) = press.render(&request, renderer.as_mut())?;
        let report = serde_json::to_string(&press.report).context("serialising the report")?;
        let g = &fields.grid;
        let arrays = [
            ("gel_normal_mm", field_array(&fields.normal_mm, g.nx, g.ny)),
            (
                "gel_lateral_x_mm",
                field_array(&fields.lateral_x_mm, g.nx, g.ny),
            ),
            (
                "gel_lateral_y_mm",
                field_array(&fields.lateral_y_mm, g.nx, g.ny),
            ),
        ];
        let s = &press.solution;
        let pressure = field_array(&s.pressure_mpa, s.grid.nx, s.grid.ny);
        let grids = [
            (g.cell_mm, [g.origin_mm.x, g.origin_mm.y]),
            (s.grid.cell_mm, [s.grid.origin_mm.x, s.grid.origin_mm.y]),
        ];
        Ok((
            report,
            frame_array(frame),
            frame_array(reference),
            arrays,
            pressure,
            grids,
        ))
    });
    let (report, frame, reference, arrays, pressure, grids) = solved.map_err(to_py)?;
    let out = PyDict::new(py);
    out.set_item("report", report)?;
    out.set_item("frame", frame.into_pyarray(py))?;
    out.set_item("reference", reference.into_pyarray(py))?;
    let fields = PyDict::new(py);
    for (name, array) in arrays {
        fields.set_item(name, array.into_pyarray(py))?;
    }
    fields.set_item("pressure_mpa", pressure.into_pyarray(py))?;
    out.set_item("fields", fields)?;
    out.set_item("field_grid", (grids[0].0, grids[0].1))?;
    out.set_item("pressure_grid", (grids[1].0, grids[1].1))?;
    Ok(out)
}

/// What a data set of `datagen tactile` would hold at `indices`, drawn in parallel: each
/// sample's labels (the manifest line without its files, JSON text) and its frames
/// [9, H, W, 3] uint8, the no-contact reference first.
#[pyfunction]
#[pyo3(signature = (fidelity, shapes, sensor, seed, indices))]
fn generate_samples<'py>(
    py: Python<'py>,
    fidelity: String,
    shapes: Vec<String>,
    sensor: Option<std::path::PathBuf>,
    seed: u64,
    indices: Vec<u64>,
) -> PyResult<Vec<(String, Bound<'py, PyArray4<u8>>)>> {
    let drawn = py.detach(|| -> anyhow::Result<Vec<(String, Array4<u8>)>> {
        let source = TactileSampleSource::new(&fidelity, &shapes, sensor.as_deref(), seed)?;
        indices
            .par_iter()
            .map_init(ContactSolver::new, |solver, &i| {
                let sample = source.sample(solver, i, true)?;
                Ok((labels(&sample)?, frames(sample)))
            })
            .collect()
    });
    let drawn = drawn.map_err(to_py)?;
    Ok(drawn
        .into_iter()
        .map(|(labels, frames)| (labels, frames.into_pyarray(py)))
        .collect())
}

fn labels(sample: &TactileSample) -> anyhow::Result<String> {
    let mut value = serde_json::to_value(sample.labels(Vec::new()))?;
    if let Some(map) = value.as_object_mut() {
        map.remove("files");
    }
    Ok(serde_json::to_string(&value)?)
}

fn frames(sample: TactileSample) -> Array4<u8> {
    let images = sample.images.expect("rendered on the CPU");
    let (w, h) = images[0].dimensions();
    let n = images.len();
    let raw: Vec<u8> = images.into_iter().flat_map(|i| i.into_raw()).collect();
    Array4::from_shape_vec((n, h as usize, w as usize, 3), raw)
        .expect("every frame of a sample has the sensor's size")
}

/// The answer of `tactex ask` (flags in `argv`, the prompt last) as JSON text, as
/// `ask --json` prints it.
#[pyfunction]
fn ask(py: Python<'_>, argv: Vec<String>) -> PyResult<String> {
    let Command::Ask(args) = parse(std::iter::once("ask".into()).chain(argv).collect())? else {
        unreachable!("the argv starts with ask")
    };
    py.detach(|| -> anyhow::Result<String> {
        let answer = tactex::commands::ask::answer(&args)?;
        serde_json::to_string_pretty(&answer).context("serialising the answer")
    })
    .map_err(to_py)
}

/// A sensor profile's identity and geometry: the built-in GelSight Mini, or the profile
/// file at `path`.
#[pyfunction]
#[pyo3(signature = (path=None))]
fn sensor_info(py: Python<'_>, path: Option<std::path::PathBuf>) -> PyResult<Bound<'_, PyDict>> {
    let profile = tactex::app::load_sensor(path.as_deref()).map_err(to_py)?;
    let out = PyDict::new(py);
    let spec = &profile.spec;
    out.set_item("id", profile.id().to_string())?;
    out.set_item("name", profile.name())?;
    out.set_item("width", spec.width_px)?;
    out.set_item("height", spec.height_px)?;
    out.set_item("mm_per_px", spec.mm_per_px)?;
    out.set_item("gel_modulus_mpa", spec.gel.modulus_mpa)?;
    out.set_item("gel_thickness_mm", spec.gel.thickness_mm)?;
    out.set_item("markers", (spec.markers.cols, spec.markers.rows))?;
    Ok(out)
}

/// Threads of the Rust pool that draws samples (RAYON_NUM_THREADS, else one per core).
#[pyfunction]
fn threads() -> usize {
    rayon::current_num_threads()
}

#[pymodule]
fn _tactex(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(press, m)?)?;
    m.add_function(wrap_pyfunction!(generate_samples, m)?)?;
    m.add_function(wrap_pyfunction!(ask, m)?)?;
    m.add_function(wrap_pyfunction!(sensor_info, m)?)?;
    m.add_function(wrap_pyfunction!(threads, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
