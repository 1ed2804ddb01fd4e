//! `tactex datagen tactile`: synthetic press sequences for pretraining tactile models.
//!
//! Layout of DIR:
//! * `dataset.json`: the settings every shard shares (a second run into DIR must match them);
//! * `shard-I-of-N.jsonl`: one line per sample of shard I, ascending index: the labels
//!   (hardness in Shore A, Shore 00 and MPa, shape, pose, sensor, seeds, fidelity) and the
//!   press facts (travel, force, contact radius per frame);
//! * `samples/NNNNNNN/` (png: `reference.png`, `frame_0.png` ...) or `samples/NNNNNNN.npz`
//!   (`frames` uint8 [9, H, W, 3] with the reference first, `gel_normal_mm` float32
//!   [8, H, W], `travel_mm` float64 [8]).
//!
//! Sample i belongs to shard i mod N and is drawn from (seed, i) alone, so shards are
//! independent jobs. Files are written whole (temporary file + rename) before the sample's
//! manifest line is appended; a rerun skips every sample with a complete line and redoes the
//! rest, so an interrupted run resumes and gives the same bytes as an uninterrupted one.

use crate::app::tactile_samples::{TactileSample, TactileSampleSource};
#[cfg(feature = "npz")]
use crate::report::npz::{NpyArray, npz_bytes};
#[cfg(feature = "npz")]
use crate::report::output::write_bytes_atomic;
use crate::report::output::write_json_atomic;
use anyhow::{Context, Result, bail};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeSet;
use std::io::{BufRead, Write};
use std::path::{Path, PathBuf};
use tactex_core::press::protocol::PressProtocol;
use tactex_core::tactile::sensor_profile::ProfileId;
use tactex_sim::contact::ContactSolver;
use tactex_sim::render::gel::{DeviceChoice, GelRenderer, open_renderer};

const FORMAT: &str = "tactex-tactile-dataset/1";
/// Redraws of a sample whose press found no contact before the run gives up on it.

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SampleFormat {
    Png,
    Npz,
}

impl SampleFormat {
    pub const NAMES: [&'static str; 2] = ["png", "npz"];
}

impl std::str::FromStr for SampleFormat {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "png" => Ok(Self::Png),
            "npz" => Ok(Self::Npz),
            _ => Err(format!("unknown format {s:?} (png or npz)")),
        }
    }
}

#[derive(Args, Debug)]
pub struct TactileDatagenArgs {
    /// Samples in the whole data set (all shards); 1 to 100000000.
    #[arg(long, value_parser = crate::app::flag_range::count::<u64>(1, 100_000_000))]
    pub(crate) count: u64,
    /// Output directory.
    #[arg(long)]
    pub(crate) out: PathBuf,
    #[arg(long, default_value_t = 0)]
    pub(crate) seed: u64,
    /// This job's part of the data set, I/N with I in 0..N: samples i with i mod N = I.
    #[arg(long, default_value = "0/1")]
    pub(crate) shard: String,
    #[arg(long, default_value = "png", value_parser = crate::app::flag_range::choice::<SampleFormat>(&SampleFormat::NAMES))]
    pub(crate) format: SampleFormat,
    /// Contact model: rigid, hertz, halfspace or layer.
    #[arg(long, default_value = "layer")]
    pub(crate) fidelity: String,
    /// Shape families to draw from (comma-separated): sphere, ellipsoid, box, fruit, blob.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "sphere,ellipsoid,box,fruit,blob"
    )]
    pub(crate) shapes: Vec<String>,
    /// Device that renders the recorded frames (auto, gpu, cpu); the contact search always
    /// renders on the CPU so that the data never depends on the device.
    #[arg(long, default_value = "cpu")]
    pub(crate) device: DeviceChoice,
    /// Sensor profile (TOML) the presses are drawn around: its background, shading, marker
    /// grid and camera, each sample with its gel, lights, exposure, noise and markers
    /// jittered; default the built-in GelSight Mini. A data set keeps one profile.
    #[arg(long)]
    pub(crate) sensor: Option<PathBuf>,
}

