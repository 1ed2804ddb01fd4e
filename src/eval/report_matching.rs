//! Which report of an answer is which fruit on the table: what the scenario and per-fruit
//! evaluations score answers by.

use crate::app::TwinAnswer;
use tactex_core::pipeline::Answer;

/// Which report identifies which scene object: a report of the object's kind whose surface
/// centroid (where the arm will touch) lies on the object in the clean render, as in
/// `eval grounding`; the highest-scoring such report when there are several.
pub fn match_reports(answer: &Answer, kinds: &[String], twin: &TwinAnswer) -> Vec<Option<usize>> {
    let (k, to_camera) = (twin.intrinsics, twin.camera_pose.inverse());
    let id_under = |p: [f64; 3]| -> Option<usize> {
        let (u, v) = k.project(to_camera.transform_point(glam::DVec3::from_array(p)))?;
        let (x, y) = k.pixel_at(u, v)?;
        let id = twin.instances.get_pixel(x, y)[0];
        (id > 0).then(|| id as usize - 1)
    };
    let mut of_object: Vec<Option<usize>> = vec![None; kinds.len()];
    for (r, report) in answer.objects.iter().enumerate() {
        let Some(o) = id_under(report.surface_centroid_m) else {
            continue;
        };
        if kinds[o] != report.label {
            continue;
        }
        let better =
            of_object[o].is_none_or(|q| report.detection_score > answer.objects[q].detection_score);
        if better {
            of_object[o] = Some(r);
        }
    }
    of_object
}
