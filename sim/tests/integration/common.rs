//! Helpers the sim's integration tests share.

use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::ground::detect::{ClassicalDetector, Detection, Detector, RgbdView};
use tactex_sim::SimDevices;

/// One frame of the twin's noisy camera through the classical detector, with the camera's
/// intrinsics and pose.
pub(crate) fn detect_classical(
    sim: &mut SimDevices,
    catalog: &FruitCatalog,
) -> (Vec<Detection>, CameraIntrinsics, Pose) {
    let frame = sim.camera.capture().unwrap();
    let (k, pose) = (sim.camera.intrinsics(), sim.camera.pose());
    let view = RgbdView {
        color: &frame.color,
        depth: &frame.depth_m,
        intrinsics: &k,
        pose: &pose,
    };
    let found = ClassicalDetector::new(catalog).detect(&view).unwrap();
    (found, k, pose)
}

/// Where the middle of a detection's mask lies on the table (x, y in metres), taking the
/// fruit's visible surface 3 cm up.
#[allow(dead_code)]
pub(crate) fn mask_centre_m(d: &Detection, k: &CameraIntrinsics, pose: &Pose) -> [f64; 2] {
    let (mut u, mut v, mut n) = (0.0, 0.0, 0.0);
    for (x, y, m) in d.mask.enumerate_pixels() {
        if m[0] > 0 {
            (u, v, n) = (u + x as f64, v + y as f64, n + 1.0);
        }
    }
    let p = pose.transform_point(k.back_project(u / n, v / n, 0.7 - 0.03));
    [p.x, p.y]
}
