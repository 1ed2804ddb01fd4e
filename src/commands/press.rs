//! `tactex press`: one press of the GelSight gel into a primitive or a mesh at a chosen
//! fidelity, reported as JSON or text, with the gel maps written as 16-bit PNGs.

use crate::app::flag_range::{above, within};
use crate::app::single_press::{
    GridReport, PressPose, PressReport, PressRequest, PressShape, SolvedPress, parse_marker_grid,
};
use crate::report::output::{OutputDir, write_json_atomic, write_png_atomic, write_png16_atomic};
use anyhow::{Context, Result, bail};
use clap::{Args, ValueEnum};
use serde::Serialize;
use std::path::PathBuf;
use tactex_core::hardness::scale::Hardness;
use tactex_core::tactile::sensor_profile::SensorProfile;
use tactex_sim::contact::{Fidelity, GelFields, Grid};
use tactex_sim::render::gel::{DeviceChoice, open_renderer};

#[derive(Clone, Copy, Debug, ValueEnum)]
pub enum Shape {
    Sphere,
    Ellipsoid,
    Box,
    Mesh,
}

#[derive(Args, Debug)]
#[command(allow_negative_numbers = true)]
pub struct PressArgs {
    /// The object's shape.
    #[arg(long, value_enum)]
    shape: Shape,
    /// Sphere radius (mm, above 0 up to 500; default 10); an ellipsoid or box without
    /// --size-mm is a ball or cube of 2 radii.
    #[arg(long, value_parser = above(0.0, 500.0))]
    radius_mm: Option<f64>,
    /// Ellipsoid or box size X,Y,Z (mm, full extents, each above 0 up to 1000); default a
    /// cube or ball of 2 radii.
    #[arg(long, value_delimiter = ',', value_parser = above(0.0, 1000.0))]
    size_mm: Option<Vec<f64>>,
    /// Turn of the object about the pressing axis (degrees, -360 to 360).
    #[arg(long, default_value_t = 0.0, value_parser = within(-360.0, 360.0))]
    yaw_deg: f64,
    /// Where on the pad the object's lowest point (a mesh: the middle of its top) stands,
    /// X,Y (mm, pad frame, origin at the pad's centre; within the pad). Default the centre.
    #[arg(long, value_delimiter = ',', allow_hyphen_values = true, value_parser = within(-100.0, 100.0))]
    at_mm: Option<Vec<f64>>,
    /// Mesh file (.obj, .gltf, .glb) for --shape mesh, pressed at the middle of its top.
    #[arg(long)]
    mesh: Option<PathBuf>,
    /// Mesh units to metres for --mesh (scenes use metres; above 0 up to 1000; default 1).
    #[arg(long, value_parser = above(0.0, 1000.0))]
    mesh_scale: Option<f64>,
    /// Object hardness as in scene files: "35A", "55 00", "rigid".
    #[arg(long, conflicts_with = "modulus_mpa")]
    hardness: Option<String>,
    /// Object Young's modulus instead of a Shore value (MPa, above 0 up to 1e6).
    #[arg(long, value_parser = above(0.0, 1e6))]
    modulus_mpa: Option<f64>,
    /// Object Poisson ratio (0 to 0.5).
    #[arg(long, default_value_t = 0.45, value_parser = within(0.0, 0.5))]
    object_poisson: f64,
    /// The sensor's travel past first touch (mm, 0 to 30): total approach of gel and object.
    #[arg(long, value_parser = within(0.0, 30.0))]
    depth_mm: f64,
    /// Contact model.
    #[arg(long, default_value = "layer")]
    fidelity: String,
    /// Solver cell (mm, 0.02 to 5: a pad of 1,000 cells across down to 4); default from the
    /// contact's size.
    #[arg(long, value_parser = within(0.02, 5.0))]
    grid_mm: Option<f64>,
    /// The contact solve stops when one step changes the pressure by less than this
    /// (relative, 1e-12 to 0.5); `bench contact` measures what looser values trade.
    #[arg(long, default_value_t = 1e-6, value_parser = within(1e-12, 0.5))]
    tolerance: f64,
    /// Gel thickness (mm, 0.5 to 50); GelSight Mini ~4.
    #[arg(long, value_parser = within(tactex_core::tactile::sensor_profile::MIN_GEL_THICKNESS_MM, 50.0))]
    gel_thickness_mm: Option<f64>,
    /// Gel Young's modulus (MPa, 0.01 to 50, as `ask` takes it); GelSight Mini ~0.15-0.45.
    #[arg(long, value_parser = within(0.01, 50.0))]
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
    #[arg(long, value_parser = above(0.0, 20.0))]
    marker_pitch_mm: Option<f64>,
    /// Seed of the rendered frame's camera noise.
    #[arg(long)]
    seed: Option<u32>,
    /// Print one JSON object on stdout.
    #[arg(long)]
    json: bool,
}

/// Sphere radius when --radius-mm is not given (mm).
const DEFAULT_RADIUS_MM: f64 = 10.0;

fn shape(args: &PressArgs) -> Result<PressShape> {
    refuse_unused_flags(args)?;
    let radius_mm = args.radius_mm.unwrap_or(DEFAULT_RADIUS_MM);
    let size = || -> Result<[f64; 3]> {
        match &args.size_mm {
            Some(v) => {
                if v.len() != 3 {
                    bail!("--size-mm: give three sizes X,Y,Z in mm, got {}", v.len());
                }
                Ok([v[0], v[1], v[2]])
            }
            None => Ok([2.0 * radius_mm; 3]),
        }
    };
    Ok(match args.shape {
        Shape::Sphere => PressShape::Sphere { radius_mm },
        Shape::Ellipsoid => PressShape::Ellipsoid { size_mm: size()? },
        Shape::Box => PressShape::Box { size_mm: size()? },
        Shape::Mesh => PressShape::Mesh {
            path: args
                .mesh
                .clone()
                .context("--shape mesh needs --mesh FILE")?,
            scale: args.mesh_scale.unwrap_or(1.0),
        },
    })
}