/// Settings that every shard of one data set shares.
#[derive(Clone, Debug, PartialEq, Serialize, serde::Deserialize)]
struct DatasetInfo {
    format: String,
    count: u64,
    seed: u64,
    sample_format: String,
    fidelity: String,
    shapes: Vec<String>,
    frames: usize,
    step_mm: f64,
    width: u32,
    height: u32,
    mm_per_px: f64,
    /// The profile the samples are drawn around.
    sensor: ProfileId,
}

fn parse_shard(text: &str) -> Result<(u64, u64)> {
    let parsed = text
        .split_once('/')
        .and_then(|(i, n)| Some((i.trim().parse::<u64>().ok()?, n.trim().parse::<u64>().ok()?)));
    match parsed {
        Some((i, n)) if n >= 1 && i < n => Ok((i, n)),
        _ => bail!("--shard: '{text}' is not I/N with 0 <= I < N (e.g. 0/4 for the first of four)"),
    }
}

fn shard_manifest(dir: &Path, shard: (u64, u64)) -> PathBuf {
    dir.join(format!("shard-{}-of-{}.jsonl", shard.0, shard.1))
}

fn sample_stem(index: u64) -> String {
    format!("samples/{index:07}")
}

/// Indices with a complete manifest line; the file is cut back to its last complete line.
fn resume(manifest: &Path) -> Result<BTreeSet<u64>> {
    let mut done = BTreeSet::new();
    let Ok(file) = std::fs::File::open(manifest) else {
        return Ok(done);
    };
    let mut good_len = 0u64;
    let mut reader = std::io::BufReader::new(file);
    let mut line = String::new();
    loop {
        line.clear();
        let n = reader
            .read_line(&mut line)
            .with_context(|| format!("{}: cannot read", manifest.display()))?;
        if n == 0 || !line.ends_with('\n') {
            break;
        }
        let Ok(value) = serde_json::from_str::<serde_json::Value>(&line) else {
            break;
        };
        let Some(index) = value["index"].as_u64() else {
            break;
        };
        done.insert(index);
        good_len += n as u64;
    }
    let file = std::fs::OpenOptions::new()
        .write(true)
        .open(manifest)
        .with_context(|| format!("{}: cannot open for writing", manifest.display()))?;
    file.set_len(good_len)
        .with_context(|| format!("{}: cannot truncate", manifest.display()))?;
    Ok(done)
}

fn write_sample(dir: &Path, format: SampleFormat, s: &TactileSample) -> Result<Vec<String>> {
    let images = s.images.as_ref().expect("rendered before writing");
    let stem = sample_stem(s.draw.index);
    match format {
        SampleFormat::Png => {
            let sample_dir = dir.join(&stem);
            std::fs::create_dir_all(&sample_dir)
                .with_context(|| format!("{}: cannot create", sample_dir.display()))?;
            let names: Vec<String> = std::iter::once("reference.png".to_string())
                .chain((0..images.len() - 1).map(|k| format!("frame_{k}.png")))
                .collect();
            names.par_iter().zip(images).try_for_each(|(name, image)| {
                crate::report::output::write_png_atomic(&sample_dir.join(name), image)
            })?;
            Ok(names.iter().map(|n| format!("{stem}/{n}")).collect())
        }
        #[cfg(not(feature = "npz"))]
        SampleFormat::Npz => {
            let _ = (dir, stem, s);
            bail!("--format npz: this build has no NumPy archive writer (the `npz` feature)")
        }
        #[cfg(feature = "npz")]
        SampleFormat::Npz => {
            let (w, h) = images[0].dimensions();
            let (w, h) = (w as usize, h as usize);
            let frames: Vec<u8> = images.iter().flat_map(|i| i.as_raw().clone()).collect();
            let normal: Vec<f32> = s
                .press
                .frames
                .iter()
                .flat_map(|f| f.fields.normal_mm.iter().copied())
                .collect();
            let travel: Vec<f64> = s.press.frames.iter().map(|f| f.travel_mm).collect();
            let n = s.press.frames.len();
            let bytes = npz_bytes(&[
                NpyArray::u8("frames", vec![n + 1, h, w, 3], frames),
                NpyArray::f32("gel_normal_mm", vec![n, h, w], &normal),
                NpyArray::f64("travel_mm", vec![n], &travel),
            ])?;
            let name = format!("{stem}.npz");
            let path = dir.join(&name);
            if let Some(parent) = path.parent() {
                std::fs::create_dir_all(parent)
                    .with_context(|| format!("{}: cannot create", parent.display()))?;
            }
            write_bytes_atomic(&path, &bytes)?;
            Ok(vec![name])
        }
    }
}

