//! A YOLOv8-seg detector: an Ultralytics segmentation model exported to ONNX, run through
//! `runtime` (tract by default, ONNX Runtime with ORT_DYLIB_PATH). Ultralytics'
//! post-processing, reimplemented: letterbox to the model's input, decode the
//! [1, 4 + classes + 32, anchors] predictions (centre-size boxes in input pixels, sigmoid
//! class scores, mask coefficients), per-class NMS, and masks from the [1, 32, H/4, W/4]
//! prototypes (sigmoid of coefficients times prototypes, cropped to the box, upsampled
//! bilinearly), mapped back to the camera image.

use crate::metadata::{metadata_props, ultralytics_names};
use crate::runtime::{OnnxError, backend, open_session};
use image::{GrayImage, Luma, RgbImage};
use ort::session::Session;
use ort::value::Tensor;
use std::path::Path;
use std::sync::Mutex;
use tactex_core::ground::detect::{DetectError, Detection, Detector, RgbdView, mask_footprint};

/// Ultralytics' prediction defaults.
#[derive(Clone, Copy, Debug)]
pub struct YoloSettings {
    pub confidence: f64,
    pub iou: f64,
    pub max_detections: usize,
}

impl Default for YoloSettings {
    fn default() -> Self {
        Self {
            confidence: 0.25,
            iou: 0.7,
            max_detections: 300,
        }
    }
}

/// Letterbox geometry: image pixel (x, y) sits at input pixel (x * scale + left, y * scale
/// + top); padding is grey 114 as in Ultralytics.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Letterbox {
    pub scale: f64,
    pub left: f64,
    pub top: f64,
    pub input_w: usize,
    pub input_h: usize,
}

impl Letterbox {
    pub fn new(image_w: u32, image_h: u32, input_w: usize, input_h: usize) -> Self {
        let scale = (input_w as f64 / image_w as f64).min(input_h as f64 / image_h as f64);
        let (new_w, new_h) = (
            (image_w as f64 * scale).round(),
            (image_h as f64 * scale).round(),
        );
        // Ultralytics splits the padding as round(d / 2 - 0.1) before the image.
        let left = ((input_w as f64 - new_w) / 2.0 - 0.1).round();
        let top = ((input_h as f64 - new_h) / 2.0 - 0.1).round();
        Self {
            scale,
            left,
            top,
            input_w,
            input_h,
        }
    }

    /// The model input, CHW float in [0, 1]: the image resized bilinearly (pixel centres,
    /// as OpenCV's INTER_LINEAR) into the padded frame.
    pub fn input(&self, image: &RgbImage) -> Vec<f32> {
        let (w, h) = (self.input_w, self.input_h);
        let mut data = vec![114.0 / 255.0; 3 * w * h];
        let (iw, ih) = image.dimensions();
        let new_w = (iw as f64 * self.scale).round() as usize;
        let new_h = (ih as f64 * self.scale).round() as usize;
        let (sx, sy) = (iw as f64 / new_w as f64, ih as f64 / new_h as f64);
        for y in 0..new_h {
            let fy = ((y as f64 + 0.5) * sy - 0.5).clamp(0.0, ih as f64 - 1.0);
            let (y0, ty) = (fy.floor() as u32, fy - fy.floor());
            let y1 = (y0 + 1).min(ih - 1);
            for x in 0..new_w {
                let fx = ((x as f64 + 0.5) * sx - 0.5).clamp(0.0, iw as f64 - 1.0);
                let (x0, tx) = (fx.floor() as u32, fx - fx.floor());
                let x1 = (x0 + 1).min(iw - 1);
                let (ox, oy) = (x + self.left as usize, y + self.top as usize);
                if ox >= w || oy >= h {
                    continue;
                }
                for c in 0..3 {
                    let at = |x, y| f64::from(image.get_pixel(x, y)[c]);
                    let v = (at(x0, y0) * (1.0 - tx) + at(x1, y0) * tx) * (1.0 - ty)
                        + (at(x0, y1) * (1.0 - tx) + at(x1, y1) * tx) * ty;
                    data[c * w * h + oy * w + ox] = (v / 255.0) as f32;
                }
            }
        }
        data
    }

    /// Input pixel coordinates to image pixel coordinates.
    pub fn to_image(&self, x: f64, y: f64) -> (f64, f64) {
        ((x - self.left) / self.scale, (y - self.top) / self.scale)
    }
}

