//! `tactex bench render`: frames per second of GelSight Mini frames (320x240) for each contact
//! fidelity level, on the CPU path and on the GPU path when a Vulkan adapter exists. A frame
//! is the whole chain: contact solve (an 8-frame press, warm-started), the gel fields at
//! pixel resolution, and rendering (slopes, shading, markers, noise). The render stages and
//! the shading alone are timed on their own too.

use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic};
use crate::report::provenance::write_markdown_report;
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::Result;
use clap::Args;
use glam::DVec2;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use tactex_core::hertz::Elastic;
use tactex_sim::contact::{ContactProblem, ContactSolver, Fidelity, ObjectSurface};
use tactex_sim::render::gel::{
    CpuRenderer, GelImageFields, GelRenderer, GpuRenderer, PressFrame, SensorOptics, adapters,
    image_fields, pad_rect,
};

#[derive(Args, Debug)]
pub struct RenderBenchArgs {
    /// Print the rows as JSON.
    #[arg(long)]
    json: bool,
    /// Write render_bench.csv, render_bench.md and render_bench.json here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timed repetitions of each 8-frame press (the median is reported); 1 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000), default_value_t = 5)]
    reps: usize,
    /// Frames per GPU dispatch for the batch row (data generation renders many at once); 1 to 4096.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 4096), default_value_t = 64)]
    batch: usize,
    /// Sensor profile to render with (default: the built-in GelSight Mini).
    #[arg(long)]
    sensor: Option<PathBuf>,
}

#[derive(Serialize, Clone)]
pub struct RenderRow {
    pub fidelity: String,
    /// "cpu", or the GPU adapter.
    pub device: String,
    /// Contact solve per frame.
    pub solve_ms: f64,
    /// Gel fields resampled to the 320x240 pixels.
    pub fields_ms: f64,
    /// All four render stages per frame (the 8 frames of the press in one batch).
    pub render_ms: f64,
    pub frame_ms: f64,
    pub fps: f64,
}

#[derive(Serialize)]
pub struct RenderBench {
    /// The sensor rendered.
    pub sensor: tactex_core::tactile::sensor_profile::ProfileId,
    pub width: u32,
    pub height: u32,
    pub rows: Vec<RenderRow>,
    /// Slopes + shading alone, CPU path, per frame.
    pub shading_only_cpu_ms: f64,
    /// The four render stages per frame in batches of `batch` frames, per device.
    pub batch: usize,
    pub batch_render_ms: Vec<(String, f64)>,
}

const DEPTHS_MM: [f64; 8] = [0.25, 0.5, 0.75, 1.0, 1.25, 1.5, 1.75, 2.0];