/// Prepares DIR: checks or writes dataset.json. Errors name the path or the differing field.
fn prepare_dir(dir: &Path, info: &DatasetInfo) -> Result<()> {
    if dir.exists() && !dir.is_dir() {
        bail!("--out {}: exists and is not a directory", dir.display());
    }
    std::fs::create_dir_all(dir)
        .with_context(|| format!("--out {}: cannot create", dir.display()))?;
    let path = dir.join("dataset.json");
    if path.exists() {
        let text = tactex_core::text_file::read_to_string(&path)
            .with_context(|| format!("{}: cannot read", path.display()))?;
        let old: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{}: not valid JSON", path.display()))?;
        let new = serde_json::to_value(info)?;
        if old.get("sensor") != new.get("sensor") {
            let shown = |v: Option<&serde_json::Value>| {
                v.and_then(|v| serde_json::from_value::<ProfileId>(v.clone()).ok())
                    .map_or("no recorded sensor".into(), |id| id.to_string())
            };
            bail!(
                "{}: sensor: the data set is drawn around {}, this run around {}; a data set keeps one profile (use another --out)",
                path.display(),
                shown(old.get("sensor")),
                shown(new.get("sensor"))
            );
        }
        for (key, value) in new.as_object().expect("a struct") {
            if old.get(key) != Some(value) {
                bail!(
                    "{}: {key} is {} there but {} for this run; use another --out or the same settings",
                    path.display(),
                    old.get(key).map_or("missing".into(), |v| v.to_string()),
                    value
                );
            }
        }
        return Ok(());
    }
    write_json_atomic(&path, info)
}

/// What a run did.
pub struct DatagenSummary {
    pub new: u64,
    /// Redraws after presses that found no contact, over the new samples.
    pub redraws: u64,
    /// Mean search steps before contact, over the new samples.
    pub mean_search_steps: f64,
}

pub(crate) fn run(args: &TactileDatagenArgs) -> Result<()> {
    generate(args, true).map(|_| ())
}

