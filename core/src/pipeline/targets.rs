//! The ground stage on the camera: detections for the query's targets, refined-mask
//! centroids from the depth median, a press site clear of the neighbours, and the query's
//! position filter.

use super::config::{PipelineConfig, PipelineError};
use crate::devices::RgbdCamera;
use crate::explain::location_words;
use crate::frames::DepthImage;
use crate::geometry::CameraIntrinsics;
use crate::ground::centroid::median_depth;
use crate::ground::colour_name::{colour_name, mean_colour};
use crate::ground::detect::{Detector, RgbdView};
use crate::ground::grounding::locate;
use crate::press::site::{HeightMap, PadClearance, PressSite, press_site};
use crate::query::{Query, Size, position_matches};
use glam::DVec3;

pub(super) struct Target {
    pub(super) label: String,
    pub(super) score: f64,
    pub(super) bbox: [u32; 4],
    pub(super) centre: DVec3,
    pub(super) surface: DVec3,
    pub(super) touch: DVec3,
    /// The pad's turn about the vertical for this press (see `press_site`).
    pub(super) pad_yaw_rad: f64,
    /// No site was clear of the neighbours by the grounding margin (see `press_site`).
    pub(super) crowded: bool,
    /// What the fruit asked about are held against ("than the banana on the left"), not
    /// asked about itself.
    pub(super) reference: bool,
    /// The area the object shows the camera (m^2), which "the bigger lime" picks by.
    pub(super) seen_area_m2: f64,
}

