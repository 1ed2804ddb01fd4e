//! The native half of the `tactex` Python package (`tactex._tactex`): thin calls into the
//! tactex library that the command line runs, so that a press, a generated sample or an
//! answer is the same from Python as from the CLI, byte for byte.
//!
//! Every call arrives as the library's own typed request, checked by the library against
//! the ranges the CLI's flags state: a press as typed keywords (`PressOptions`) through a
//! `Profile` loaded once, the longer calls (ask, calibrate, compare, read) as their request
//! in JSON text (`AskRequest`, ...), whose errors name the field. Long calls release the GIL and run on the Rust thread pool;
//! frames are handed to numpy without a copy.

use anyhow::Context;
use glam::DVec3;
use numpy::ndarray::{Array2, Array3, Array4};
use numpy::{IntoPyArray, PyArray4, PyReadonlyArray2};
use pyo3::exceptions::{PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use rayon::prelude::*;
use std::sync::{Arc, Mutex};
use tactex::app::error_kind::ErrorKind;
use tactex::app::flag_range::FieldError;
use tactex::app::press_options::PressOptions;
use tactex::app::press_steps::PressSteps;
use tactex::app::request_json::from_json;
use tactex::app::single_press::{PressPose, PressReport, PressShape};
use tactex::app::tactile_samples::{TactileSample, TactileSampleSource};
use tactex::cli::error_line;
use tactex::commands::ask::AskRequest;
use tactex::commands::read::ReadRequest;
use tactex::sim2real::calibrate::CalibrateRequest;
use tactex::sim2real::compare::CompareRequest;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::contact::HeightMap;
use tactex_sim::contact::{ContactSolution, ContactSolver, GelFields};
use tactex_sim::mesh::TriMesh;
use tactex_sim::render::gel::{DeviceChoice, open_renderer};

// As in the `tactex` binary: frames and fields are allocated and freed by the hundred per
// press, and glibc hands blocks this size back to the kernel on each free, to fault them in
// again on the next press (python/bench/press_overhead.py measures the difference).
#[global_allocator]
static ALLOCATOR: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// The thread pool native calls run on. rayon's global pool does not survive a fork (a
/// DataLoader worker is a forked copy of the training process, whose pool threads are not
/// copied), so each process makes its own pool, on first use after it was started or forked.
fn pool() -> PyResult<Arc<rayon::ThreadPool>> {
    static POOL: Mutex<Option<(u32, Arc<rayon::ThreadPool>)>> = Mutex::new(None);
    let pid = std::process::id();
    let mut slot = POOL.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
    if let Some((owner, pool)) = slot.as_ref()
        && *owner == pid
    {
        return Ok(pool.clone());
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .build()
        .map_err(|e| PyRuntimeError::new_err(format!("cannot start the thread pool: {e}")))?;
    let pool = Arc::new(pool);
    *slot = Some((pid, pool.clone()));
    Ok(pool)
}

/// Runs `work` without the GIL on this process's pool.
fn off_the_gil<T: Send>(
    py: Python<'_>,
    work: impl FnOnce() -> anyhow::Result<T> + Send,
) -> PyResult<T> {
    let pool = pool()?;
    py.detach(|| pool.install(work)).map_err(to_py)
}

/// An error as a Python exception carrying the CLI's one-line message, by the kind of
/// mistake its chain holds: FileNotFoundError for a missing file, ValueError for bad input,
/// RuntimeError for a failure of the machinery.
fn to_py(e: anyhow::Error) -> PyErr {
    let line = error_line(&e);
    match ErrorKind::of(&e) {
        ErrorKind::Missing => PyFileNotFoundError::new_err(line),
        ErrorKind::BadInput => PyValueError::new_err(line),
        ErrorKind::Failure => PyRuntimeError::new_err(line),
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

/// The caller's own geometry, from numpy: a mesh (vertices N x 3 in its units, z up; faces
/// M x 3 indices) or a height map (H x W mm, larger nearer the gel, NaN where absent).
/// Checked here so that an error names the Python keyword. A dict with every key (None where
/// not given).
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct Geometry<'py> {
    vertices: Option<PyReadonlyArray2<'py, f64>>,
    faces: Option<PyReadonlyArray2<'py, i64>>,
    mesh_scale: Option<f64>,
    height_map_mm: Option<PyReadonlyArray2<'py, f64>>,
    mm_per_px: Option<f64>,
}

impl Geometry<'_> {
    fn shape(&self) -> PyResult<Option<PressShape>> {
        let bad = |m: String| Err(PyValueError::new_err(m));
        if let Some(map) = &self.height_map_mm {
            let map = map.as_array();
            let (height, width) = map.dim();
            let Some(mm_per_px) = self.mm_per_px else {
                return bad("mm_per_px: needed with height_map_mm".into());
            };
            return Ok(Some(PressShape::HeightMap(HeightMap {
                heights_mm: map.iter().copied().collect(),
                width,
                height,
                mm_per_px,
            })));
        }
        let (Some(vertices), Some(faces)) = (&self.vertices, &self.faces) else {
            return Ok(None);
        };
        let (vertices, faces) = (vertices.as_array(), faces.as_array());
        if vertices.ncols() != 3 {
            return bad(format!(
                "mesh: vertices must be N x 3, got {:?}",
                vertices.dim()
            ));
        }
        if faces.ncols() != 3 {
            return bad(format!(
                "mesh: faces must be M x 3 (triangles), got {:?}",
                faces.dim()
            ));
        }
        let n = vertices.nrows() as i64;
        if let Some(i) = faces.iter().find(|&&i| i < 0 || i >= n) {
            return bad(format!("mesh: face index {i} is outside the {n} vertices"));
        }
        // Checked with the press (`PressOptions::request`), as a file's --mesh-scale is.
        let scale = self.mesh_scale.unwrap_or(1.0);
        Ok(Some(PressShape::Triangles {
            mesh: TriMesh {
                vertices: vertices
                    .rows()
                    .into_iter()
                    .map(|v| DVec3::new(v[0], v[1], v[2]))
                    .collect(),
                triangles: faces
                    .rows()
                    .into_iter()
                    .map(|f| [f[0] as u32, f[1] as u32, f[2] as u32])
                    .collect(),
            },
            scale,
            name: "mesh".into(),
        }))
    }
}

/// A sensor profile loaded once: the built-in GelSight Mini, or a profile file (TOML, as
/// `tactex calibrate` writes it). Presses through it do not read the file again.
#[pyclass(frozen, module = "tactex._tactex")]
struct Profile {
    sensor: Arc<SensorProfile>,
}

#[pymethods]
impl Profile {
    #[new]
    #[pyo3(signature = (path=None))]
    fn new(path: Option<std::path::PathBuf>) -> PyResult<Self> {
        // Named as `Sensor(profile)` names it.
        let sensor = match path {
            Some(p) => tactex::app::sensor::load_profile(&p)
                .context("profile")
                .map_err(to_py)?,
            None => SensorProfile::gelsight_mini(),
        };
        Ok(Self {
            sensor: Arc::new(sensor),
        })
    }

    /// The profile's name and content hash, as every output names it.
    #[getter]
    fn id(&self) -> String {
        self.sensor.id().to_string()
    }

    /// The profile's name and SHA-256 as data sets and model cards record them (JSON text).
    #[getter]
    fn profile_id(&self) -> PyResult<String> {
        serde_json::to_string(&self.sensor.id()).map_err(|e| PyRuntimeError::new_err(e.to_string()))
    }

    #[getter]
    fn name(&self) -> String {
        self.sensor.name().to_string()
    }

    /// Frame size (width, height) in pixels.
    #[getter]
    fn size(&self) -> (u32, u32) {
        (self.sensor.spec.width_px, self.sensor.spec.height_px)
    }

    #[getter]
    fn mm_per_px(&self) -> f64 {
        self.sensor.spec.mm_per_px
    }

    #[getter]
    fn gel_modulus_mpa(&self) -> f64 {
        self.sensor.spec.gel.modulus_mpa
    }

    #[getter]
    fn gel_thickness_mm(&self) -> f64 {
        self.sensor.spec.gel.thickness_mm
    }

    /// Marker grid (columns, rows).
    #[getter]
    fn markers(&self) -> (u32, u32) {
        (self.sensor.spec.markers.cols, self.sensor.spec.markers.rows)
    }
}

/// `Sensor.press`'s keywords, each already a number, text or path (python/tactex makes them
/// so, naming the keyword when it cannot); the library checks their values
/// (`PressOptions::request`). A dict with every key, None where not given.
#[derive(FromPyObject)]
#[pyo3(from_item_all)]
struct PressKeywords {
    shape: String,
    radius_mm: Option<f64>,
    size_mm: Option<Vec<f64>>,
    mesh: Option<std::path::PathBuf>,
    mesh_scale: Option<f64>,
    at_mm: Option<Vec<f64>>,
    yaw_deg: Option<f64>,
    hardness: Option<String>,
    modulus_mpa: Option<f64>,
    object_poisson: Option<f64>,
    depth_mm: f64,
    fidelity: String,
    grid_mm: Option<f64>,
    tolerance: Option<f64>,
    gel_thickness_mm: Option<f64>,
    gel_modulus_mpa: Option<f64>,
    marker_grid: Option<String>,
    marker_pitch_mm: Option<f64>,
    seed: u32,
}

impl PressKeywords {
    /// The library's press options, with the caller's own object when it gave one.
    fn options(self, object: Option<PressShape>) -> PyResult<PressOptions> {
        let defaults = PressOptions::default();
        let shape = self
            .shape
            .parse()
            .map_err(|e: FieldError| PyValueError::new_err(e.to_string()))?;
        Ok(PressOptions {
            shape,
            radius_mm: self.radius_mm,
            size_mm: self.size_mm,
            mesh: self.mesh,
            mesh_scale: if object.is_some() {
                None
            } else {
                self.mesh_scale
            },
            object,
            at_mm: self.at_mm,
            yaw_deg: self.yaw_deg.unwrap_or(defaults.yaw_deg),
            hardness: self.hardness,
            modulus_mpa: self.modulus_mpa,
            object_poisson: self.object_poisson.unwrap_or(defaults.object_poisson),
            depth_mm: self.depth_mm,
            fidelity: self.fidelity,
            grid_mm: self.grid_mm,
            tolerance: self.tolerance.unwrap_or(defaults.tolerance),
            gel_thickness_mm: self.gel_thickness_mm,
            gel_modulus_mpa: self.gel_modulus_mpa,
            marker_grid: self.marker_grid,
            marker_pitch_mm: self.marker_pitch_mm,
            seed: self.seed,
        })
    }
}

/// The press `options` describe, on the caller's own object when it gave one.
fn press_options(options: PressKeywords, geometry: Option<Geometry<'_>>) -> PyResult<PressOptions> {
    let object = geometry.map(|g| g.shape()).transpose()?.flatten();
    options.options(object)
}

/// A press's results, ready for numpy: the report (JSON text), the frame (and the
/// no-contact frame where the call draws one), the gel's fields over the pad and the
/// pressure over the solver grid (float32, rows x columns) with their grids, and the
/// library's own time for it.
struct PressArrays {
    report: String,
    frame: Array3<u8>,
    reference: Option<Array3<u8>>,
    fields: [(&'static str, Array2<f32>); 3],
    pressure: Array2<f32>,
    grids: [(f64, [f64; 2]); 2],
    library_s: f64,
}

impl PressArrays {
    fn new(
        report: &PressReport,
        fields: &GelFields,
        solution: &ContactSolution,
        frame: image::RgbImage,
        reference: Option<image::RgbImage>,
        library_s: f64,
    ) -> anyhow::Result<Self> {
        let g = &fields.grid;
        let s = &solution.grid;
        Ok(Self {
            report: serde_json::to_string(report).context("serialising the report")?,
            frame: frame_array(frame),
            reference: reference.map(frame_array),
            fields: [
                ("gel_normal_mm", field_array(&fields.normal_mm, g.nx, g.ny)),
                (
                    "gel_lateral_x_mm",
                    field_array(&fields.lateral_x_mm, g.nx, g.ny),
                ),
                (
                    "gel_lateral_y_mm",
                    field_array(&fields.lateral_y_mm, g.nx, g.ny),
                ),
            ],
            pressure: field_array(&solution.pressure_mpa, s.nx, s.ny),
            grids: [
                (g.cell_mm, [g.origin_mm.x, g.origin_mm.y]),
                (s.cell_mm, [s.origin_mm.x, s.origin_mm.y]),
            ],
            library_s,
        })
    }

    fn into_dict(self, py: Python<'_>) -> PyResult<Bound<'_, PyDict>> {
        let out = PyDict::new(py);
        out.set_item("report", self.report)?;
        out.set_item("library_s", self.library_s)?;
        out.set_item("frame", self.frame.into_pyarray(py))?;
        if let Some(reference) = self.reference {
            out.set_item("reference", reference.into_pyarray(py))?;
        }
        let fields = PyDict::new(py);
        for (name, array) in self.fields {
            fields.set_item(name, array.into_pyarray(py))?;
        }
        fields.set_item("pressure_mpa", self.pressure.into_pyarray(py))?;
        out.set_item("fields", fields)?;
        out.set_item("field_grid", self.grids[0])?;
        out.set_item("pressure_grid", self.grids[1])?;
        Ok(out)
    }
}

fn device_choice(device: &str) -> PyResult<DeviceChoice> {
    device
        .parse()
        .map_err(|e: String| PyValueError::new_err(format!("device: {e}")))
}

/// One press through `profile`: `options` are `Sensor.press`'s keywords, `geometry` the
/// caller's own object if any, `device` the renderer (auto, gpu, cpu). Returns the report
/// (JSON text), the pressed frame and the no-contact frame (H x W x 3 uint8), and the gel's
/// fields over the pad and the pressure over the solver grid (float32, rows x columns) with
/// their grids.
#[pyfunction]
#[pyo3(signature = (profile, options, device, geometry=None))]
fn press<'py>(
    py: Python<'py>,
    profile: PyRef<'py, Profile>,
    options: PressKeywords,
    device: &str,
    geometry: Option<Geometry<'py>>,
) -> PyResult<Bound<'py, PyDict>> {
    let device = device_choice(device)?;
    let options = press_options(options, geometry)?;
    let sensor = profile.sensor.clone();
    let solved = off_the_gil(py, || -> anyhow::Result<PressArrays> {
        // The library's own time for the press (the request checked, solved and rendered),
        // against which the binding's cost is measured (python/bench/press_overhead.py).
        let started = std::time::Instant::now();
        let request = options.request(sensor)?;
        let mut press = request.solve()?;
        let mut renderer = open_renderer(device)?.renderer;
        let fields = press.pad_fields();
        let (frame, reference) = press.render(&request, renderer.as_mut())?;
        let library_s = started.elapsed().as_secs_f64();
        PressArrays::new(
            &press.report,
            &fields,
            &press.solution,
            frame,
            Some(reference),
            library_s,
        )
    });
    solved?.into_dict(py)
}

/// One object pressed step by step along a path the caller drives (`Sensor.contact`): the
/// object read once, the solver's kernels and the optics kept between steps.
#[pyclass(frozen, module = "tactex._tactex")]
struct Steps {
    steps: Mutex<PressSteps>,
    reference: Array3<u8>,
}

#[pymethods]
impl Steps {
    /// The no-contact frame (H x W x 3 uint8) the steps are read against.
    #[getter]
    fn reference<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray3<u8>> {
        numpy::PyArray3::from_array(py, &self.reference)
    }

    /// The object at (x_mm, y_mm, yaw_deg) on the pad, the sensor `depth_mm` past first
    /// touch: a press's arrays and report, as `press` returns them, without the reference.
    fn step<'py>(
        &self,
        py: Python<'py>,
        x_mm: f64,
        y_mm: f64,
        yaw_deg: f64,
        depth_mm: f64,
    ) -> PyResult<Bound<'py, PyDict>> {
        let done = off_the_gil(py, || -> anyhow::Result<PressArrays> {
            let started = std::time::Instant::now();
            let mut steps = self.steps.lock().unwrap_or_else(|p| p.into_inner());
            let pose = PressPose {
                at_mm: [x_mm, y_mm],
                yaw_deg,
            };
            let step = steps.step(pose, depth_mm)?;
            let library_s = started.elapsed().as_secs_f64();
            PressArrays::new(
                &step.report,
                &step.fields,
                &step.solution,
                step.frame,
                None,
                library_s,
            )
        });
        done?.into_dict(py)
    }
}

/// The object `options` and `geometry` describe through `profile`, ready to be pressed step
/// by step (`options`' pose and depth are the first step's default; each step gives its own).
#[pyfunction]
#[pyo3(signature = (profile, options, device, geometry=None))]
fn contact<'py>(
    py: Python<'py>,
    profile: PyRef<'py, Profile>,
    options: PressKeywords,
    device: &str,
    geometry: Option<Geometry<'py>>,
) -> PyResult<Steps> {
    let device = device_choice(device)?;
    let options = press_options(options, geometry)?;
    let sensor = profile.sensor.clone();
    off_the_gil(py, || -> anyhow::Result<Steps> {
        let request = options.request(sensor)?;
        let renderer = open_renderer(device)?.renderer;
        let steps = PressSteps::new(request, renderer)?;
        let reference = frame_array(steps.reference().clone());
        Ok(Steps {
            steps: Mutex::new(steps),
            reference,
        })
    })
}

