//! Crowded tables: fruits drawn against each other settle touching, and the classical
//! detector tells touching fruits apart (the watershed on height) on the twin's noisy camera.

use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::scene::Scene;
use tactex_sim::SimDevices;
use tactex_sim::datagen::scene_random::{Variation, random_scene};
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
    let (found, k, pose) = crate::common::detect_classical(&mut sim, &catalog);
    assert_eq!(
        found.len(),
        2,
        "{:?}",
        found.iter().map(|d| &d.label).collect::<Vec<_>>()
    );
    for d in &found {
        assert_eq!(d.label, "tomato");
        // Each mask's centre lies over one tomato, not on the seam between them.
        let p = crate::common::mask_centre_m(d, &k, &pose);
        let nearest = centres
            .iter()
            .map(|c| (p[0] - c[0]).hypot(p[1] - c[1]))
            .fold(f64::INFINITY, f64::min);
        assert!(
            nearest < 0.012,
            "a mask centred {nearest} m from either tomato"
        );
    }
}

#[test]
fn a_strawberry_under_an_apples_flank_of_its_colour_is_found() {
    // From a crowded table of `eval fruits` (seed 2, table 176): the strawberry's top stands
    // below the apple's silhouette edge as the camera sees it, and both are red, so neither
    // height nor colour parts them; the notches where their outlines meet do.
    let text = r#"name = "tucked"
[camera]
position_m = [0.0, 0.0, 0.7]
look_at_m = [0.0, 0.0, 0.0]
[[objects]]
kind = "apple"
size_m = [0.0750, 0.0729, 0.0649]
position_m = [0.2002, -0.0965]
yaw_deg = -168.8
color = [0.682, 0.115, 0.157]
modulus_mpa = 3.25
[[objects]]
kind = "strawberry"
size_m = [0.0389, 0.0282, 0.0295]
position_m = [0.2204, -0.1429]
yaw_deg = -158.0
color = [0.848, 0.121, 0.169]
modulus_mpa = 0.2
"#;
    let catalog = FruitCatalog::builtin();
    let scene = Scene::parse(text, Path::new("tucked.toml"), &catalog).unwrap();
    let mut sim = SimDevices::from_scene(&scene, 14000006).unwrap();
    let centres: Vec<(String, [f64; 3])> = {
        let world = sim.world.lock().unwrap();
        world
            .objects
            .iter()
            .map(|o| (o.label.clone(), o.centre.to_array()))
            .collect()
    };
    let (found, k, pose) = crate::common::detect_classical(&mut sim, &catalog);
    let mut labels: Vec<&str> = found.iter().map(|d| d.label.as_str()).collect();
    labels.sort();
    assert_eq!(labels, ["apple", "strawberry"]);
    for d in &found {
        let p = crate::common::mask_centre_m(d, &k, &pose);
        let (_, c) = centres.iter().find(|(l, _)| *l == d.label).unwrap();
        let off = (p[0] - c[0]).hypot(p[1] - c[1]);
        assert!(off < 0.012, "{}'s mask centred {off} m from it", d.label);
    }
}
