//! `tactex datagen scenes`: synthetic RGB-D scenes with YOLO segmentation labels, for
//! training real fruit detectors (Ultralytics trains on DIR/data.yaml as is).
//!
//! Layout of DIR (scene files are `scene_NNNNNN.*`, in `train/` or `val/`):
//! * `images/{train,val}/`: colour PNG, 640x480, with the camera's colour noise;
//! * `labels/{train,val}/`: one line per visible fruit, `class x1 y1 x2 y2 ...`, the outer
//!   contour of its mask as a polygon normalised to [0, 1] (Ultralytics' segment format);
//! * `depth/{train,val}/`: 16-bit PNG, depth in mm (0 = no depth), D435 noise on;
//! * `instances/{train,val}/`: 16-bit PNG of instance ids (0 table, i + 1 object i);
//! * `meta/{train,val}/`: JSON ground truth: intrinsics, camera pose, and per object its
//!   class, ripeness, modulus, 3D centre and pixel box;
//! * `dataset.json`: the settings (a second run into DIR must match them); `data.yaml`,
//!   written last; `preview.png`: the first scenes with their polygons drawn.
//!
//! Scene i is drawn from (seed, i) alone. Each scene's label file is written last, so a rerun
//! skips scenes with a label file and redoes the rest.

use crate::report::output::{
    write_bytes_atomic, write_json_atomic, write_png_atomic, write_png16_atomic,
};
use crate::report::palette::class_colour;
use anyhow::{Context, Result, bail};
use clap::Args;
use image::{GrayImage, RgbImage};
use imageproc::contours::{BorderType, find_contours};
use imageproc::geometry::approximate_polygon_dp;
use imageproc::point::Point;
use indicatif::{ProgressBar, ProgressStyle};
use rand::seq::IndexedRandom;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::dir_claim::LockDir;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::ground::mask::mask_box;
use tactex_sim::SimDevices;
use tactex_sim::datagen::scene_random::{Variation, random_scene};
use tactex_sim::devices::camera::{InstanceImage, instance_mask};
use tactex_sim::render::device::DeviceChoice;
use tactex_sim::render::scene::SceneRenderer;

const FORMAT: &str = "tactex-scene-dataset/1";
/// Douglas-Peucker tolerance of the label polygons (px): keeps them within a pixel of the
/// mask outline at a tenth of the points.
const POLYGON_TOLERANCE_PX: f64 = 0.8;
/// Fruits showing fewer pixels than this get no label (a sliver at the image edge).
const MIN_VISIBLE_PX: u32 = 40;
const PREVIEW_SCENES: usize = 4;

#[derive(Args, Debug)]
pub struct SceneDatagenArgs {
    /// Scenes in the data set; 1 to 10000000.
    #[arg(long, value_parser = crate::app::flag_range::count::<usize>(1, 10_000_000))]
    pub count: usize,
    /// Output directory.
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// Fruits per scene, MIN-MAX, at most 12 (kinds drawn with repeats, so "both bananas" scenes occur; large kinds fit fewer).
    #[arg(long, default_value = "1-6")]
    pub fruits: String,
    /// Fruit kinds to draw from (catalog names, comma-separated); all catalog fruits if unset.
    #[arg(long, value_delimiter = ',')]
    pub kinds: Vec<String>,
    /// Share of scenes in the validation split, 0 to under 1, spread evenly over the indices.
    #[arg(long, default_value_t = 0.2)]
    pub val_fraction: f64,
    /// Device that renders the scenes: cpu (the default, so that the data never depends on
    /// the machine), gpu (any Vulkan adapter) or auto (a hardware GPU if there is one).
    #[arg(long, default_value = "cpu")]
    pub device: DeviceChoice,
}

/// Settings every run into one directory shares.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
struct DatasetInfo {
    format: String,
    count: usize,
    seed: u64,
    fruits: [usize; 2],
    kinds: Vec<String>,
    val_fraction: f64,
    classes: Vec<String>,
    width: u32,
    height: u32,
    depth_unit_m: f64,
    /// "cpu" or "gpu": the two agree to f32 precision, not to the byte, so one data set
    /// keeps to one. Sets from before the GPU path were rendered on the CPU.
    #[serde(default = "cpu_renderer")]
    renderer: String,
}