pub(crate) fn generate(args: &TactileDatagenArgs, show_progress: bool) -> Result<DatagenSummary> {
    let shard = parse_shard(&args.shard)?;
    if args.count == 0 {
        bail!("--count: must be at least 1");
    }
    let source = TactileSampleSource::new(
        &args.fidelity,
        &args.shapes,
        args.sensor.as_deref(),
        args.seed,
    )?;
    let space = &source.space;
    let sensor = space.sensor.id();
    let protocol = PressProtocol::default();
    let optics = tactex_sim::render::gel::SensorOptics::for_profile(&space.sensor);
    let info = DatasetInfo {
        format: FORMAT.into(),
        count: args.count,
        seed: args.seed,
        sample_format: format!("{:?}", args.format).to_lowercase(),
        fidelity: space.fidelity.to_string(),
        shapes: space.families.iter().map(|f| f.to_string()).collect(),
        frames: protocol.frames,
        step_mm: space.step_mm,
        width: optics.width,
        height: optics.height,
        mm_per_px: optics.mm_per_px,
        sensor,
    };
    // The renderer first: a missing device fails before anything is written.
    let choice = open_renderer(args.device)?;
    if let Some(note) = &choice.note {
        eprintln!("note: {note}");
    }
    let mut renderer: Option<Box<dyn GelRenderer>> =
        (choice.renderer.name() != "cpu").then_some(choice.renderer);
    prepare_dir(&args.out, &info)?;
    // Shards of one data set run side by side; one shard has one writer.
    let lock_path = args.out.join(format!(
        "{}-shard-{}-of-{}",
        tactex_core::dir_claim::DATASET_LOCK,
        shard.0,
        shard.1
    ));
    let _lock = tactex_core::dir_claim::LockDir::claim(&lock_path, "writing this shard")
        .map_err(|e| anyhow::anyhow!("--out {}: {e}", args.out.display()))?;
    let manifest_path = shard_manifest(&args.out, shard);
    let done = resume(&manifest_path)?;
    // Drawn chunk by chunk from the index range: 10^8 samples need no list of their indices.
    let mut todo = (shard.0..args.count)
        .step_by(shard.1 as usize)
        .filter(|i| !done.contains(i));
    let total = args.count.saturating_sub(shard.0).div_ceil(shard.1);
    let in_shard =
        |i: &&u64| **i < args.count && **i >= shard.0 && (**i - shard.0).is_multiple_of(shard.1);
    let new_samples = total - done.iter().filter(in_shard).count() as u64;
    let bar = ProgressBar::new(total).with_style(
        ProgressStyle::with_template("{msg} [{bar:40}] {pos}/{len} samples, {per_sec}, eta {eta}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    bar.set_message(format!("shard {}/{}", shard.0, shard.1));
    let (mut redraws, mut search_steps) = (0u64, 0u64);
    bar.set_position(total - new_samples);
    let mut manifest = std::fs::OpenOptions::new()
        .create(true)
        .append(true)
        .open(&manifest_path)
        .with_context(|| format!("{}: cannot open", manifest_path.display()))?;
    let chunk = 4 * rayon::current_num_threads().max(1);
    let render_here = renderer.is_none();
    loop {
        let indices: Vec<u64> = todo.by_ref().take(chunk).collect();
        if indices.is_empty() {
            break;
        }
        let mut samples: Vec<TactileSample> = indices
            .par_iter()
            .map_init(ContactSolver::new, |solver, &i| {
                source.sample(solver, i, render_here)
            })
            .collect::<Result<_>>()?;
        if let Some(gpu) = renderer.as_mut() {
            for s in &mut samples {
                s.render_with(gpu.as_mut())?;
            }
        }
        let files: Vec<Vec<String>> = samples
            .par_iter()
            .map(|s| write_sample(&args.out, args.format, s))
            .collect::<Result<_>>()?;
        for (s, files) in samples.iter().zip(files) {
            redraws += s.draw.attempt as u64;
            search_steps += s.press.search_steps as u64;
            manifest
                .write_all(s.manifest_line(files)?.as_bytes())
                .with_context(|| format!("{}: write failed", manifest_path.display()))?;
            bar.inc(1);
        }
        manifest
            .sync_data()
            .with_context(|| format!("{}: sync failed", manifest_path.display()))?;
    }
    bar.finish_and_clear();
    if show_progress {
        eprintln!(
            "{}: shard {}/{}: {} samples ({} new) in {}",
            args.out.display(),
            shard.0,
            shard.1,
            total,
            new_samples,
            manifest_path.display()
        );
    }
    Ok(DatagenSummary {
        new: new_samples,
        redraws,
        mean_search_steps: search_steps as f64 / new_samples.max(1) as f64,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_bad_ones_are_refused() {
        assert_eq!(parse_shard("0/1").unwrap(), (0, 1));
        assert_eq!(parse_shard(" 3 / 4 ").unwrap(), (3, 4));
        for bad in ["4/4", "1/0", "x/2", "2", "-1/3", ""] {
            let e = parse_shard(bad).unwrap_err().to_string();
            assert!(e.starts_with("--shard"), "{bad}: {e}");
        }
    }
}