/// One decoded prediction, in input pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    pub class: usize,
    pub score: f64,
    /// x0, y0, x1, y1.
    pub xyxy: [f64; 4],
    pub coefficients: Vec<f32>,
}

/// Candidates above `confidence` from predictions laid out [channels, anchors] (row-major),
/// channels = 4 + classes + mask coefficients.
pub fn decode(
    predictions: &[f32],
    anchors: usize,
    classes: usize,
    coefficients: usize,
    confidence: f64,
) -> Vec<Candidate> {
    let at = |c: usize, a: usize| predictions[c * anchors + a];
    (0..anchors)
        .filter_map(|a| {
            let (class, score) = (0..classes)
                .map(|c| (c, at(4 + c, a)))
                .max_by(|x, y| x.1.total_cmp(&y.1))?;
            // NaN scores fail this test too.
            if f64::from(score).partial_cmp(&confidence) != Some(std::cmp::Ordering::Greater) {
                return None;
            }
            let (cx, cy, w, h) = (at(0, a), at(1, a), at(2, a), at(3, a));
            let xyxy = [cx - w / 2.0, cy - h / 2.0, cx + w / 2.0, cy + h / 2.0].map(f64::from);
            if xyxy.iter().any(|v| !v.is_finite()) {
                return None;
            }
            Some(Candidate {
                class,
                score: f64::from(score),
                xyxy,
                coefficients: (0..coefficients).map(|k| at(4 + classes + k, a)).collect(),
            })
        })
        .collect()
}

fn box_iou(a: &[f64; 4], b: &[f64; 4]) -> f64 {
    let iw = (a[2].min(b[2]) - a[0].max(b[0])).max(0.0);
    let ih = (a[3].min(b[3]) - a[1].max(b[1])).max(0.0);
    let inter = iw * ih;
    let area = |r: &[f64; 4]| (r[2] - r[0]).max(0.0) * (r[3] - r[1]).max(0.0);
    let union = area(a) + area(b) - inter;
    if union > 0.0 { inter / union } else { 0.0 }
}

/// Greedy per-class non-maximum suppression, best score first, at most `max` kept.
fn non_max_suppression(mut candidates: Vec<Candidate>, iou: f64, max: usize) -> Vec<Candidate> {
    candidates.sort_by(|a, b| b.score.total_cmp(&a.score));
    let mut kept: Vec<Candidate> = Vec::new();
    for c in candidates {
        if kept.len() >= max {
            break;
        }
        if kept
            .iter()
            .all(|k| k.class != c.class || box_iou(&k.xyxy, &c.xyxy) <= iou)
        {
            kept.push(c);
        }
    }
    kept
}

/// Prototype masks [k, mh, mw] (row-major) for an input of `input_w` x `input_h`.
pub struct Prototypes<'a> {
    pub data: &'a [f32],
    pub k: usize,
    pub mh: usize,
    pub mw: usize,
}