/// The paper's press protocol on one object through `profile` (`options`: `Sensor.press`'s
/// keywords; `depth_mm` is not read, the protocol decides the travel): frames [9, H, W, 3]
/// uint8 (the no-contact reference, then the 8 recorded frames) and the press's facts (JSON
/// text).
#[pyfunction]
#[pyo3(signature = (profile, options, phase_mm, geometry=None))]
fn press_sequence<'py>(
    py: Python<'py>,
    profile: PyRef<'py, Profile>,
    options: PressKeywords,
    phase_mm: f64,
    geometry: Option<Geometry<'py>>,
) -> PyResult<(Bound<'py, PyArray4<u8>>, String)> {
    let options = press_options(options, geometry)?;
    let sensor = profile.sensor.clone();
    let done = off_the_gil(py, || -> anyhow::Result<(Array4<u8>, String)> {
        let request = options.request(sensor)?;
        let (press, images) = request.press_sequence(phase_mm)?;
        let f = &press.frames;
        let facts = serde_json::json!({
            "travel_mm": f.iter().map(|x| x.travel_mm).collect::<Vec<_>>(),
            "approach_mm": f.iter().map(|x| x.approach_mm).collect::<Vec<_>>(),
            "force_n": f.iter().map(|x| x.force_n).collect::<Vec<_>>(),
            "contact_radius_mm": f.iter().map(|x| x.contact_radius_mm).collect::<Vec<_>>(),
            "gel_max_indentation_mm": f.iter().map(|x| x.gel_max_indentation_mm).collect::<Vec<_>>(),
            "search_steps": press.search_steps,
            "contact": press.contact,
            "warnings": press.warnings,
            "fidelity": request.fidelity.name(),
            "sensor": request.sensor.id(),
        });
        Ok((stack(images), serde_json::to_string(&facts)?))
    });
    let (frames, facts) = done?;
    Ok((frames.into_pyarray(py), facts))
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
    let drawn = off_the_gil(py, || -> anyhow::Result<Vec<(String, Array4<u8>)>> {
        let source = TactileSampleSource::new(&fidelity, &shapes, sensor.as_deref(), seed)?;
        indices
            .par_iter()
            .map_init(ContactSolver::new, |solver, &i| {
                let sample = source.sample(solver, i, true)?;
                Ok((labels(&sample)?, frames(sample)))
            })
            .collect()
    });
    let drawn = drawn?;
    Ok(drawn
        .into_iter()
        .map(|(labels, frames)| (labels, frames.into_pyarray(py)))
        .collect())
}

