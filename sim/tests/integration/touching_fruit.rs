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

#[test]
fn a_banana_lying_across_another_is_two_bananas() {
    // From a crowded table of `eval fruits` (seed 3, table 720): an overripe yellow banana
    // settles across the tip of an olive one. Their chromaticities differ by 0.03 and the
    // olive one's ridge stands no higher than where the yellow one lies on it, so the height
    // watershed joined them and the cut between their outline's two notches made a "mango"
    // and a 24 cm banana of them. The yellow one is 1.4 times as bright where seen.
    let text = r#"name = "crossed"
[camera]
position_m = [0.0, 0.0, 0.7]
look_at_m = [0.0, 0.0, 0.0]
[[objects]]
kind = "banana"
size_m = [0.1966, 0.0580, 0.0339]
position_m = [-0.1586, -0.0446]
yaw_deg = -118.85
modulus_mpa = 0.83
color = [0.639, 0.477, 0.105]
[[objects]]
kind = "banana"
size_m = [0.1765, 0.0634, 0.0369]
position_m = [-0.1221, -0.1213]
yaw_deg = 149.57
modulus_mpa = 0.3
color = [0.954, 0.780, 0.212]
"#;
    let catalog = FruitCatalog::builtin();
    let scene = Scene::parse(text, Path::new("crossed.toml"), &catalog).unwrap();
    let mut sim = SimDevices::from_scene(&scene, 21016153).unwrap();
    let centres: Vec<[f64; 3]> = {
        let world = sim.world.lock().unwrap();
        world.objects.iter().map(|o| o.centre.to_array()).collect()
    };
    let (found, k, pose) = crate::common::detect_classical(&mut sim, &catalog);
    let labels: Vec<&str> = found.iter().map(|d| d.label.as_str()).collect();
    assert_eq!(labels, ["banana", "banana"]);
    // Each mask lies over its own banana: the yellow one on top is seen whole, so its mask is
    // centred near it (a curved banana's centre lies off its flesh, inside the curve); the
    // olive one's is nearer the olive one (its end hidden under the yellow one pulls the
    // visible part's centre a few centimetres along it).
    let distances: Vec<[f64; 2]> = found
        .iter()
        .map(|d| {
            let p = crate::common::mask_centre_m(d, &k, &pose);
            [0, 1].map(|i| (p[0] - centres[i][0]).hypot(p[1] - centres[i][1]))
        })
        .collect();
    let yellow = distances
        .iter()
        .position(|d| d[1] < d[0])
        .expect("a mask nearer the yellow banana");
    assert!(distances[yellow][1] < 0.02, "{distances:?}");
    let olive = distances[1 - yellow];
    assert!(olive[0] < olive[1], "{distances:?}");
}
