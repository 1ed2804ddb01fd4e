//! Crowded tables: fruits drawn against each other settle touching, and the classical
//! detector tells touching fruits apart (the watershed on height) on the twin's noisy camera.

use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::devices::RgbdCamera;
use tactex_core::perception::detect::{ClassicalDetector, Detector, RgbdView};
use tactex_core::scene::Scene;
use tactex_sim::SimDevices;
use tactex_sim::scene_random::{Variation, random_scene};
use tactex_sim::world::SimWorld;

#[test]
fn fruit_put_against_each_other_settle_touching_and_resting() {
    let catalog = FruitCatalog::builtin();
    let kinds = [
        "apple", "lime", "tomato", "kiwi", "orange", "peach", "lemon", "mango", "avocado", "banana",
    ];
    let variation = Variation {
        gap_m: 0.005,
        margin_m: 0.02,
        touching_share: 0.6,
        ..Variation::default()
    };
    let scene = random_scene(&kinds, &catalog, 3, &variation).unwrap();
    let world = SimWorld::from_scene(&scene).unwrap();
    let touching = world.touching(0.003).iter().filter(|t| **t).count();
    assert!(touching >= 4, "only {touching} of 10 touch");
    for o in &world.objects {
        let (lo, _) = o.mesh.bounds();
        assert!(
            lo.z.abs() < 0.003,
            "{} does not rest on the table ({} m)",
            o.label,
            lo.z
        );
    }
    // The default draws no touching fruit.
    let apart = random_scene(&kinds[..6], &catalog, 3, &Variation::default()).unwrap();
    let world = SimWorld::from_scene(&apart).unwrap();
    assert!(world.touching(0.003).iter().all(|t| !t));
}

#[test]
fn two_touching_tomatoes_are_two_detections_where_they_lie() {
    // 66 mm tomatoes 64 mm apart: they overlap by 2 mm and settle against each other.
    let text = r#"name = "touching"
[camera]
position_m = [0.0, 0.0, 0.7]
look_at_m = [0.0, 0.0, 0.0]
[[objects]]
kind = "tomato"
position_m = [0.05, 0.02]
ripeness = "ripe"
[[objects]]
kind = "tomato"
position_m = [0.114, 0.02]
ripeness = "ripe"
"#;
    let catalog = FruitCatalog::builtin();
    let scene = Scene::parse(text, Path::new("touching.toml"), &catalog).unwrap();
    let mut sim = SimDevices::from_scene(&scene, 5).unwrap();
    let centres: Vec<[f64; 3]> = {
        let world = sim.world.lock().unwrap();
        assert!(
            world.touching(0.003).iter().all(|t| *t),
            "they should touch"
        );
        world.objects.iter().map(|o| o.centre.to_array()).collect()
    };
    let frame = sim.camera.capture().unwrap();
    let (k, pose) = (sim.camera.intrinsics(), sim.camera.pose());
    let view = RgbdView {
        color: &frame.color,
        depth: &frame.depth_m,
        intrinsics: &k,
        pose: &pose,
    };
    let found = ClassicalDetector::new(&catalog).detect(&view).unwrap();
    assert_eq!(
        found.len(),
        2,
        "{:?}",
        found.iter().map(|d| &d.label).collect::<Vec<_>>()
    );
    for d in &found {
        assert_eq!(d.label, "tomato");
        // Each mask's centre lies over one tomato, not on the seam between them.
        let (mut u, mut v, mut n) = (0.0, 0.0, 0.0);
        for (x, y, m) in d.mask.enumerate_pixels() {
            if m[0] > 0 {
                (u, v, n) = (u + x as f64, v + y as f64, n + 1.0);
            }
        }
        let ray = k.back_project(u / n, v / n, 0.7 - 0.03);
        let p = pose.transform_point(ray);
        let nearest = centres
            .iter()
            .map(|c| (p.x - c[0]).hypot(p.y - c[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 0.012,
            "a mask centred {nearest} m from either tomato"
        );
    }
}
