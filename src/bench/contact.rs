//! `tactex bench contact`: the speed/accuracy ladder of the contact solver. For each
//! fidelity level and solver cell, the median time per press frame (an 8-frame press,
//! warm-started) and its error against the finest `layer` solution and against Hertz; and
//! for the default grid, what the conjugate gradient's stopping tolerance and its
//! preconditioner buy.

use crate::report::output::{OutputDir, write_bytes_atomic, write_json_atomic};
use crate::report::plot;
use crate::report::provenance::write_markdown_report;
use crate::report::summary::median;
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use glam::DVec2;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use tactex_core::hertz::{Elastic, Hertz, contact_modulus_mpa, gel_share};
use tactex_core::tactile::spec::TactileSpec;
use tactex_sim::contact::{
    ContactProblem, ContactSolution, ContactSolver, Fidelity, GelFields, Grid, ObjectSurface, Rect,
};

#[derive(Args, Debug)]
pub struct ContactBenchArgs {
    /// Print the rows as JSON.
    #[arg(long)]
    json: bool,
    /// Write contact_bench.csv, contact_bench.md and contact_pareto.png here.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Timed repetitions of each 8-frame press (the median is reported); 1 to 1000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 1000), default_value_t = 5)]
    reps: usize,
    /// Solver cells to time (mm, 0.02 to 5, or "auto" for the default grid).
    #[arg(long, value_delimiter = ',', default_value = "auto,0.4,0.2,0.1")]
    cells: Vec<String>,
    /// Finest cell (mm, 0.01 to 1): the reference `layer` solution.
    #[arg(long, default_value_t = 0.05, value_parser = crate::app::flag_range::within(0.01, 1.0))]
    reference_cell_mm: f64,
    /// Stopping tolerances to time besides the default (1e-12 to 0.5), for `layer` on the
    /// first cell.
    #[arg(long, value_delimiter = ',', default_value = "1e-3,1e-4,1e-5,1e-8",
          value_parser = crate::app::flag_range::within(1e-12, 0.5))]
    tolerances: Vec<f64>,
}

/// Tolerance of the reference and of the converged solves rows are compared with: far below
/// anything a row asks for, so that what they measure is the row's own stopping error.
const CONVERGED_TOLERANCE: f64 = 1e-11;

/// The pressed object: a 10 mm sphere of 1 MPa (a ripe-fruit modulus) on the Mini's gel.
const RADIUS_MM: f64 = 10.0;
const OBJECT: Elastic = Elastic {
    modulus_mpa: Some(1.0),
    poisson: 0.45,
};

#[derive(Serialize, Clone)]
pub struct BenchRow {
    pub fidelity: String,
    /// "auto" or the cell asked for.
    pub cell: String,
    pub cell_mm: f64,
    pub grid: String,
    /// Over the local contact region, or the whole pad.
    pub domain: &'static str,
    /// Each frame started from the previous one, or cold.
    pub start: &'static str,
    /// The conjugate gradient preconditioned ("pre") or plain.
    pub cg: &'static str,
    /// The conjugate gradient stops when the pressure changes by less than this (relative).
    pub tolerance: f64,
    pub ms_per_frame: f64,
    pub iterations_per_frame: f64,
    pub force_err_vs_reference_pct: f64,
    pub radius_err_vs_reference_pct: f64,
    pub rms_gel_um_vs_reference: f64,
    pub force_err_vs_hertz_pct: f64,
    pub radius_err_vs_hertz_pct: f64,
    pub rms_gel_um_vs_hertz: f64,
    /// The same press on the same grid solved to `CONVERGED_TOLERANCE`: the error of
    /// stopping early, apart from the grid's.
    pub rms_gel_um_vs_converged: f64,
}

/// One timed configuration.
#[derive(Clone, Copy)]
struct Config {
    fidelity: Fidelity,
    cell: Option<f64>,
    whole_pad: bool,
    warm: bool,
    tolerance: f64,
    preconditioned: bool,
}

struct Setup {
    surface: ObjectSurface,
    spec: TactileSpec,
    pad: Rect,
    depths: Vec<f64>,
}