fn cpu_renderer() -> String {
    "cpu".into()
}

#[derive(Serialize)]
struct SceneMeta {
    index: usize,
    split: &'static str,
    seed: u64,
    intrinsics: CameraIntrinsics,
    camera_pose: Pose,
    depth_unit_m: f64,
    objects: Vec<ObjectMeta>,
}

#[derive(Serialize)]
struct ObjectMeta {
    instance_id: u16,
    class: Option<usize>,
    label: String,
    ripeness: Option<String>,
    modulus_mpa: Option<f64>,
    centre_m: [f64; 3],
    visible_px: u32,
    /// Pixel box of the visible mask, [x_min, y_min, x_max, y_max] (inclusive pixels).
    box_px: Option<[u32; 4]>,
    /// Whether a label line was written (visible and at least `MIN_VISIBLE_PX`).
    labelled: bool,
}

/// Fruits one scene may ask for: the demo table holds about ten of mixed kinds (fewer
/// bananas); beyond that no draw fits.
pub const MAX_FRUITS: usize = 12;

fn parse_range(text: &str) -> Result<[usize; 2]> {
    let parsed = match text.split_once('-') {
        Some((a, b)) => a.trim().parse().ok().zip(b.trim().parse().ok()),
        None => text.trim().parse().ok().map(|n| (n, n)),
    };
    match parsed {
        Some((lo, hi)) if 1 <= lo && lo <= hi && hi <= MAX_FRUITS => Ok([lo, hi]),
        _ => bail!(
            "--fruits: '{text}' is not MIN-MAX with 1 <= MIN <= MAX <= {MAX_FRUITS} (e.g. 1-6)"
        ),
    }
}

/// The split of scene `index`: validation scenes spread evenly over the indices.
fn split(index: usize, val_fraction: f64) -> &'static str {
    let val = ((index + 1) as f64 * val_fraction).floor() > (index as f64 * val_fraction).floor();
    if val { "val" } else { "train" }
}

fn scene_seed(seed: u64, index: usize) -> u64 {
    seed.wrapping_mul(0x9e37_79b9_7f4a_7c15)
        .wrapping_add(index as u64)
}

/// The outer contour of a mask's largest region, simplified, as polygon vertices (pixel
/// coordinates, the convention of OpenCV's contours that Ultralytics' converters use).
fn mask_polygon(mask: &GrayImage) -> Option<Vec<Point<i32>>> {
    let contours = find_contours::<i32>(mask);
    let outer = contours
        .iter()
        .filter(|c| c.border_type == BorderType::Outer && c.points.len() >= 3)
        .max_by(|a, b| polygon_area(&a.points).total_cmp(&polygon_area(&b.points)))?;
    let polygon = approximate_polygon_dp(&outer.points, POLYGON_TOLERANCE_PX, true);
    (polygon.len() >= 3).then_some(polygon)
}

fn polygon_area(points: &[Point<i32>]) -> f64 {
    let n = points.len();
    (0..n)
        .map(|i| {
            let (a, b) = (points[i], points[(i + 1) % n]);
            (a.x as f64) * (b.y as f64) - (b.x as f64) * (a.y as f64)
        })
        .sum::<f64>()
        .abs()
        / 2.0
}

fn label_line(class: usize, polygon: &[Point<i32>], width: u32, height: u32) -> String {
    let mut line = class.to_string();
    for p in polygon {
        let x = (p.x as f64 / width as f64).clamp(0.0, 1.0);
        let y = (p.y as f64 / height as f64).clamp(0.0, 1.0);
        line.push_str(&format!(" {x:.6} {y:.6}"));
    }
    line
}

struct Rendered {
    color: RgbImage,
    depth_mm: Vec<u16>,
    instances: InstanceImage,
    meta: SceneMeta,
    label: String,
    polygons: Vec<(usize, Vec<Point<i32>>)>,
}