fn labels(sample: &TactileSample) -> anyhow::Result<String> {
    Ok(serde_json::to_string(&sample.labels(Vec::new()))?)
}

fn frames(sample: TactileSample) -> Array4<u8> {
    stack(sample.images.expect("rendered on the CPU"))
}

/// Frames of one size as one [N, H, W, 3] array.
fn stack(images: Vec<image::RgbImage>) -> Array4<u8> {
    let (w, h) = images[0].dimensions();
    let n = images.len();
    let raw: Vec<u8> = images.into_iter().flat_map(|i| i.into_raw()).collect();
    Array4::from_shape_vec((n, h as usize, w as usize, 3), raw)
        .expect("every frame of a sample has the sensor's size")
}

/// The answer to the question `request` holds (an `AskRequest` as JSON text: `tactex.ask`'s
/// keywords), as JSON text, as `ask --json` prints it.
#[pyfunction]
fn ask(py: Python<'_>, request: &str) -> PyResult<String> {
    let request: AskRequest = from_json(request).map_err(|e| to_py(e.into()))?;
    off_the_gil(py, || -> anyhow::Result<String> {
        let answer = tactex::commands::ask::answer(&request)?;
        serde_json::to_string_pretty(&answer).context("serialising the answer")
    })
}

/// Fits and writes a sensor profile (`request`: a `CalibrateRequest` as JSON text,
/// `tactex.calibrate`'s keywords); returns what `calibrate --json` prints (JSON text).
#[pyfunction]
fn calibrate(py: Python<'_>, request: &str) -> PyResult<String> {
    let args: CalibrateRequest = from_json(request).map_err(|e| to_py(e.into()))?;
    off_the_gil(py, || -> anyhow::Result<String> {
        let fit = tactex::sim2real::calibrate::calibrate(&args)?;
        serde_json::to_string_pretty(&fit).context("serialising the calibration")
    })
}

