//! `tactex press`: one press of the GelSight gel into a primitive or a mesh at a chosen
//! fidelity, reported as JSON or text, with the gel maps written as 16-bit PNGs.

use crate::app::press_options::fields::*;
use crate::app::press_options::{PressOptions, ShapeKind};
use crate::app::single_press::{GridReport, PressReport, PressRequest, SolvedPress};
use crate::report::output::{OutputDir, write_json_atomic, write_png_atomic, write_png16_atomic};
use crate::report::tail::print_json_or_text;
use anyhow::{Result, bail};
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::contact::{GelFields, Grid};
use tactex_sim::render::gel::{DeviceChoice, open_renderer};

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct PressArgs {
    /// The object's shape.
    #[arg(long, value_parser = clap::builder::PossibleValuesParser::new(ShapeKind::NAMES))]
    shape: String,
    /// Sphere radius (mm, above 0 up to 500; default 10); an ellipsoid or box without
    /// --size-mm is a ball or cube of 2 radii.
    #[arg(long, value_parser = RADIUS_MM.parser())]
    radius_mm: Option<f64>,
    /// Ellipsoid or box size X,Y,Z (mm, full extents, each above 0 up to 1000); default a
    /// cube or ball of 2 radii.
    #[arg(long, value_delimiter = ',', value_parser = SIZE_MM.parser())]
    size_mm: Option<Vec<f64>>,
    /// Turn of the object about the pressing axis (degrees, -360 to 360).
    #[arg(long, default_value_t = 0.0, value_parser = YAW_DEG.parser())]
    yaw_deg: f64,
    /// Where on the pad the object's lowest point (a mesh: the middle of its top) stands,
    /// X,Y (mm, pad frame, origin at the pad's centre; within the pad). Default the centre.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = AT_MM.parser())]
    at_mm: Option<Vec<f64>>,
    /// Mesh file (.obj, .gltf, .glb) for --shape mesh, pressed at the middle of its top.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// Mesh units to metres for --mesh (scenes use metres; above 0 up to 1000; default 1).
    #[arg(long, value_parser = MESH_SCALE.parser())]
    mesh_scale: Option<f64>,
    /// Object hardness as in scene files: "35A", "55 00", "rigid".
    #[arg(long, conflicts_with = "modulus_mpa")]
    hardness: Option<String>,
    /// Object Young's modulus instead of a Shore value (MPa, above 0 up to 1e6).
    #[arg(long, value_parser = MODULUS_MPA.parser())]
    modulus_mpa: Option<f64>,
    /// Object Poisson ratio (0 to 0.5).
    #[arg(long, default_value_t = 0.45, value_parser = OBJECT_POISSON.parser())]
    object_poisson: f64,
    /// The sensor's travel past first touch (mm, 0 to 30): total approach of gel and object.
    #[arg(long, value_parser = DEPTH_MM.parser())]
    depth_mm: f64,
    /// Contact model.
    #[arg(long, default_value = "layer")]
    fidelity: String,
    /// Solver cell (mm, 0.02 to 5: a pad of 1,000 cells across down to 4); default from the
    /// contact's size.
    #[arg(long, value_parser = GRID_MM.parser())]
    grid_mm: Option<f64>,
    /// The contact solve stops when one step changes the pressure by less than this
    /// (relative, 1e-12 to 0.5); `bench contact` measures what looser values trade.
    #[arg(long, default_value_t = 1e-6, value_parser = TOLERANCE.parser())]
    tolerance: f64,
    /// Gel thickness (mm, 0.5 to 50); GelSight Mini ~4.
    #[arg(long, value_parser = GEL_THICKNESS_MM.parser())]
    gel_thickness_mm: Option<f64>,
    /// Gel Young's modulus (MPa, 0.01 to 50, as `ask` takes it); GelSight Mini ~0.15-0.45.
    #[arg(long, value_parser = GEL_MODULUS_MPA.parser())]
    gel_modulus_mpa: Option<f64>,
    /// Write the gel displacement and pressure maps (16-bit PNG + JSON sidecar), the
    /// rendered GelSight Mini frame (tactile.png) and a no-contact frame (reference.png) here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Device that renders tactile.png: auto (the default: a hardware GPU if there is one,
    /// else the CPU), gpu (any Vulkan adapter, software included) or cpu.
    #[arg(long)]
    device: Option<DeviceChoice>,
    /// Sensor profile whose gel, frame and optics the press uses (TOML); default the
    /// built-in GelSight Mini. The gel and marker flags override its values.
    #[arg(long)]
    sensor: Option<PathBuf>,
    /// Marker grid of the rendered frame, COLSxROWS (the Mini prints 9x7; 11x9 and others
    /// are common on other gels); 0x0 for none. Default: the profile's.
    #[arg(long)]
    marker_grid: Option<String>,
    /// Marker pitch (mm, above 0 up to 20). Default: the profile's.
    #[arg(long, value_parser = MARKER_PITCH_MM.parser())]
    marker_pitch_mm: Option<f64>,
    /// Seed of the rendered frame's camera noise.
    #[arg(long)]
    seed: Option<u32>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

impl PressArgs {
    /// The device that renders the frames.
    pub(crate) fn device(&self) -> DeviceChoice {
        self.device.unwrap_or(DeviceChoice::Auto)
    }

    /// The press as the library takes it: the flags, field for field.
    pub(crate) fn options(&self) -> PressOptions {
        PressOptions {
            shape: self.shape.parse().unwrap_or_default(),
            radius_mm: self.radius_mm,
            size_mm: self.size_mm.clone(),
            mesh: self.mesh.clone(),
            mesh_scale: self.mesh_scale,
            object: None,
            at_mm: self.at_mm.clone(),
            yaw_deg: self.yaw_deg,
            hardness: self.hardness.clone(),
            modulus_mpa: self.modulus_mpa,
            object_poisson: self.object_poisson,
            depth_mm: self.depth_mm,
            fidelity: self.fidelity.clone(),
            grid_mm: self.grid_mm,
            tolerance: self.tolerance,
            gel_thickness_mm: self.gel_thickness_mm,
            gel_modulus_mpa: self.gel_modulus_mpa,
            marker_grid: self.marker_grid.clone(),
            marker_pitch_mm: self.marker_pitch_mm,
            seed: self.seed.unwrap_or(0),
        }
    }
}

/// The press the flags describe, through the sensor `--sensor` names.
fn request(args: &PressArgs) -> Result<PressRequest> {
    let sensor = crate::app::load_sensor(args.sensor.as_deref())?;
    Ok(args.options().request(std::sync::Arc::new(sensor))?)
}

pub(crate) fn run(args: &PressArgs) -> Result<()> {
    let request = request(args)?;
    if args.out.is_none() {
        // These shape the rendered frame, which only --out writes: without it they would do
        // nothing, and the user would believe they had (their values are checked first).
        let frame_flags = [
            ("--marker-grid", args.marker_grid.is_some()),
            ("--marker-pitch-mm", args.marker_pitch_mm.is_some()),
            ("--seed", args.seed.is_some()),
            ("--device", args.device.is_some()),
        ];
        if let Some((flag, _)) = frame_flags.iter().find(|(_, given)| *given) {
            bail!("{flag}: sets the rendered frame, which press writes only with --out DIR");
        }
    }
    let mut press = request.solve()?;
    if let Some(out) = &args.out {
        // The renderer first: a missing device fails before any file is written.
        let choice = open_renderer(args.device())?;
        let mut out = OutputDir::create("--out", out)?;
        out.keep(args.sensor.iter().flat_map(|p| SensorProfile::files(p)));
        out.keep(args.mesh.clone());
        let dir = out.path();
        if let Some(note) = &choice.note {
            eprintln!("note: {note}");
        }
        let mut renderer = choice.renderer;
        write_maps(dir, &mut press)?;
        let (frame, reference) = press.render(&request, renderer.as_mut())?;
        write_png_atomic(&dir.join("tactile.png"), &frame)?;
        write_png_atomic(&dir.join("reference.png"), &reference)?;
        out.finish()?;
    }
    print_json_or_text(&press.report, args.json, || {
        print_report(&press.report);
        Ok(())
    })?;
    Ok(())
}

/// `v` rounded to `decimals`, a rounded-away negative zero shown as 0 ("-0.0000 mm" read as
/// a pull).
fn shown(v: f64, decimals: i32) -> f64 {
    let scale = 10f64.powi(decimals);
    (v * scale).round() / scale + 0.0
}

fn print_report(r: &PressReport) {
    let object = r
        .object_modulus_mpa
        .map_or("rigid".to_string(), |e| format!("{e:.3} MPa"));
    let article = match r.shape.chars().next() {
        Some('a' | 'e' | 'i' | 'o' | 'u') => "an",
        _ => "a",
    };
    println!(
        "{} press of {article} {} ({object}, {:.1} Shore A) {:.3} mm past first touch:",
        r.fidelity, r.shape, r.object_shore_a, r.depth_mm
    );
    println!("  force            {:>10.4} N", r.force_n);
    println!(
        "  contact          {:>10.4} mm radius, {:.3} mm^2",
        r.contact_radius_mm, r.contact_area_mm2
    );
    println!("  max pressure     {:>10.4} MPa", r.max_pressure_mpa);
    println!(
        "  gel indentation  {:>10.4} mm (of a {:.2} mm gel)",
        shown(r.gel_max_indentation_mm, 4),
        r.gel_thickness_mm
    );
    println!(
        "  object indent.   {:>10.4} mm",
        shown(r.object_max_indentation_mm, 4)
    );
    println!(
        "  solver           {} x {} cells of {:.4} mm, {} iterations, residual {:.1e}",
        r.grid.nx, r.grid.ny, r.grid.cell_mm, r.iterations, r.residual
    );
    for w in &r.warnings {
        println!("  warning: {w}");
    }
}

/// Scales a field to 16 bits: value = offset_mm + png * scale; the sidecar says how.
fn quantise(field: &[f64]) -> (Vec<u16>, f64, f64) {
    let lo = field.iter().copied().fold(f64::INFINITY, f64::min).min(0.0);
    let hi = field
        .iter()
        .copied()
        .fold(f64::NEG_INFINITY, f64::max)
        .max(0.0);
    let scale = if hi > lo { (hi - lo) / 65535.0 } else { 1.0 };
    let data = field
        .iter()
        .map(|v| ((v - lo) / scale).round().clamp(0.0, 65535.0) as u16)
        .collect();
    (data, lo, scale)
}

#[derive(Serialize)]
struct MapEntry {
    file: String,
    quantity: &'static str,
    unit: &'static str,
    /// value = offset + png_value * scale
    offset: f64,
    scale: f64,
    grid: GridReport,
}

fn write_maps(dir: &std::path::Path, press: &mut SolvedPress) -> Result<()> {
    // The gel moves beyond the solver grid: map it over the pad.
    let fields: GelFields = press.pad_fields();
    let (solution, report) = (&press.solution, &press.report);
    let maps: [(&str, &'static str, &'static str, &[f64], &Grid); 4] = [
        (
            "gel_normal.png",
            "gel normal displacement (into the gel)",
            "mm",
            &fields.normal_mm,
            &fields.grid,
        ),
        (
            "gel_lateral_x.png",
            "gel lateral displacement along x (image columns)",
            "mm",
            &fields.lateral_x_mm,
            &fields.grid,
        ),
        (
            "gel_lateral_y.png",
            "gel lateral displacement along y (image rows)",
            "mm",
            &fields.lateral_y_mm,
            &fields.grid,
        ),
        (
            "pressure.png",
            "contact pressure",
            "MPa",
            &solution.pressure_mpa,
            &solution.grid,
        ),
    ];
    let mut entries = Vec::new();
    for (file, quantity, unit, field, grid) in maps {
        let (data, offset, scale) = quantise(field);
        write_png16_atomic(&dir.join(file), grid.nx as u32, grid.ny as u32, data)?;
        entries.push(MapEntry {
            file: file.into(),
            quantity,
            unit,
            offset,
            scale,
            grid: grid.into(),
        });
    }
    write_json_atomic(
        &dir.join("maps.json"),
        &serde_json::json!({ "press": report, "maps": entries }),
    )
}