impl Prototypes<'_> {
    /// The candidate's mask on a `width` x `height` camera image: mask logits (coefficients
    /// times prototypes) sampled bilinearly at each pixel's place in the input, positive
    /// inside the box.
    pub fn mask(&self, c: &Candidate, letterbox: &Letterbox, width: u32, height: u32) -> GrayImage {
        let (sx, sy) = (
            self.mw as f64 / letterbox.input_w as f64,
            self.mh as f64 / letterbox.input_h as f64,
        );
        // Logits over the prototype cells the box touches (plus one for interpolation).
        let px0 = ((c.xyxy[0] * sx).floor() as i64 - 1).clamp(0, self.mw as i64 - 1) as usize;
        let py0 = ((c.xyxy[1] * sy).floor() as i64 - 1).clamp(0, self.mh as i64 - 1) as usize;
        let px1 = ((c.xyxy[2] * sx).ceil() as i64 + 1).clamp(0, self.mw as i64 - 1) as usize;
        let py1 = ((c.xyxy[3] * sy).ceil() as i64 + 1).clamp(0, self.mh as i64 - 1) as usize;
        let (gw, gh) = (px1 - px0 + 1, py1 - py0 + 1);
        let mut logits = vec![0f32; gw * gh];
        for (j, coefficient) in c.coefficients.iter().enumerate().take(self.k) {
            let plane = &self.data[j * self.mh * self.mw..(j + 1) * self.mh * self.mw];
            for y in 0..gh {
                let row = &plane[(py0 + y) * self.mw + px0..(py0 + y) * self.mw + px0 + gw];
                for (l, p) in logits[y * gw..(y + 1) * gw].iter_mut().zip(row) {
                    *l += coefficient * p;
                }
            }
        }
        let logit = |gx: f64, gy: f64| -> f64 {
            let fx = (gx - px0 as f64).clamp(0.0, (gw - 1) as f64);
            let fy = (gy - py0 as f64).clamp(0.0, (gh - 1) as f64);
            let (x0, y0) = (fx.floor() as usize, fy.floor() as usize);
            let (x1, y1) = ((x0 + 1).min(gw - 1), (y0 + 1).min(gh - 1));
            let (tx, ty) = (fx - x0 as f64, fy - y0 as f64);
            let v = |x: usize, y: usize| f64::from(logits[y * gw + x]);
            (v(x0, y0) * (1.0 - tx) + v(x1, y0) * tx) * (1.0 - ty)
                + (v(x0, y1) * (1.0 - tx) + v(x1, y1) * tx) * ty
        };
        let (ix0, iy0) = letterbox.to_image(c.xyxy[0], c.xyxy[1]);
        let (ix1, iy1) = letterbox.to_image(c.xyxy[2], c.xyxy[3]);
        let mut mask = GrayImage::new(width, height);
        let (x_lo, x_hi) = (
            ix0.floor().max(0.0) as u32,
            ix1.ceil().min(width as f64) as u32,
        );
        let (y_lo, y_hi) = (
            iy0.floor().max(0.0) as u32,
            iy1.ceil().min(height as f64) as u32,
        );
        for y in y_lo..y_hi {
            for x in x_lo..x_hi {
                // The pixel centre in input pixels, then in prototype cells (centres at +0.5).
                let ix = (x as f64 + 0.5) * letterbox.scale + letterbox.left;
                let iy = (y as f64 + 0.5) * letterbox.scale + letterbox.top;
                let inside_box =
                    ix >= c.xyxy[0] && ix <= c.xyxy[2] && iy >= c.xyxy[1] && iy <= c.xyxy[3];
                if inside_box && logit(ix * sx - 0.5, iy * sy - 0.5) > 0.0 {
                    mask.put_pixel(x, y, Luma([255]));
                }
            }
        }
        mask
    }
}

pub struct YoloSegDetector {
    name: String,
    label: String,
    names: Vec<String>,
    input: String,
    predictions: String,
    prototypes: String,
    input_w: usize,
    input_h: usize,
    backend: String,
    pub settings: YoloSettings,
    // ort runs a session through &mut; detectors are shared across threads.
    session: Mutex<Session>,
}

impl YoloSegDetector {
    /// An Ultralytics YOLOv8-seg ONNX export; class names from its `names` metadata.
    pub fn load(path: &Path) -> Result<Self, OnnxError> {
        let bytes = crate::runtime::read_model_file(path)?;
        Self::from_bytes(&path.display().to_string(), &bytes)
    }