fn render_scene(
    index: usize,
    info: &DatasetInfo,
    catalog: &FruitCatalog,
    renderer: &Arc<dyn SceneRenderer>,
) -> Result<Rendered> {
    let seed = scene_seed(info.seed, index);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = rng.random_range(info.fruits[0]..=info.fruits[1]);
    let kinds: Vec<&str> = (0..n)
        .map(|_| info.kinds.choose(&mut rng).expect("kinds checked").as_str())
        .collect();
    let scene = random_scene(&kinds, catalog, seed, &Variation::default())
        .with_context(|| format!("scene {index}"))?;
    let mut sim = SimDevices::from_scene(&scene, seed).with_context(|| format!("scene {index}"))?;
    sim.camera.set_renderer(renderer.clone());
    let clean = sim.camera.clean()?.clone();
    let frame = sim
        .camera
        .capture()
        .with_context(|| format!("scene {index}"))?;
    let (k, pose) = (sim.camera.intrinsics(), sim.camera.pose());
    let depth_mm = frame
        .depth_m
        .iter()
        .map(|z| (*z as f64 / info.depth_unit_m).round().clamp(0.0, 65535.0) as u16)
        .collect();
    let centres: Vec<[f64; 3]> = {
        let world = sim.world.lock().expect("world lock");
        world.objects.iter().map(|o| o.centre.to_array()).collect()
    };
    let mut objects = Vec::new();
    let mut lines = Vec::new();
    let mut polygons = Vec::new();
    for (i, object) in scene.objects.iter().enumerate() {
        let id = i as u16 + 1;
        let mask = instance_mask(&clean.instances, id);
        let class = info.classes.iter().position(|c| *c == object.label);
        let boxed = mask_box(&mask);
        let visible_px = boxed.map_or(0, |(_, n)| n);
        let polygon = (visible_px >= MIN_VISIBLE_PX)
            .then(|| mask_polygon(&mask))
            .flatten();
        let labelled = class.is_some() && polygon.is_some();
        if let (Some(class), Some(polygon)) = (class, polygon) {
            lines.push(label_line(class, &polygon, k.width, k.height));
            polygons.push((class, polygon));
        }
        objects.push(ObjectMeta {
            instance_id: id,
            class,
            label: object.label.clone(),
            ripeness: object.ripeness.clone(),
            modulus_mpa: object.hardness.modulus_mpa(),
            centre_m: centres[i],
            visible_px,
            box_px: boxed.map(|(b, _)| b),
            labelled,
        });
    }
    let mut label = lines.join("\n");
    if !label.is_empty() {
        label.push('\n');
    }
    Ok(Rendered {
        color: frame.color,
        depth_mm,
        instances: clean.instances,
        meta: SceneMeta {
            index,
            split: split(index, info.val_fraction),
            seed,
            intrinsics: k,
            camera_pose: pose,
            depth_unit_m: info.depth_unit_m,
            objects,
        },
        label,
        polygons,
    })
}

fn scene_paths(dir: &Path, index: usize, split: &str) -> [PathBuf; 5] {
    let stem = format!("scene_{index:06}");
    [
        dir.join(format!("images/{split}/{stem}.png")),
        dir.join(format!("labels/{split}/{stem}.txt")),
        dir.join(format!("depth/{split}/{stem}.png")),
        dir.join(format!("instances/{split}/{stem}.png")),
        dir.join(format!("meta/{split}/{stem}.json")),
    ]
}

fn write_scene(dir: &Path, r: &Rendered) -> Result<()> {
    let [image, label, depth, instances, meta] = scene_paths(dir, r.meta.index, r.meta.split);
    let (w, h) = r.color.dimensions();
    write_png16_atomic(&depth, w, h, r.depth_mm.clone())?;
    write_png16_atomic(&instances, w, h, r.instances.as_raw().clone())?;
    write_json_atomic(&meta, &r.meta)?;
    write_png_atomic(&image, &r.color)?;
    // Last: a label file marks the scene complete.
    write_bytes_atomic(&label, r.label.as_bytes())
}