/// A size flag the chosen shape does not read would be dropped without a word, and the user
/// would believe the press was of the object they described.
fn refuse_unused_flags(args: &PressArgs) -> Result<()> {
    let shape = args
        .shape
        .to_possible_value()
        .expect("every shape is a --shape value");
    let given = [
        ("--radius-mm", args.radius_mm.is_some()),
        ("--size-mm", args.size_mm.is_some()),
        ("--mesh", args.mesh.is_some()),
        ("--mesh-scale", args.mesh_scale.is_some()),
    ];
    let used: &[&str] = match args.shape {
        Shape::Sphere => &["--radius-mm"],
        Shape::Ellipsoid | Shape::Box if args.size_mm.is_some() => &["--size-mm"],
        Shape::Ellipsoid | Shape::Box => &["--radius-mm", "--size-mm"],
        Shape::Mesh => &["--mesh", "--mesh-scale"],
    };
    if let Some((flag, _)) = given.iter().find(|(flag, on)| *on && !used.contains(flag)) {
        bail!(
            "{flag}: not read for --shape {}, which takes {}",
            shape.get_name(),
            used.join(" or ")
        );
    }
    Ok(())
}

fn object(args: &PressArgs) -> Result<Hardness> {
    match (&args.hardness, args.modulus_mpa) {
        (Some(text), _) => Hardness::parse(text).with_context(|| format!("--hardness {text:?}")),
        (None, Some(e)) => Ok(Hardness::ModulusMpa(e)),
        (None, None) => bail!(
            "--hardness: give the object's hardness (e.g. \"35A\", \"rigid\") or --modulus-mpa"
        ),
    }
}

/// `--at-mm X,Y`, checked to lie on the pad (a contact may still be cut by its edge).
fn at_on_pad(at: Option<&[f64]>, pad_mm: [f64; 2]) -> Result<[f64; 2]> {
    let Some(at) = at else {
        return Ok([0.0, 0.0]);
    };
    let [x, y] = at else {
        bail!("--at-mm: give X,Y in mm, got {} values", at.len());
    };
    let [hw, hh] = pad_mm.map(|s| s / 2.0);
    if x.abs() > hw || y.abs() > hh {
        bail!(
            "--at-mm: ({x}, {y}) mm is off the pad, which spans X -{hw:.2}..{hw:.2} and Y -{hh:.2}..{hh:.2} mm"
        );
    }
    Ok([*x, *y])
}

impl PressArgs {
    /// The device that renders the frames.
    pub fn device(&self) -> DeviceChoice {
        self.device.unwrap_or(DeviceChoice::Auto)
    }
}

/// The press the flags describe, the sensor's gel and markers overridden as they say.
pub fn request(args: &PressArgs) -> Result<PressRequest> {
    let fidelity: Fidelity = args
        .fidelity
        .parse()
        .map_err(|e| anyhow::anyhow!("--fidelity: {e}"))?;
    let hardness = object(args)?;
    let shape = shape(args)?;
    let mut sensor = crate::app::load_sensor(args.sensor.as_deref())?;
    let spec = &mut sensor.spec;
    if let Some(grid) = &args.marker_grid {
        let (cols, rows) = parse_marker_grid(grid).context("--marker-grid")?;
        spec.markers.cols = cols;
        spec.markers.rows = rows;
    }
    if let Some(pitch) = args.marker_pitch_mm {
        let m = &spec.markers;
        if m.cols * m.rows == 0 {
            bail!("--marker-pitch-mm: the gel has no markers (--marker-grid 0x0 or the profile's)");
        }
        let pad = spec.pad_size_mm();
        let span = [f64::from(m.cols - 1) * pitch, f64::from(m.rows - 1) * pitch];
        if span[0] > pad[0] || span[1] > pad[1] {
            bail!(
                "--marker-pitch-mm {pitch}: a {} x {} grid spans {:.1} x {:.1} mm, past the {:.1} x {:.1} mm pad",
                m.cols,
                m.rows,
                span[0],
                span[1],
                pad[0],
                pad[1]
            );
        }
        // Dots wider than their spacing would merge into one dark gel, not a grid.
        if pitch <= 2.0 * m.radius_mm {
            bail!(
                "--marker-pitch-mm {pitch}: not over the markers' diameter ({:.3} mm); they would overlap",
                2.0 * m.radius_mm
            );
        }
        spec.markers.pitch_mm = pitch;
    }
    if let Some(t) = args.gel_thickness_mm {
        spec.gel.thickness_mm = t;
    }
    if let Some(e) = args.gel_modulus_mpa {
        spec.gel.modulus_mpa = e;
    }
    let pose = PressPose {
        at_mm: at_on_pad(args.at_mm.as_deref(), sensor.spec.pad_size_mm())?,
        yaw_deg: args.yaw_deg,
    };
    Ok(PressRequest {
        shape,
        pose,
        hardness,
        object_poisson: args.object_poisson,
        depth_mm: args.depth_mm,
        fidelity,
        cell_mm: args.grid_mm,
        tolerance: args.tolerance,
        sensor,
        seed: args.seed.unwrap_or(0),
    })
}

pub fn run(args: &PressArgs) -> Result<()> {
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
    if args.json {
        println!("{}", serde_json::to_string_pretty(&press.report)?);
    } else {
        print_report(&press.report);
    }
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