/// Ball presses or a recorded session rebuilt in the twin and scored (`request`: a
/// `CompareRequest` as JSON text, `tactex.compare`'s keywords); returns what `compare
/// --json` prints (JSON text).
#[pyfunction]
fn compare(py: Python<'_>, request: &str) -> PyResult<String> {
    let args: CompareRequest = from_json(request).map_err(|e| to_py(e.into()))?;
    off_the_gil(py, || -> anyhow::Result<String> {
        let report = tactex::sim2real::compare::compare(&args)?;
        serde_json::to_string_pretty(&report).context("serialising the comparison")
    })
}

/// One frame read through a sensor's optics (`request`: a `ReadRequest` as JSON text,
/// `tactex.read`'s keywords). Returns the report (JSON text, what `read --json` prints) and
/// the indentation map (mm into the gel, float32, H x W); `out` writes the picture as the
/// command does.
#[pyfunction]
fn read<'py>(py: Python<'py>, request: &str) -> PyResult<Bound<'py, PyDict>> {
    let args: ReadRequest = from_json(request).map_err(|e| to_py(e.into()))?;
    let (report, map) = off_the_gil(py, || -> anyhow::Result<(String, Array2<f32>)> {
        let (report, reading, image) = tactex::commands::read::read(&args)?;
        if let Some(out) = &args.out {
            tactex::commands::read::write_picture(out, &image, &reading)?;
        }
        let report = serde_json::to_string_pretty(&report).context("serialising the reading")?;
        Ok((
            report,
            field_array(&reading.indentation_mm, reading.width, reading.height),
        ))
    })?;
    let out = PyDict::new(py);
    out.set_item("report", report)?;
    out.set_item("indentation_mm", map.into_pyarray(py))?;
    Ok(out)
}

/// Threads of the Rust pool that draws samples (RAYON_NUM_THREADS, else one per core).
#[pyfunction]
fn threads() -> PyResult<usize> {
    Ok(pool()?.current_num_threads())
}

#[pymodule]
fn _tactex(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(press, m)?)?;
    m.add_function(wrap_pyfunction!(press_sequence, m)?)?;
    m.add_function(wrap_pyfunction!(generate_samples, m)?)?;
    m.add_function(wrap_pyfunction!(ask, m)?)?;
    m.add_function(wrap_pyfunction!(calibrate, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_class::<Profile>()?;
    m.add_class::<Steps>()?;
    m.add_function(wrap_pyfunction!(contact, m)?)?;
    m.add_function(wrap_pyfunction!(threads, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
