//! `tactex bench scene`: RGB-D scene rendering at the camera's 640x480, on the CPU reference
//! and on each Vulkan adapter: opening the device, building the triangles, one clean render
//! (colour, depth, instance ids), and the per-frame noise (colour and D435 depth) that every
//! captured frame adds on the CPU. Medians of `--reps` runs, all rows measured in one run.

use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::provenance::write_markdown_report;
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::scene::Scene;
use tactex_sim::SimDevices;
use tactex_sim::render::device::adapters;
use tactex_sim::render::scene::{CpuSceneRenderer, GpuSceneRenderer, SceneGeometry, SceneRenderer};

#[derive(Args, Debug)]
pub struct SceneBenchArgs {
    /// Scene file (TOML); default scenes/demo.toml.
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Timed repetitions of each measurement (the median is reported); 1 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000), default_value_t = 9)]
    reps: usize,
    /// Print the report as JSON.
    #[arg(long)]
    json: bool,
    /// Write scene_bench.md and scene_bench.json here.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Serialize)]
pub struct SceneBenchRow {
    /// "cpu", or the GPU adapter.
    pub device: String,
    /// Creating the device and compiling the pipeline (0 for the CPU).
    pub open_ms: f64,
    /// One clean render: upload, raster, read back.
    pub render_ms: f64,
    pub renders_per_s: f64,
}

#[derive(Serialize)]
pub struct SceneBench {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub triangles: usize,
    /// Triangles from the world (table, floor, meshes with texture).
    pub geometry_ms: f64,
    /// Colour and depth noise of one captured frame (CPU, every frame).
    pub frame_noise_ms: f64,
    pub rows: Vec<SceneBenchRow>,
}

pub(crate) fn run(args: &SceneBenchArgs) -> Result<()> {
    let reps = args.reps;
    let path = args.scene.clone().unwrap_or_else(crate::app::default_scene);
    let scene = Scene::load(&path, &FruitCatalog::builtin())?;
    let mut sim = SimDevices::from_scene(&scene, 0)?;
    let world = sim.world.clone();
    let geometry_times: Vec<f64> = (0..reps)
        .map(|_| {
            let t = Instant::now();
            let g = SceneGeometry::of_world(&world.lock().expect("world lock"));
            std::hint::black_box(g);
            t.elapsed().as_secs_f64() * 1e3
        })
        .collect();
    let geometry = SceneGeometry::of_world(&world.lock().expect("world lock"));
    let found = adapters();
    let bar = ProgressBar::new((1 + found.len()) as u64).with_style(
        ProgressStyle::with_template("{msg:>24} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    let mut devices: Vec<(Arc<dyn SceneRenderer>, f64)> = vec![(Arc::new(CpuSceneRenderer), 0.0)];
    for adapter in &found {
        let t = Instant::now();
        let gpu = GpuSceneRenderer::new(adapter)?;
        devices.push((Arc::new(gpu), t.elapsed().as_secs_f64() * 1e3));
    }
    let mut rows = Vec::new();
    for (renderer, open_ms) in devices {
        bar.set_message(renderer.name().split(" (").next().unwrap_or("").to_string());
        // The first render warms caches and the driver's pipeline; it is not timed.
        renderer.render(&geometry)?;
        let times: Vec<f64> = (0..reps)
            .map(|_| -> Result<f64> {
                let t = Instant::now();
                std::hint::black_box(renderer.render(&geometry)?);
                Ok(t.elapsed().as_secs_f64() * 1e3)
            })
            .collect::<Result<_>>()?;
        let render_ms = median(times);
        rows.push(SceneBenchRow {
            device: renderer.name(),
            open_ms,
            render_ms,
            renders_per_s: 1e3 / render_ms,
        });
        bar.inc(1);
    }
    // The clean render is cached after the first capture: later captures time the noise.
    sim.camera.capture().context("first capture")?;
    let noise_times: Vec<f64> = (0..reps)
        .map(|_| -> Result<f64> {
            let t = Instant::now();
            std::hint::black_box(sim.camera.capture()?);
            Ok(t.elapsed().as_secs_f64() * 1e3)
        })
        .collect::<Result<_>>()?;
    bar.inc(1);
    bar.finish_and_clear();
    let report = SceneBench {
        scene: path.display().to_string(),
        width: geometry.intrinsics.width,
        height: geometry.intrinsics.height,
        triangles: geometry.triangles.len(),
        geometry_ms: median(geometry_times),
        frame_noise_ms: median(noise_times),
        rows,
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_markdown_report(&dir.join("scene_bench.md"), &markdown(&report))?;
        write_json_atomic(&dir.join("scene_bench.json"), &report)?;
        out.finish()?;
    }
    print_json_or_text(&report, args.json, || {
        print!("{}", markdown(&report));
        Ok(())
    })?;
    Ok(())
}

fn markdown(r: &SceneBench) -> String {
    let mut out = format!(
        "{}: {}x{} RGB-D, {} triangles; building them {:.2} ms; per-frame noise (CPU) {:.2} ms. Medians.\n\n",
        r.scene, r.width, r.height, r.triangles, r.geometry_ms, r.frame_noise_ms
    );
    out += "| device | open ms | clean render ms | renders/s |\n|---|---:|---:|---:|\n";
    let cpu_ms = r.rows.first().map(|row| row.render_ms);
    for row in &r.rows {
        out += &format!(
            "| {} | {:.1} | {:.2} | {:.1} |\n",
            row.device, row.open_ms, row.render_ms, row.renders_per_s
        );
    }
    if let Some(cpu) = cpu_ms {
        for row in r.rows.iter().skip(1) {
            out += &format!(
                "\n{}: {:.2}x the CPU's render speed.",
                row.device.split(" (").next().unwrap_or(""),
                cpu / row.render_ms
            );
        }
        out += "\n";
    }
    out
}