impl Setup {
    fn problem(&self, cell_mm: Option<f64>) -> ContactProblem<'_> {
        ContactProblem {
            surface: &self.surface,
            object: OBJECT,
            gel: self.spec.gel,
            pad: self.pad,
            approach_mm: 0.0,
            cell_mm,
        }
    }
}

/// RMS difference of the gel's normal displacement `fields` from `truth` over the
/// reference grid (micrometres).
fn rms_um(
    fields: &GelFields,
    reference: &ContactSolution,
    truth: impl Fn(DVec2) -> Option<f64>,
) -> f64 {
    let g: &Grid = &reference.grid;
    let mut sum = 0.0;
    for j in 0..g.ny {
        for i in 0..g.nx {
            let p = g.centre(i, j);
            let expected = truth(p).unwrap_or(reference.gel.normal_mm[j * g.nx + i]);
            let d = fields.grid.sample(&fields.normal_mm, p) - expected;
            sum += d * d;
        }
    }
    1e3 * (sum / g.len() as f64).sqrt()
}

pub(crate) fn run(args: &ContactBenchArgs) -> Result<()> {
    let spec = TactileSpec::gelsight_mini();
    let setup = Setup {
        surface: ObjectSurface::Sphere {
            radius_mm: RADIUS_MM,
            centre_mm: DVec2::ZERO,
        },
        pad: Rect::centred(
            DVec2::new(spec.width_px as f64, spec.height_px as f64) * spec.mm_per_px / 2.0,
        ),
        depths: (1..=8).map(|k| 0.25 * k as f64).collect(),
        spec,
    };
    let gel = Elastic {
        modulus_mpa: Some(setup.spec.gel.modulus_mpa),
        poisson: setup.spec.gel.poisson,
    };
    let hertz_at = |depth: f64| Hertz {
        radius_mm: RADIUS_MM,
        approach_mm: depth,
        contact_modulus_mpa: contact_modulus_mpa(gel, OBJECT),
    };
    let share = gel_share(gel, OBJECT);

    let mut cells = Vec::new();
    for c in &args.cells {
        cells.push(match c.trim() {
            "auto" => None,
            text => Some(
                text.parse::<f64>()
                    .ok()
                    .filter(|v| v.is_finite() && (0.02..=5.0).contains(v))
                    .with_context(|| {
                        format!(
                            "--cells: {text:?} is neither \"auto\" nor a cell size of 0.02 to 5 mm"
                        )
                    })?,
            ),
        });
    }
    // Only once every flag is read: a refused flag is one line.
    if cfg!(debug_assertions) {
        eprintln!(
            "note: this is a debug build; run `cargo run --release -- bench contact` for timings"
        );
    }
    let default_tolerance = ContactSolver::new().settings.tolerance;
    let config = |fidelity, cell, whole_pad, warm, tolerance| Config {
        fidelity,
        cell,
        whole_pad,
        warm,
        tolerance,
        preconditioned: true,
    };
    let mut configs = Vec::new();
    for fidelity in Fidelity::ALL {
        for cell in &cells {
            configs.push(config(fidelity, *cell, false, true, default_tolerance));
        }
    }
    // What modelling only the touched region saves: the same solve over the whole pad.
    for cell in &cells {
        configs.push(config(
            Fidelity::Layer,
            *cell,
            true,
            true,
            default_tolerance,
        ));
    }
    // What the warm start saves: each frame solved cold.
    configs.push(config(
        Fidelity::Layer,
        cells[0],
        false,
        false,
        default_tolerance,
    ));
    // What the stopping tolerance trades.
    for t in &args.tolerances {
        configs.push(config(Fidelity::Layer, cells[0], false, true, *t));
    }
    // What the preconditioner saves: the plain conjugate gradient.
    for fidelity in [Fidelity::Halfspace, Fidelity::Layer] {
        configs.push(Config {
            preconditioned: false,
            ..config(fidelity, cells[0], false, true, default_tolerance)
        });
    }

    let bar = ProgressBar::new(configs.len() as u64 + 1);
    bar.set_style(
        ProgressStyle::with_template("{msg:>28} [{bar:30}] {pos}/{len} {elapsed}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar.set_message("reference layer solve");
    let mut solver = ContactSolver::new();
    solver.settings.tolerance = CONVERGED_TOLERANCE;
    let reference = solver.press_sequence(
        &setup.problem(Some(args.reference_cell_mm)),
        Fidelity::Layer,
        &setup.depths,
    )?;
    bar.inc(1);

    let mut rows = Vec::new();
    for Config {
        fidelity,
        cell,
        whole_pad,
        warm,
        tolerance,
        preconditioned,
    } in configs
    {
        let label = format!(
            "{fidelity} {}{}{}{} tol {tolerance:.0e}",
            cell.map_or("auto".into(), |c| format!("{c} mm")),
            if whole_pad { " (pad)" } else { "" },
            if warm { "" } else { " (cold)" },
            if preconditioned { "" } else { " (plain)" }
        );
        bar.set_message(label);
        let problem = setup.problem(cell);
        let deepest = *setup.depths.last().expect("eight depths");
        let mut grid = solver.plan_grid(&problem, fidelity, deepest)?;
        if whole_pad {
            let cell_mm = grid.map_or(0.1, |g| g.cell_mm);
            grid = Some(Grid::covering(&setup.pad, cell_mm));
        }
        solver.settings.preconditioned = preconditioned;
        let press = |solver: &mut ContactSolver, tolerance: f64| {
            solver.settings.tolerance = tolerance;
            let mut frames: Vec<ContactSolution> = Vec::new();
            for &depth in &setup.depths {
                let frame = ContactProblem {
                    approach_mm: depth,
                    ..problem
                };
                let previous = if warm { frames.last() } else { None };
                let s = solver.solve_on(&frame, fidelity, grid, previous)?;
                frames.push(s);
            }
            anyhow::Ok(frames)
        };
        let converged = press(&mut solver, CONVERGED_TOLERANCE)?;
        let mut times = Vec::with_capacity(args.reps);
        let mut frames: Vec<ContactSolution> = Vec::new();
        for _ in 0..args.reps {
            let start = Instant::now();
            frames = press(&mut solver, tolerance)?;
            times.push(start.elapsed().as_secs_f64() * 1e3 / setup.depths.len() as f64);
        }
        let n = frames.len() as f64;
        let mut row = BenchRow {
            fidelity: fidelity.to_string(),
            cell: cell.map_or("auto".into(), |c| format!("{c}")),
            cell_mm: grid.map_or(0.0, |g| g.cell_mm),
            grid: grid.map_or("-".into(), |g| format!("{}x{}", g.nx, g.ny)),
            domain: if whole_pad { "pad" } else { "contact" },
            start: if warm { "warm" } else { "cold" },
            cg: if preconditioned { "pre" } else { "plain" },
            tolerance,
            ms_per_frame: median(times),
            iterations_per_frame: frames.iter().map(|f| f.iterations as f64).sum::<f64>() / n,
            force_err_vs_reference_pct: 0.0,
            radius_err_vs_reference_pct: 0.0,
            rms_gel_um_vs_reference: 0.0,
            force_err_vs_hertz_pct: 0.0,
            radius_err_vs_hertz_pct: 0.0,
            rms_gel_um_vs_hertz: 0.0,
            rms_gel_um_vs_converged: 0.0,
        };
        for (((s, r), c), &depth) in frames
            .iter()
            .zip(&reference)
            .zip(&converged)
            .zip(&setup.depths)
        {
            let h = hertz_at(depth);
            row.force_err_vs_reference_pct += 100.0 * (s.force_n / r.force_n - 1.0).abs() / n;
            row.radius_err_vs_reference_pct +=
                100.0 * (s.contact_radius_mm / r.contact_radius_mm - 1.0).abs() / n;
            row.force_err_vs_hertz_pct += 100.0 * (s.force_n / h.force_n() - 1.0).abs() / n;
            row.radius_err_vs_hertz_pct +=
                100.0 * (s.contact_radius_mm / h.contact_radius_mm() - 1.0).abs() / n;
            let fields = solver.fields_over(s, &r.grid.rect());
            row.rms_gel_um_vs_reference += rms_um(&fields, r, |_| None) / n;
            row.rms_gel_um_vs_hertz += rms_um(&fields, r, |p| {
                Some(share * h.total_displacement_mm(p.length()))
            }) / n;
            row.rms_gel_um_vs_converged += rms_um(&s.gel, c, |_| None) / n;
        }
        rows.push(row);
        bar.inc(1);
    }
    bar.finish_and_clear();

    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_bytes_atomic(&dir.join("contact_bench.csv"), csv(&rows).as_bytes())?;
        write_markdown_report(&dir.join("contact_bench.md"), &markdown(&rows))?;
        write_json_atomic(&dir.join("contact_bench.json"), &rows)?;
        let points: Vec<plot::ParetoPoint> = rows
            .iter()
            .map(|r| plot::ParetoPoint {
                series: if r.domain == "pad" {
                    format!("{} (whole pad)", r.fidelity)
                } else {
                    r.fidelity.clone()
                },
                label: match (r.tolerance == default_tolerance, r.cg) {
                    (true, "pre") => r.cell.clone(),
                    (true, cg) => format!("{} {cg} CG", r.cell),
                    (false, _) => format!("{} tol {:.0e}", r.cell, r.tolerance),
                },
                x: r.ms_per_frame,
                y: r.force_err_vs_reference_pct,
            })
            .collect();
        plot::pareto(
            &dir.join("contact_pareto.png"),
            "Contact solver: time per press frame vs force error",
            "median time per frame (ms)",
            "force error vs finest layer (%)",
            &points,
        )?;
        out.finish()?;
    }
    print_json_or_text(&rows, args.json, || {
        print!("{}", markdown(&rows));
        Ok(())
    })?;
    Ok(())
}

fn csv(rows: &[BenchRow]) -> String {
    let mut out = String::from(
        "fidelity,cell,cell_mm,grid,domain,start,cg,tolerance,ms_per_frame,iterations_per_frame,force_err_vs_reference_pct,radius_err_vs_reference_pct,rms_gel_um_vs_reference,force_err_vs_hertz_pct,radius_err_vs_hertz_pct,rms_gel_um_vs_hertz,rms_gel_um_vs_converged\n",
    );
    for r in rows {
        out += &format!(
            "{},{},{:.5},{},{},{},{},{:e},{:.4},{:.1},{:.4},{:.4},{:.3},{:.4},{:.4},{:.3},{:.6}\n",
            r.fidelity,
            r.cell,
            r.cell_mm,
            r.grid,
            r.domain,
            r.start,
            r.cg,
            r.tolerance,
            r.ms_per_frame,
            r.iterations_per_frame,
            r.force_err_vs_reference_pct,
            r.radius_err_vs_reference_pct,
            r.rms_gel_um_vs_reference,
            r.force_err_vs_hertz_pct,
            r.radius_err_vs_hertz_pct,
            r.rms_gel_um_vs_hertz,
            r.rms_gel_um_vs_converged
        );
    }
    out
}

fn markdown(rows: &[BenchRow]) -> String {
    let mut out = String::from(
        "| fidelity | cell | grid | domain | start | CG | tolerance | ms/frame | iter/frame | force err vs ref | radius err vs ref | RMS gel vs ref | force err vs Hertz | radius err vs Hertz | RMS gel vs Hertz | RMS gel vs converged |\n|---|---|---|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in rows {
        let cell = if r.cell == "auto" {
            format!("auto ({:.3} mm)", r.cell_mm)
        } else {
            format!("{} mm", r.cell)
        };
        out += &format!(
            "| {} | {cell} | {} | {} | {} | {} | {:.0e} | {:.3} | {:.1} | {:.2}% | {:.2}% | {:.1} µm | {:.2}% | {:.2}% | {:.1} µm | {:.2} nm |\n",
            r.fidelity,
            r.grid,
            r.domain,
            r.start,
            r.cg,
            r.tolerance,
            r.ms_per_frame,
            r.iterations_per_frame,
            r.force_err_vs_reference_pct,
            r.radius_err_vs_reference_pct,
            r.rms_gel_um_vs_reference,
            r.force_err_vs_hertz_pct,
            r.radius_err_vs_hertz_pct,
            r.rms_gel_um_vs_hertz,
            1e3 * r.rms_gel_um_vs_converged
        );
    }
    out
}