pub(crate) fn run(args: &RenderBenchArgs) -> Result<()> {
    let reps = args.reps;
    let profile = crate::app::load_sensor(args.sensor.as_deref())?;
    let spec = profile.spec.clone();
    let optics = SensorOptics::for_profile(&profile);
    let surface = ObjectSurface::Sphere {
        radius_mm: 10.0,
        centre_mm: DVec2::ZERO,
    };
    let problem = ContactProblem {
        surface: &surface,
        object: Elastic {
            modulus_mpa: Some(1.0),
            poisson: 0.45,
        },
        gel: spec.gel,
        pad: pad_rect(&optics),
        approach_mm: 0.0,
        cell_mm: None,
    };
    let mut devices: Vec<Box<dyn GelRenderer>> = vec![Box::new(CpuRenderer)];
    if let Some(adapter) = adapters().first() {
        devices.push(Box::new(GpuRenderer::new(adapter)?));
    }
    let fidelities = [
        Fidelity::Rigid,
        Fidelity::Hertz,
        Fidelity::Halfspace,
        Fidelity::Layer,
    ];
    let bar = ProgressBar::new((fidelities.len() * devices.len() + devices.len() + 1) as u64);
    bar.set_style(
        ProgressStyle::with_template("{msg:>28} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let n = DEPTHS_MM.len() as f64;
    let mut rows = Vec::new();
    for fidelity in fidelities {
        for device in devices.iter_mut() {
            bar.set_message(format!("{fidelity} on {}", short(&device.name())));
            let (mut solve, mut fields_t, mut render) = (Vec::new(), Vec::new(), Vec::new());
            for seed in 0..reps as u32 {
                let mut solver = ContactSolver::new();
                let t = Instant::now();
                let solutions = solver.press_sequence(&problem, fidelity, &DEPTHS_MM)?;
                solve.push(t.elapsed().as_secs_f64() * 1e3 / n);
                let t = Instant::now();
                let fields: Vec<GelImageFields> = solutions
                    .iter()
                    .map(|s| image_fields(&mut solver, s, &spec.gel, &optics))
                    .collect();
                fields_t.push(t.elapsed().as_secs_f64() * 1e3 / n);
                let frames: Vec<PressFrame> = fields
                    .iter()
                    .enumerate()
                    .map(|(k, f)| PressFrame {
                        fields: f,
                        seed: seed * 8 + k as u32,
                    })
                    .collect();
                let t = Instant::now();
                device.render_batch(&optics, &frames)?;
                render.push(t.elapsed().as_secs_f64() * 1e3 / n);
            }
            let (s, f, r) = (median(solve), median(fields_t), median(render));
            rows.push(RenderRow {
                fidelity: fidelity.name().into(),
                device: device.name(),
                solve_ms: s,
                fields_ms: f,
                render_ms: r,
                frame_ms: s + f + r,
                fps: 1e3 / (s + f + r),
            });
            bar.inc(1);
        }
    }
    // Rendering throughput for data generation: many presses per call.
    let mut solver = ContactSolver::new();
    let pressed = solver.solve(
        &ContactProblem {
            approach_mm: 1.0,
            ..problem
        },
        Fidelity::Layer,
    )?;
    let fields = image_fields(&mut solver, &pressed, &spec.gel, &optics);
    let batch = args.batch;
    let frames: Vec<PressFrame> = (0..batch as u32)
        .map(|seed| PressFrame {
            fields: &fields,
            seed,
        })
        .collect();
    let mut batch_render_ms = Vec::new();
    for device in devices.iter_mut() {
        bar.set_message(format!("batch of {batch} on {}", short(&device.name())));
        let times: Vec<f64> = (0..reps)
            .map(|_| -> Result<f64> {
                let t = Instant::now();
                device.render_batch(&optics, &frames)?;
                Ok(t.elapsed().as_secs_f64() * 1e3 / batch as f64)
            })
            .collect::<Result<_>>()?;
        batch_render_ms.push((device.name(), median(times)));
        bar.inc(1);
    }
    bar.set_message("shading alone");
    let one = PressFrame {
        fields: &fields,
        seed: 0,
    };
    let shading: Vec<f64> = (0..reps * 4)
        .map(|_| {
            let t = Instant::now();
            std::hint::black_box(CpuRenderer.shade_only(&optics, &one));
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    bar.inc(1);
    bar.finish_and_clear();
    let report = RenderBench {
        sensor: profile.id(),
        width: optics.width,
        height: optics.height,
        rows,
        shading_only_cpu_ms: median(shading),
        batch,
        batch_render_ms,
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_bytes_atomic(&dir.join("render_bench.csv"), csv(&report).as_bytes())?;
        write_markdown_report(&dir.join("render_bench.md"), &markdown(&report))?;
        write_json_atomic(&dir.join("render_bench.json"), &report)?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        print!("{}", markdown(&report));
        Ok(())
    })?;
    Ok(())
}

/// The adapter's name without its driver details.
fn short(name: &str) -> &str {
    name.split(" (").next().unwrap_or(name)
}

fn csv(r: &RenderBench) -> String {
    let mut out = String::from("fidelity,device,solve_ms,fields_ms,render_ms,frame_ms,fps\n");
    for row in &r.rows {
        out += &format!(
            "{},{},{:.3},{:.3},{:.3},{:.3},{:.1}\n",
            row.fidelity,
            short(&row.device),
            row.solve_ms,
            row.fields_ms,
            row.render_ms,
            row.frame_ms,
            row.fps
        );
    }
    out
}

fn markdown(r: &RenderBench) -> String {
    let mut out = format!(
        "Full {}x{} frame of {}: contact solve + gel fields + render, median ms per frame of an 8-frame press.\n\n",
        r.width, r.height, r.sensor
    );
    out += "| fidelity | device | solve ms | fields ms | render ms | frame ms | fps |\n";
    out += "|---|---|---:|---:|---:|---:|---:|\n";
    for row in &r.rows {
        out += &format!(
            "| {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.0} |\n",
            row.fidelity,
            short(&row.device),
            row.solve_ms,
            row.fields_ms,
            row.render_ms,
            row.frame_ms,
            row.fps
        );
    }
    out += &format!(
        "\nShading alone (slopes + shading, CPU): {:.2} ms per frame.\n",
        r.shading_only_cpu_ms
    );
    for (device, ms) in &r.batch_render_ms {
        out += &format!(
            "Render stages in batches of {}, {}: {:.2} ms per frame ({:.0} fps).\n",
            r.batch,
            short(device),
            ms,
            1e3 / ms
        );
    }
    out
}
