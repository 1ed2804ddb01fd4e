//! `tactex bench datagen`: press sequences per second of `datagen tactile` (search for
//! contact, 8 frames, rendering, PNG or NPZ encoding, manifest), per contact fidelity level,
//! and the time the paper's 5,000-sequence pretraining set would take at that rate.

use crate::datagen::tactile::{SampleFormat, TactileDatagenArgs, generate};
use crate::report::output::{OutputDir, write_json_atomic};
use crate::report::tail::print_json_or_text;
use anyhow::{Context, Result};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use serde::Serialize;
use std::path::PathBuf;
use std::time::Instant;
use tactex_sim::render::gel::DeviceChoice;

#[derive(Args, Debug)]
pub struct DatagenBenchArgs {
    /// Sequences generated per fidelity level; 1 to 100000.
    #[arg(long, value_parser = crate::app::flag_range::count::<u64>(1, 100_000), default_value_t = 48)]
    count: u64,
    /// Fidelity levels to time (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "rigid,hertz,halfspace,layer"
    )]
    fidelity: Vec<String>,
    /// Shape families (comma-separated).
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "sphere,ellipsoid,box,fruit,blob"
    )]
    shapes: Vec<String>,
    #[arg(long, value_enum, default_value = "png")]
    format: SampleFormat,
    /// Print the rows as JSON.
    #[arg(long)]
    json: bool,
    /// Write datagen_bench.json here.
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Serialize)]
struct Row {
    fidelity: String,
    sequences: u64,
    seconds: f64,
    sequences_per_s: f64,
    /// Minutes for the paper's 5,000-sequence pretraining set at this rate.
    minutes_for_5000: f64,
    redraws: u64,
    mean_search_steps: f64,
    megabytes_per_sequence: f64,
}

#[derive(Serialize)]
struct Bench {
    threads: usize,
    format: SampleFormat,
    shapes: Vec<String>,
    rows: Vec<Row>,
}

fn dir_bytes(dir: &std::path::Path) -> u64 {
    std::fs::read_dir(dir)
        .map(|entries| {
            entries
                .flatten()
                .map(|e| {
                    let p = e.path();
                    if p.is_dir() {
                        dir_bytes(&p)
                    } else {
                        e.metadata().map_or(0, |m| m.len())
                    }
                })
                .sum()
        })
        .unwrap_or(0)
}

pub(crate) fn run(args: &DatagenBenchArgs) -> Result<()> {
    let bar = ProgressBar::new(args.fidelity.len() as u64).with_style(
        ProgressStyle::with_template("bench datagen [{bar:30}] {pos}/{len} levels {msg}")
            .expect("a valid template"),
    );
    let mut rows = Vec::new();
    for fidelity in &args.fidelity {
        bar.set_message(fidelity.clone());
        let tmp = tempfile::tempdir().context("a temporary directory for the bench")?;
        let run_args = TactileDatagenArgs {
            count: args.count,
            out: tmp.path().join("data"),
            seed: 0,
            shard: "0/1".into(),
            format: args.format,
            fidelity: fidelity.clone(),
            shapes: args.shapes.clone(),
            device: DeviceChoice::Cpu,
            sensor: None,
        };
        let start = Instant::now();
        let summary = generate(&run_args, false)?;
        let seconds = start.elapsed().as_secs_f64();
        let rate = summary.new as f64 / seconds;
        rows.push(Row {
            fidelity: fidelity.clone(),
            sequences: summary.new,
            seconds,
            sequences_per_s: rate,
            minutes_for_5000: 5000.0 / rate / 60.0,
            redraws: summary.redraws,
            mean_search_steps: summary.mean_search_steps,
            megabytes_per_sequence: dir_bytes(&run_args.out) as f64 / 1e6 / summary.new as f64,
        });
        bar.inc(1);
    }
    bar.finish_and_clear();
    let bench = Bench {
        threads: rayon::current_num_threads(),
        format: args.format,
        shapes: args.shapes.clone(),
        rows,
    };
    if let Some(out) = &args.out {
        let out = OutputDir::create("--out", out)?;
        let dir = out.path();
        write_json_atomic(&dir.join("datagen_bench.json"), &bench)?;
        out.finish()?;
    }
    print_json_or_text(&bench, args.json, || {
        println!(
            "datagen tactile, {} sequences per level, {} threads, {:?}, shapes {}",
            args.count,
            bench.threads,
            args.format,
            args.shapes.join(",")
        );
        println!(
            "{:<10} {:>9} {:>8} {:>10} {:>8} {:>12} {:>8}",
            "fidelity", "seq/s", "seconds", "5000 (min)", "redraws", "search steps", "MB/seq"
        );
        for r in &bench.rows {
            println!(
                "{:<10} {:>9.2} {:>8.1} {:>10.1} {:>8} {:>12.2} {:>8.2}",
                r.fidelity,
                r.sequences_per_s,
                r.seconds,
                r.minutes_for_5000,
                r.redraws,
                r.mean_search_steps,
                r.megabytes_per_sequence
            );
        }
        Ok(())
    })
}