/// Ultralytics' data.yaml. `path` is absolute: Ultralytics resolves a relative one against
/// its own datasets directory, not against the file.
fn data_yaml(root: &Path, info: &DatasetInfo) -> String {
    let mut text = format!(
        "# TactEx twin synthetic fruit scenes: {} scenes, seed {}, {}-{} fruits each.\n\
         # Written by `tactex datagen scenes`; depth, instance ids and ground truth in \
         depth/, instances/, meta/.\n\
         path: {}\ntrain: images/train\nval: images/val\nnc: {}\nnames:\n",
        info.count,
        info.seed,
        info.fruits[0],
        info.fruits[1],
        yaml_string(&root.display().to_string()),
        info.classes.len()
    );
    for (i, name) in info.classes.iter().enumerate() {
        text.push_str(&format!("  {i}: {}\n", yaml_string(name)));
    }
    text
}

/// A YAML double-quoted scalar.
fn yaml_string(s: &str) -> String {
    format!("{:?}", s)
}

fn preview(rendered: &[Rendered]) -> Option<RgbImage> {
    let first = rendered.first()?;
    let (w, h) = first.color.dimensions();
    let cols = rendered.len().min(2) as u32;
    let rows = rendered.len().div_ceil(2) as u32;
    let mut sheet = RgbImage::new(w * cols, h * rows);
    for (n, r) in rendered.iter().enumerate() {
        let (ox, oy) = ((n as u32 % 2) * w, (n as u32 / 2) * h);
        image::imageops::replace(&mut sheet, &r.color, ox as i64, oy as i64);
        for (class, polygon) in &r.polygons {
            let colour = class_colour(*class);
            for i in 0..polygon.len() {
                let (a, b) = (polygon[i], polygon[(i + 1) % polygon.len()]);
                imageproc::drawing::draw_line_segment_mut(
                    &mut sheet,
                    ((a.x as u32 + ox) as f32, (a.y as u32 + oy) as f32),
                    ((b.x as u32 + ox) as f32, (b.y as u32 + oy) as f32),
                    colour,
                );
            }
        }
    }
    Some(sheet)
}

pub struct SceneDatagenSummary {
    pub written: usize,
    pub skipped: usize,
    pub labels: usize,
}

pub(crate) fn run(args: &SceneDatagenArgs) -> Result<()> {
    let summary = generate(args, true)?;
    eprintln!(
        "{}: {} scenes ({} new, {} already there), {} labelled fruits in the new ones; \
         train with data.yaml",
        args.out.display(),
        summary.written + summary.skipped,
        summary.written,
        summary.skipped,
        summary.labels
    );
    Ok(())
}

pub(crate) fn generate(
    args: &SceneDatagenArgs,
    show_progress: bool,
) -> Result<SceneDatagenSummary> {
    if args.count == 0 {
        bail!("--count: must be at least 1");
    }
    if !(0.0..1.0).contains(&args.val_fraction) {
        bail!("--val-fraction: {} is not in [0, 1)", args.val_fraction);
    }
    let fruits = parse_range(&args.fruits)?;
    let catalog = FruitCatalog::builtin();
    let classes: Vec<String> = catalog.names().iter().map(|s| s.to_string()).collect();
    let kinds = if args.kinds.is_empty() {
        classes.clone()
    } else {
        for kind in &args.kinds {
            if catalog.get(kind).is_none() {
                bail!(
                    "--kinds: '{kind}' is not in the fruit catalog (known: {})",
                    classes.join(", ")
                );
            }
        }
        args.kinds.clone()
    };
    // The renderer first: a missing device fails before anything is written.
    let renderer = crate::app::scene_renderer(args.device)?;
    let info = DatasetInfo {
        format: FORMAT.into(),
        count: args.count,
        seed: args.seed,
        fruits,
        kinds,
        val_fraction: args.val_fraction,
        classes,
        width: 640,
        height: 480,
        depth_unit_m: 0.001,
        renderer: if renderer.name() == "cpu" {
            "cpu"
        } else {
            "gpu"
        }
        .into(),
    };
    let existed = args.out.exists();
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("{}: cannot create the directory", args.out.display()))?;
    let root = args
        .out
        .canonicalize()
        .with_context(|| format!("{}: cannot resolve", args.out.display()))?;
    let lock = LockDir::claim(
        &root.join(tactex_core::dir_claim::DATASET_LOCK),
        "writing this data set",
    )
    .map_err(|e| anyhow::anyhow!("--out {}: {e}", args.out.display()))?;
    let result = fill(&root, args, &info, &catalog, &renderer, show_progress);
    drop(lock);
    if result.is_err() && !has_scenes(&root) {
        // Nothing usable was written: leave the directory as it was, so that a corrected run
        // starts clean.
        if existed {
            let _ = std::fs::remove_file(root.join("dataset.json"));
            for sub in SUBDIRS {
                for split in ["train", "val"] {
                    let _ = std::fs::remove_dir(root.join(sub).join(split));
                }
                let _ = std::fs::remove_dir(root.join(sub));
            }
        } else {
            let _ = std::fs::remove_dir_all(&root);
        }
    }
    result
}