/// Detections for the query's targets, with refined-mask centroids from the depth median.
pub(super) fn ground<C: RgbdCamera>(
    query: &Query,
    camera: &mut C,
    detector: &dyn Detector,
    pad: &PadClearance,
    config: &PipelineConfig,
) -> Result<Vec<Target>, PipelineError> {
    let frames = (0..config.depth_frames.max(1))
        .map(|_| camera.capture())
        .collect::<Result<Vec<_>, _>>()?;
    let depths: Vec<_> = frames.iter().map(|f| &f.depth_m).collect();
    let depth = median_depth(&depths).ok_or_else(|| {
        PipelineError::Camera(format!("{}: depth frames differ in size", camera.name()))
    })?;
    let (k, pose) = (camera.intrinsics(), camera.pose());
    let view = RgbdView {
        color: &frames[0].color,
        depth: &depth,
        intrinsics: &k,
        pose: &pose,
    };
    let detections = detector.detect_for(&view, query)?;
    // Every pixel's point once: each target's press site looks at all the others.
    let (w, h) = depth.dimensions();
    let cloud: Vec<Option<DVec3>> = (0..h)
        .flat_map(|v| (0..w).map(move |u| (u, v)))
        .map(|(u, v)| {
            let z = f64::from(depth.get_pixel(u, v)[0]);
            (z > 0.0 && z.is_finite())
                .then(|| pose.transform_point(k.back_project(f64::from(u), f64::from(v), z)))
        })
        .collect();
    let candidates: Vec<Target> = detections
        .iter()
        .enumerate()
        .filter_map(|(i, d)| {
            let at = locate(&d.mask, true, &depth, &k, &pose)?;
            // The filters choose the fruit asked about, not the one they are held against.
            if query.filters.color.is_some() && !query.is_reference(&d.label) {
                let colour = mean_colour(&frames[0].color, &at.mask).map_or("grey", colour_name);
                if !query.filters.colour_matches(colour) {
                    return None;
                }
            }
            let site = clear_touch(at.touch, i, &detections, &cloud, pad).unwrap_or(PressSite {
                at: at.touch,
                yaw_rad: 0.0,
                crowded: false,
            });
            Some(Target {
                label: d.label.clone(),
                score: d.score,
                bbox: d.bbox,
                centre: at.centre,
                surface: at.surface,
                touch: site.at,
                pad_yaw_rad: site.yaw_rad,
                crowded: site.crowded,
                reference: false,
                seen_area_m2: seen_area_m2(&d.mask, &depth, &k),
            })
        })
        .collect();
    let mut targets = apply_size(query, apply_position(query, candidates));
    // A stable order: left to right, then front to back.
    targets.sort_by(|a, b| {
        (a.centre.x, a.centre.y)
            .partial_cmp(&(b.centre.x, b.centre.y))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    Ok(targets)
}

/// Where the pad can press detection `index` without meeting anything else first (see
/// `press_site`); None when the detection has no depth points.
/// The object's own points are its mask's; everything else is the other detections' and
/// whatever lies more than a few pixels outside its mask (its own flank just outside the mask
/// is not an obstacle).
pub(super) fn clear_touch(
    crest: DVec3,
    index: usize,
    detections: &[crate::ground::detect::Detection],
    cloud: &[Option<DVec3>],
    pad: &PadClearance,
) -> Option<PressSite> {
    let mask = &detections[index].mask;
    // Holes in the mask (a highlight, a dropout) are the object's own, not obstacles.
    let near = imageproc::morphology::dilate(
        &fill_holes(mask),
        imageproc::distance_transform::Norm::LInf,
        4,
    );
    let in_other = |at: usize| {
        detections
            .iter()
            .enumerate()
            .any(|(j, d)| j != index && d.mask.as_raw().get(at).is_some_and(|m| *m > 0))
    };
    let (mut own, mut others) = (Vec::new(), Vec::new());
    for (at, p) in cloud.iter().enumerate() {
        let Some(p) = p else { continue };
        if mask.as_raw().get(at).is_some_and(|m| *m > 0) {
            own.push(*p);
        } else if near.as_raw().get(at).is_none_or(|m| *m == 0) || in_other(at) {
            others.push(*p);
        }
    }
    const CELL_M: f64 = 0.002;
    press_site(
        crest,
        &HeightMap::new(&own, CELL_M)?,
        &HeightMap::new(&others, CELL_M)?,
        pad,
    )
}

/// `mask` with every background region that does not reach the image's border filled.
pub(super) fn fill_holes(mask: &image::GrayImage) -> image::GrayImage {
    use imageproc::region_labelling::{Connectivity, connected_components};
    let background = image::GrayImage::from_fn(mask.width(), mask.height(), |x, y| {
        image::Luma([if mask.get_pixel(x, y)[0] > 0 { 0 } else { 255 }])
    });
    let regions = connected_components(&background, Connectivity::Four, image::Luma([0u8]));
    let (w, h) = mask.dimensions();
    let mut outside = std::collections::HashSet::new();
    for (x, y, l) in regions.enumerate_pixels() {
        if l[0] > 0 && (x == 0 || y == 0 || x + 1 == w || y + 1 == h) {
            outside.insert(l[0]);
        }
    }
    image::GrayImage::from_fn(w, h, |x, y| {
        let l = regions.get_pixel(x, y)[0];
        image::Luma([if l == 0 || !outside.contains(&l) {
            255
        } else {
            0
        }])
    })
}

/// Targets whose location matches the query's position filter, and the reference at the
/// reference's place ("than the banana on the left") marked as the reference, in their
/// order. When none is at the place asked ("the fruit on the left" with every fruit right of
/// centre), the one furthest that way answers. The reference's other instances are asked
/// about when their kind is ("Which banana is softer than the banana on the left?").
pub(super) fn apply_position(query: &Query, targets: Vec<Target>) -> Vec<Target> {
    let filter = query.filters.position.as_deref();
    let reference_place = query.relation.as_ref().and_then(|r| r.position.as_deref());
    // The fruit asked about and the reference are placed each by their own words.
    let (references, mut asked): (Vec<Indexed>, Vec<Indexed>) = targets
        .into_iter()
        .enumerate()
        .partition(|(_, t)| query.is_reference(&t.label));
    let references = match reference_place {
        Some(place) => {
            let (there, others) = placed(place, references);
            asked.extend(
                others
                    .into_iter()
                    .filter(|(_, t)| query.asks_about_kind(&t.label)),
            );
            there
        }
        None => references,
    };
    let mut kept = match filter {
        Some(place) => placed(place, asked).0,
        None => asked,
    };
    kept.extend(references.into_iter().map(|(i, t)| {
        (
            i,
            Target {
                reference: true,
                ..t
            },
        )
    }));
    kept.sort_by_key(|(i, _)| *i);
    kept.into_iter().map(|(_, t)| t).collect()
}

/// The area a mask shows the camera (m^2): each pixel with a depth z covers (z / fx)(z / fy)
/// facing it, so near and far objects compare by their true size.
fn seen_area_m2(mask: &image::GrayImage, depth: &DepthImage, k: &CameraIntrinsics) -> f64 {
    mask.enumerate_pixels()
        .filter(|(_, _, m)| m[0] > 0)
        .filter_map(|(u, v, _)| {
            let z = f64::from(depth.get_pixel_checked(u, v)?[0]);
            (z > 0.0 && z.is_finite()).then(|| (z / k.fx) * (z / k.fy))
        })
        .sum()
}

/// The one target asked about that shows the camera the most or least area, with the
/// references, when the prompt picks by size ("the bigger lime"); all of them otherwise.
pub(super) fn apply_size(query: &Query, targets: Vec<Target>) -> Vec<Target> {
    let Some(size) = query.filters.size else {
        return targets;
    };
    let area = |t: &Target| match size {
        Size::Largest => t.seen_area_m2,
        Size::Smallest => -t.seen_area_m2,
    };
    let pick = targets
        .iter()
        .enumerate()
        .filter(|(_, t)| !t.reference)
        .max_by(|(_, a), (_, b)| area(a).total_cmp(&area(b)))
        .map(|(i, _)| i);
    targets
        .into_iter()
        .enumerate()
        .filter(|(i, t)| t.reference || Some(*i) == pick)
        .map(|(_, t)| t)
        .collect()
}

/// A target with its index among the targets, so that placing keeps their order.
type Indexed = (usize, Target);

/// The targets at `place`, or the one furthest that way; and the others.
fn placed(place: &str, targets: Vec<Indexed>) -> (Vec<Indexed>, Vec<Indexed>) {
    let located = |t: &Target| location_words(t.centre.x, t.centre.y);
    let matches = |(_, t): &Indexed| position_matches(place, &located(t));
    if targets.iter().any(matches) {
        return targets.into_iter().partition(matches);
    }
    // How far a target lies in the filter's direction (x right, y back).
    let toward = |(_, t): &Indexed| -> f64 {
        place
            .split(' ')
            .map(|w| match w {
                "left" => -t.centre.x,
                "right" => t.centre.x,
                "front" => -t.centre.y,
                "back" => t.centre.y,
                _ => -t.centre.truncate().length(),
            })
            .sum()
    };
    let furthest = targets
        .iter()
        .enumerate()
        .max_by(|(_, a), (_, b)| toward(a).total_cmp(&toward(b)))
        .map(|(k, _)| k);
    let (there, others): (Vec<_>, Vec<_>) = targets
        .into_iter()
        .enumerate()
        .partition(|(k, _)| Some(*k) == furthest);
    (
        there.into_iter().map(|(_, t)| t).collect(),
        others.into_iter().map(|(_, t)| t).collect(),
    )
}