    /// A model held in memory (`label` names it in errors).
    pub fn from_bytes(label: &str, onnx: &[u8]) -> Result<Self, OnnxError> {
        let bad = |reason: String| OnnxError::Model {
            path: label.to_string(),
            reason,
        };
        let props = metadata_props(onnx).map_err(bad)?;
        let names_literal = props
            .iter()
            .find(|(k, _)| k == "names")
            .map(|(_, v)| v.as_str())
            .ok_or_else(|| {
                bad(
                    "has no class names (Ultralytics' ONNX export writes them as metadata \
                     'names')"
                        .into(),
                )
            })?;
        let names = ultralytics_names(names_literal).ok_or_else(|| {
            bad(format!(
                "metadata 'names' is not a {{0: 'name', ...}} dict: {}",
                names_literal.chars().take(80).collect::<String>()
            ))
        })?;
        let session = open_session(label, onnx)?;
        let signature = "a YOLOv8-seg signature: input [1, 3, H, W], outputs [1, 4 + classes + \
                         32, anchors] and [1, 32, H/4, W/4]";
        let [input] = session.inputs() else {
            return Err(bad(format!(
                "has {} inputs, expected {signature}",
                session.inputs().len()
            )));
        };
        let shape: Vec<i64> = input
            .dtype()
            .tensor_shape()
            .map(|s| s.to_vec())
            .unwrap_or_default();
        let (input_h, input_w) = match shape.as_slice() {
            [n, 3, h, w] if (*n == 1 || *n < 0) => (
                if *h > 0 { *h as usize } else { 640 },
                if *w > 0 { *w as usize } else { 640 },
            ),
            _ => {
                return Err(bad(format!(
                    "input '{}' has shape {shape:?}, expected {signature}",
                    input.name()
                )));
            }
        };
        if !input_w.is_multiple_of(32) || !input_h.is_multiple_of(32) {
            return Err(bad(format!(
                "input size {input_w}x{input_h} is not a multiple of the stride 32"
            )));
        }
        let outputs = session.outputs();
        let rank = |i: usize| outputs[i].dtype().tensor_shape().map(|s| s.len());
        let (predictions, prototypes) = match outputs.len() {
            2 if rank(0) == Some(3) && rank(1) == Some(4) => (0, 1),
            2 if rank(0) == Some(4) && rank(1) == Some(3) => (1, 0),
            n => {
                return Err(bad(format!(
                    "has {n} outputs of ranks [{}], expected {signature} (a detection-only \
                     model has no mask prototypes)",
                    (0..n)
                        .map(|i| rank(i).map_or("?".to_string(), |r| r.to_string()))
                        .collect::<Vec<_>>()
                        .join(", ")
                )));
            }
        };
        let dims = |i: usize| -> Vec<i64> {
            outputs[i]
                .dtype()
                .tensor_shape()
                .map(|s| s.to_vec())
                .unwrap_or_default()
        };
        let (pd, td) = (dims(predictions), dims(prototypes));
        let (channels, coefficients) = (
            pd.get(1).copied().unwrap_or(-1),
            td.get(1).copied().unwrap_or(-1),
        );
        if channels > 0 && coefficients > 0 && channels != 4 + names.len() as i64 + coefficients {
            return Err(bad(format!(
                "output '{}' has {} channels, but 4 + {} classes (metadata 'names') + {} mask \
                 coefficients make {}",
                outputs[predictions].name(),
                channels,
                names.len(),
                coefficients,
                4 + names.len() as i64 + coefficients
            )));
        }
        let file = Path::new(label)
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| label.to_string());
        Ok(Self {
            name: format!("yolo:{file}"),
            label: label.to_string(),
            input: input.name().to_string(),
            predictions: outputs[predictions].name().to_string(),
            prototypes: outputs[prototypes].name().to_string(),
            names,
            input_w,
            input_h,
            backend: backend()?.name(),
            settings: YoloSettings::default(),
            session: Mutex::new(session),
        })
    }

    pub fn class_names(&self) -> &[String] {
        &self.names
    }

    /// The inference backend (tract or onnxruntime VERSION).
    pub fn backend(&self) -> &str {
        &self.backend
    }

    pub fn input_size(&self) -> (usize, usize) {
        (self.input_w, self.input_h)
    }

    /// Detections with their masks on the camera image (no depth needed).
    pub fn detect_image(&self, image: &RgbImage) -> Result<Vec<(Detection, usize)>, DetectError> {
        let failed = |message: String| DetectError::Model {
            detector: self.label.clone(),
            message,
        };
        let (width, height) = image.dimensions();
        let letterbox = Letterbox::new(width, height, self.input_w, self.input_h);
        let data = letterbox.input(image);
        let input = Tensor::from_array(([1usize, 3, self.input_h, self.input_w], data))
            .map_err(|e| failed(e.to_string()))?;
        let mut session = self
            .session
            .lock()
            .map_err(|_| failed("a previous run panicked".into()))?;
        let outputs = session
            .run(ort::inputs![self.input.as_str() => input])
            .map_err(|e| failed(format!("inference failed: {e}")))?;
        let (pshape, predictions) = outputs[self.predictions.as_str()]
            .try_extract_tensor::<f32>()
            .map_err(|e| failed(format!("output '{}': {e}", self.predictions)))?;
        let (tshape, prototypes) = outputs[self.prototypes.as_str()]
            .try_extract_tensor::<f32>()
            .map_err(|e| failed(format!("output '{}': {e}", self.prototypes)))?;
        let (pshape, tshape) = (pshape.to_vec(), tshape.to_vec());
        let (channels, anchors) = match pshape.as_slice() {
            [1, c, a] => (*c as usize, *a as usize),
            _ => return Err(failed(format!("predictions have shape {pshape:?}"))),
        };
        let (k, mh, mw) = match tshape.as_slice() {
            [1, k, mh, mw] => (*k as usize, *mh as usize, *mw as usize),
            _ => return Err(failed(format!("prototypes have shape {tshape:?}"))),
        };
        if channels != 4 + self.names.len() + k {
            return Err(failed(format!(
                "predictions have {channels} channels, expected 4 + {} classes + {k}",
                self.names.len()
            )));
        }
        let candidates = decode(
            predictions,
            anchors,
            self.names.len(),
            k,
            self.settings.confidence,
        );
        let kept = non_max_suppression(candidates, self.settings.iou, self.settings.max_detections);
        let protos = Prototypes {
            data: prototypes,
            k,
            mh,
            mw,
        };
        Ok(kept
            .into_iter()
            .filter_map(|c| {
                let mask = protos.mask(&c, &letterbox, width, height);
                let (x0, y0) = letterbox.to_image(c.xyxy[0], c.xyxy[1]);
                let (x1, y1) = letterbox.to_image(c.xyxy[2], c.xyxy[3]);
                let clamp = |v: f64, hi: u32| v.round().clamp(0.0, (hi - 1) as f64) as u32;
                let bbox = [
                    clamp(x0, width),
                    clamp(y0, height),
                    clamp(x1, width),
                    clamp(y1, height),
                ];
                if bbox[0] >= bbox[2] || bbox[1] >= bbox[3] {
                    return None;
                }
                Some((
                    Detection {
                        label: self.names[c.class].clone(),
                        score: c.score,
                        bbox,
                        mask,
                        size_m: [0.0; 3],
                    },
                    c.class,
                ))
            })
            .collect())
    }
}