const SUBDIRS: [&str; 5] = ["images", "labels", "depth", "instances", "meta"];

/// Whether any scene is complete (its label file, written last, exists).
fn has_scenes(root: &Path) -> bool {
    ["train", "val"].iter().any(|split| {
        std::fs::read_dir(root.join("labels").join(split))
            .is_ok_and(|mut entries| entries.next().is_some())
    })
}

fn fill(
    root: &Path,
    args: &SceneDatagenArgs,
    info: &DatasetInfo,
    catalog: &FruitCatalog,
    renderer: &Arc<dyn SceneRenderer>,
    show_progress: bool,
) -> Result<SceneDatagenSummary> {
    let info_path = root.join("dataset.json");
    // Settings are fixed once a scene is written; before that a new run may change them.
    if info_path.exists() && has_scenes(root) {
        let text = std::fs::read_to_string(&info_path)
            .with_context(|| format!("{}: cannot read", info_path.display()))?;
        let theirs: DatasetInfo = serde_json::from_str(&text)
            .with_context(|| format!("{}: not a tactex scene data set", info_path.display()))?;
        if theirs != *info {
            let (theirs, ours) = (serde_json::to_value(&theirs)?, serde_json::to_value(info)?);
            let fields: Vec<&str> = ours
                .as_object()
                .expect("a struct")
                .iter()
                .filter(|(k, v)| theirs.get(k.as_str()) != Some(*v))
                .map(|(k, _)| k.as_str())
                .collect();
            bail!(
                "{}: this directory holds a data set with other settings (differing: {}); use another --out",
                info_path.display(),
                fields.join(", ")
            );
        }
    } else {
        write_json_atomic(&info_path, info)?;
    }
    for sub in SUBDIRS {
        for split in ["train", "val"] {
            let dir = root.join(sub).join(split);
            std::fs::create_dir_all(&dir)
                .with_context(|| format!("{}: cannot create the directory", dir.display()))?;
        }
    }
    let todo: Vec<usize> = (0..args.count)
        .filter(|&i| !scene_paths(root, i, split(i, info.val_fraction))[1].exists())
        .collect();
    let bar = ProgressBar::new(todo.len() as u64).with_style(
        ProgressStyle::with_template("scenes [{bar:40}] {pos}/{len}, {per_sec}, eta {eta}")
            .expect("a valid template")
            .progress_chars("=> "),
    );
    if !show_progress {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    let labels = todo
        .par_iter()
        .map(|&i| -> Result<(usize, Option<Rendered>)> {
            let r = render_scene(i, info, catalog, renderer)?;
            write_scene(root, &r)?;
            bar.inc(1);
            let n = r.polygons.len();
            Ok((n, (i < PREVIEW_SCENES).then_some(r)))
        })
        .collect::<Result<Vec<_>>>()?;
    bar.finish_and_clear();
    let new_labels = labels.iter().map(|(n, _)| n).sum();
    let previews: Vec<Rendered> = labels.into_iter().filter_map(|(_, r)| r).collect();
    if let Some(sheet) = preview(&previews) {
        write_png_atomic(&root.join("preview.png"), &sheet)?;
    }
    write_bytes_atomic(&root.join("data.yaml"), data_yaml(root, info).as_bytes())?;
    Ok(SceneDatagenSummary {
        written: todo.len(),
        skipped: args.count - todo.len(),
        labels: new_labels,
    })
}