impl Detector for YoloSegDetector {
    fn name(&self) -> &str {
        &self.name
    }

    fn detect(&self, view: &RgbdView<'_>) -> Result<Vec<Detection>, DetectError> {
        Ok(self
            .detect_image(view.color)?
            .into_iter()
            .map(|(mut d, _)| {
                d.size_m = mask_footprint(view, &d.mask).unwrap_or([0.0; 3]);
                d
            })
            .collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn letterbox_centres_a_640x480_frame_and_maps_back() {
        let lb = Letterbox::new(640, 480, 640, 640);
        assert_eq!((lb.scale, lb.left, lb.top), (1.0, 0.0, 80.0));
        let half = Letterbox::new(640, 480, 320, 320);
        assert_eq!((half.scale, half.left, half.top), (0.5, 0.0, 40.0));
        assert_eq!(half.to_image(160.0, 40.0), (320.0, 0.0));
        // A 2x2 block averages on a halving resize, as OpenCV's INTER_LINEAR does.
        let image = RgbImage::from_fn(640, 480, |x, y| {
            image::Rgb([if (x + y) % 2 == 0 { 255 } else { 0 }, 0, 0])
        });
        let input = half.input(&image);
        let red = |x: usize, y: usize| input[y * 320 + x];
        assert!((red(10, 100) - 0.5).abs() < 1e-6, "{}", red(10, 100));
        assert!((red(10, 10) - 114.0 / 255.0).abs() < 1e-6, "padding");
    }

    #[test]
    fn nms_keeps_the_best_of_overlapping_boxes_of_one_class_only() {
        let c = |class, score, x0: f64| Candidate {
            class,
            score,
            xyxy: [x0, 0.0, x0 + 10.0, 10.0],
            coefficients: vec![],
        };
        let kept = non_max_suppression(
            vec![
                c(0, 0.6, 1.0),
                c(0, 0.9, 0.0),
                c(1, 0.8, 0.5),
                c(0, 0.7, 30.0),
            ],
            0.7,
            300,
        );
        let scores: Vec<f64> = kept.iter().map(|k| k.score).collect();
        assert_eq!(
            scores,
            vec![0.9, 0.8, 0.7],
            "the 0.6 box overlaps the 0.9 one"
        );
        assert!((box_iou(&[0.0, 0.0, 2.0, 2.0], &[1.0, 0.0, 3.0, 2.0]) - 1.0 / 3.0).abs() < 1e-12);
    }

    #[test]
    fn decode_reads_channel_major_predictions_and_drops_low_scores() {
        // 2 anchors, 2 classes, 1 coefficient: rows cx, cy, w, h, s0, s1, m0.
        let p = [
            50.0, 10.0, //
            40.0, 10.0, //
            20.0, 4.0, //
            10.0, 4.0, //
            0.1, 0.2, //
            0.8, 0.1, //
            3.0, -1.0,
        ];
        let got = decode(&p, 2, 2, 1, 0.25);
        assert_eq!(got.len(), 1);
        assert_eq!(got[0].class, 1);
        assert_eq!(got[0].xyxy, [40.0, 35.0, 60.0, 45.0]);
        assert_eq!(got[0].coefficients, vec![3.0]);
    }
}
