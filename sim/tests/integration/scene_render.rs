//! The RGB-D scene renderers: the CPU reference against ray-sphere geometry, and the GPU
//! raster path against the CPU reference on the demo scene.

use glam::DVec3;
use std::path::Path;
use tactex_core::catalog::FruitCatalog;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::scene::Scene;
use tactex_sim::render::device::DeviceChoice;
use tactex_sim::render::scene::{
    CleanRender, CpuSceneRenderer, SceneGeometry, SceneRenderer, open_scene_renderer,
};
use tactex_sim::world::SimWorld;

const RADIUS_M: f64 = 0.04;

fn sphere_world() -> SimWorld {
    let text = format!(
        r#"name = "sphere"
[camera]
position_m = [0.0, 0.0, 0.7]
look_at_m = [0.0, 0.0, 0.0]
[[objects]]
kind = "sphere"
radius_m = {RADIUS_M}
position_m = [0.0, 0.0]
hardness = "rigid"
color = [0.8, 0.3, 0.2]
"#
    );
    let scene = Scene::parse(&text, Path::new("sphere.toml"), &FruitCatalog::builtin()).unwrap();
    SimWorld::from_scene(&scene).unwrap()
}

fn demo_world() -> SimWorld {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes/demo.toml");
    let scene = Scene::load(&path, &FruitCatalog::builtin()).unwrap();
    SimWorld::from_scene(&scene).unwrap()
}

/// Camera z of the first hit of pixel (x, y)'s ray on a sphere (camera frame), if any.
fn ray_sphere_z(world: &SimWorld, x: u32, y: u32, centre: DVec3) -> Option<f64> {
    let k = world.intrinsics;
    let d = DVec3::new((x as f64 - k.cx) / k.fx, (y as f64 - k.cy) / k.fy, 1.0);
    let c = world.camera_pose.inverse().transform_point(centre);
    let (a, b, q) = (
        d.length_squared(),
        d.dot(c),
        c.length_squared() - RADIUS_M.powi(2),
    );
    let disc = b * b - a * q;
    (disc >= 0.0).then(|| (b - disc.sqrt()) / a)
}

#[test]
fn depth_of_a_sphere_matches_the_ray_sphere_intersection() {
    let world = sphere_world();
    let render = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    let centre = world.objects[0].centre;
    let centre_z = world.camera_pose.inverse().transform_point(centre).z;
    let k = world.intrinsics;
    // Silhouette radius in pixels of a sphere on the optical axis: f r / sqrt(d^2 - r^2).
    let silhouette_px = k.fx * RADIUS_M / (centre_z.powi(2) - RADIUS_M.powi(2)).sqrt();
    let (cx, cy) = world
        .intrinsics
        .project(world.camera_pose.inverse().transform_point(centre))
        .unwrap();
    let mut worst: f64 = 0.0;
    let mut checked = 0;
    for y in 0..k.height {
        for x in 0..k.width {
            let r = ((x as f64 - cx).powi(2) + (y as f64 - cy).powi(2)).sqrt();
            // Inside 80% of the silhouette the facets (up to 0.043 mm inside the sphere at a
            // quad's middle) are seen at a slant of at most 53 degrees: within 0.075 mm.
            if r > 0.8 * silhouette_px {
                continue;
            }
            let i = (y * k.width + x) as usize;
            assert_eq!(
                render.instances.get_pixel(x, y)[0],
                1,
                "({x}, {y}) not on the sphere"
            );
            let truth = ray_sphere_z(&world, x, y, centre).unwrap();
            worst = worst.max((render.depth_m[i] - truth).abs());
            checked += 1;
        }
    }
    eprintln!("{checked} pixels, worst depth error {:.4} mm", worst * 1e3);
    assert!(checked > 2000, "{checked} pixels");
    assert!(worst < 0.1e-3, "worst depth error {:.4} mm", worst * 1e3);
}

#[test]
fn sphere_silhouette_covers_the_projected_disc() {
    let world = sphere_world();
    let render = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    let centre_z = world
        .camera_pose
        .inverse()
        .transform_point(world.objects[0].centre)
        .z;
    let k = world.intrinsics;
    let rx = k.fx * RADIUS_M / (centre_z.powi(2) - RADIUS_M.powi(2)).sqrt();
    let ry = k.fy * RADIUS_M / (centre_z.powi(2) - RADIUS_M.powi(2)).sqrt();
    let expected = std::f64::consts::PI * rx * ry;
    let covered = render.instances.pixels().filter(|p| p[0] == 1).count() as f64;
    eprintln!("{covered} pixels on the sphere, {expected:.1} expected");
    assert!(
        (covered / expected - 1.0).abs() < 0.01,
        "{covered} pixels on the sphere, {expected:.0} expected"
    );
    // The table is seen everywhere else within the image (the camera looks down at it).
    assert!(render.depth_m.iter().all(|z| *z > 0.0));
}

/// The sphere's silhouette (instance 1) is centred on the principal point: its mean pixel
/// within 0.2 px. The facets and whole-pixel sampling move the middle by up to 0.1 px; the
/// old half-pixel shift moved it 0.4-0.6 px.
fn assert_centred_on_the_principal_point(render: &CleanRender, k: &CameraIntrinsics) {
    let (mut x, mut y, mut n) = (0.0, 0.0, 0.0);
    for (px, py, id) in render.instances.enumerate_pixels() {
        if id[0] == 1 {
            (x, y, n) = (x + px as f64, y + py as f64, n + 1.0);
        }
    }
    let (x, y) = (x / n, y / n);
    assert!(
        (x - k.cx).abs() < 0.2 && (y - k.cy).abs() < 0.2,
        "silhouette centred at ({x:.3}, {y:.3}), principal point ({}, {})",
        k.cx,
        k.cy
    );
}

/// Pixel x's centre is at u = x, as a real camera's OpenCV or librealsense intrinsics mean
/// it: a sphere on the optical axis is seen centred on the principal point, not half a pixel
/// off it (which put every twin centroid 0.6 mm from where a real camera's would be).
#[test]
fn a_sphere_on_the_optical_axis_is_seen_centred_on_the_principal_point() {
    let world = sphere_world();
    let render = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    assert_centred_on_the_principal_point(&render, &world.intrinsics);
}

/// The sphere's pixels back-projected as the pipeline does (pixel x at u = x, at its
/// rendered depth) land on the sphere round its own axis: the mean of the visible cap lies
/// over its centre. Half a pixel of disagreement between renderer and back-projection put
/// it 0.54 mm off in x and y.
#[test]
fn a_sphere_back_projected_from_its_render_stands_where_it_is() {
    let world = sphere_world();
    let render = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    let (k, w) = (world.intrinsics, world.intrinsics.width);
    let (mut sum, mut n) = (DVec3::ZERO, 0.0);
    for (x, y, id) in render.instances.enumerate_pixels() {
        let z = render.depth_m[(y * w + x) as usize];
        if id[0] == 1 && z > 0.0 {
            sum += world
                .camera_pose
                .transform_point(k.back_project(x as f64, y as f64, z));
            n += 1.0;
        }
    }
    let off_mm = (sum / n - world.objects[0].centre).truncate() * 1e3;
    assert!(
        off_mm.length() < 0.1,
        "the cap's middle is {:.3} mm, {:.3} mm from the sphere's axis",
        off_mm.x,
        off_mm.y
    );
}

/// Every scene shipped in scenes/ (fruits.toml is the catalog), as its world.
fn shipped_worlds() -> Vec<(String, SimWorld)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../scenes");
    ["demo.toml", "bananas.toml", "meshes.toml"]
        .into_iter()
        .map(|name| {
            let scene = Scene::load(&dir.join(name), &FruitCatalog::builtin()).unwrap();
            (name.to_string(), SimWorld::from_scene(&scene).unwrap())
        })
        .collect()
}

#[test]
fn the_parked_arm_is_out_of_every_shipped_scenes_view_while_it_grounds() {
    for (name, mut world) in shipped_worlds() {
        let parked = CpuSceneRenderer
            .render(&SceneGeometry::of_world(&world))
            .unwrap();
        // The same world with the arm far above the camera: nothing of it in view.
        world.tool = Pose::tool_down(DVec3::new(0.0, 0.0, 50.0));
        let away = CpuSceneRenderer
            .render(&SceneGeometry::of_world(&world))
            .unwrap();
        assert!(
            parked.depth_m == away.depth_m && parked.color == away.color,
            "{name}"
        );
    }
}

#[test]
fn the_arm_over_the_table_hides_it_at_the_wrists_depth() {
    let mut world = sphere_world();
    let table_only = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    // The pad 0.2 m above the table over the sphere, pointing down: the camera straight
    // above sees only the top of the wrist link, 0.2 + 0.024 + 0.015 + 0.110 m up.
    let pad = DVec3::new(0.0, 0.0, 0.2);
    world.tool = Pose::tool_down(pad);
    let render = CpuSceneRenderer
        .render(&SceneGeometry::of_world(&world))
        .unwrap();
    let to_camera = world.camera_pose.inverse();
    let top = to_camera.transform_point(pad + DVec3::Z * (0.024 + 0.015 + 0.110));
    let (u, v) = world.intrinsics.project(top).unwrap();
    let (x, y) = world.intrinsics.pixel_at(u, v).unwrap();
    let i = (y * world.intrinsics.width + x) as usize;
    assert!(
        (render.depth_m[i] - top.z).abs() < 1e-4,
        "{} m, {} m",
        render.depth_m[i],
        top.z
    );
    assert_eq!(
        render.instances.get_pixel(x, y)[0],
        0,
        "the arm is no object"
    );
    // What it hides is the wrist's 75 mm disc seen from that distance: its area in pixels,
    // within the 24-sided prism's 1%.
    let k = world.intrinsics;
    let disc = std::f64::consts::PI * (k.fx * 0.0375 / top.z) * (k.fy * 0.0375 / top.z);
    let hidden = render
        .depth_m
        .iter()
        .zip(&table_only.depth_m)
        .filter(|(a, b)| (*a - *b).abs() > 1e-6)
        .count() as f64;
    assert!(
        (hidden / disc - 1.0).abs() < 0.02,
        "{hidden} px hidden, disc {disc:.0} px"
    );
}

/// The GPU path; its tests run in CI (lavapipe) and are ignored elsewhere.
fn gpu() -> std::sync::Arc<dyn SceneRenderer> {
    match open_scene_renderer(DeviceChoice::Gpu) {
        Ok(choice) => choice.renderer,
        Err(e) => panic!("GPU scene renderer: {e}"),
    }
}

/// Whether any 4-neighbour of pixel i has another instance id in either render.
fn at_an_edge(a: &CleanRender, b: &CleanRender, x: u32, y: u32) -> bool {
    let (w, h) = a.instances.dimensions();
    let id = a.instances.get_pixel(x, y)[0];
    [(-1i64, 0i64), (1, 0), (0, -1), (0, 1)]
        .iter()
        .any(|(dx, dy)| {
            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
            if nx < 0 || ny < 0 || nx >= w as i64 || ny >= h as i64 {
                return false;
            }
            let (nx, ny) = (nx as u32, ny as u32);
            a.instances.get_pixel(nx, ny)[0] != id || b.instances.get_pixel(nx, ny)[0] != id
        })
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn the_gpu_raster_centres_pixels_as_the_intrinsics_do() {
    let world = sphere_world();
    let render = gpu().render(&SceneGeometry::of_world(&world)).unwrap();
    assert_centred_on_the_principal_point(&render, &world.intrinsics);
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn gpu_and_cpu_scene_renders_agree_on_the_demo_scene() {
    let gpu = gpu();
    let geometry = SceneGeometry::of_world(&demo_world());
    let on_gpu = gpu.render(&geometry).unwrap();
    let on_cpu = CpuSceneRenderer.render(&geometry).unwrap();
    let (w, h) = on_cpu.instances.dimensions();
    assert_eq!(on_gpu.instances.dimensions(), (w, h));
    let n = (w * h) as usize;
    let mut id_mismatch = 0usize;
    let (mut colour_sum, mut colour_max, mut depth_max) = (0.0f64, 0.0f64, 0.0f64);
    let mut compared = 0usize;
    for y in 0..h {
        for x in 0..w {
            let i = (y * w + x) as usize;
            if on_gpu.instances.get_pixel(x, y) != on_cpu.instances.get_pixel(x, y) {
                id_mismatch += 1;
                continue;
            }
            if at_an_edge(&on_cpu, &on_gpu, x, y) {
                continue;
            }
            compared += 1;
            for c in 0..3 {
                let d = (on_gpu.color[i][c] - on_cpu.color[i][c]).abs() * 255.0;
                colour_sum += d / 3.0;
                colour_max = colour_max.max(d);
            }
            depth_max = depth_max.max((on_gpu.depth_m[i] - on_cpu.depth_m[i]).abs());
        }
    }
    let colour_mean = colour_sum / compared as f64;
    eprintln!(
        "{}: ids differ at {id_mismatch} of {n} pixels; colour mean {colour_mean:.4} max {colour_max:.3} grey levels; depth max {:.4} mm",
        gpu.name(),
        depth_max * 1e3
    );
    // Silhouette pixels whose centre lies on an edge to within the rasterizer's snapping
    // may go either way; nothing else may.
    assert!(
        id_mismatch * 2000 < n,
        "{id_mismatch} pixels with other ids"
    );
    assert!(colour_mean <= 0.1, "colour mean {colour_mean}");
    assert!(colour_max <= 1.0, "colour max {colour_max}");
    assert!(depth_max < 0.1e-3, "depth max {} mm", depth_max * 1e3);
    for id in 1..=6u16 {
        let count = |r: &CleanRender| r.instances.pixels().filter(|p| p[0] == id).count();
        assert!(count(&on_cpu) > 500, "fruit {id} barely visible");
        assert!(
            count(&on_cpu).abs_diff(count(&on_gpu)) * 200 < count(&on_cpu),
            "fruit {id}"
        );
    }
}

#[test]
#[cfg_attr(
    not(ci),
    ignore = "needs a Vulkan adapter (lavapipe: mesa-vulkan-drivers, as .ci/run installs)"
)]
fn gpu_scene_render_is_deterministic() {
    let gpu = gpu();
    let geometry = SceneGeometry::of_world(&sphere_world());
    let (a, b) = (
        gpu.render(&geometry).unwrap(),
        gpu.render(&geometry).unwrap(),
    );
    assert_eq!(a.instances.as_raw(), b.instances.as_raw());
    assert_eq!(a.depth_m, b.depth_m);
    assert_eq!(a.color, b.color);
}

/// A board the arm holds face up at `height_m` under the camera, centred on the table's
/// middle: the camera's clean render with it.
fn render_with_board(height_m: f64) -> (CleanRender, CleanRender) {
    use tactex_core::charuco::CharucoBoard;
    use tactex_sim::devices::camera::SimCamera;
    use tactex_sim::render::board_view::SheetLook;
    use tactex_sim::world::HeldBoard;
    let shared = sphere_world().shared();
    let mut camera = SimCamera::new(shared.clone(), 1);
    let bare = camera.clean().unwrap().clone();
    let board = CharucoBoard::default();
    let (w_mm, h_mm) = board.size_mm();
    {
        let mut world = shared.lock().unwrap();
        // The pad pointing up (its housing and the wrist below it); the board over the
        // pad's face, its frame's origin at a corner, its z (into the sheet) down.
        world.tool = Pose::new(DVec3::new(0.0, 0.0, height_m), glam::DQuat::IDENTITY);
        world.held_board = Some(HeldBoard {
            board,
            board_in_tool: Pose::new(
                DVec3::new(-w_mm / 2.0 * 1e-3, h_mm / 2.0 * 1e-3, 0.005),
                glam::DQuat::from_rotation_x(std::f64::consts::PI),
            ),
            look: SheetLook::default(),
        });
    }
    (bare, camera.clean().unwrap().clone())
}

#[test]
fn a_held_board_is_seen_at_its_depth_and_hidden_behind_what_is_nearer() {
    let (_, above) = render_with_board(0.3);
    let k = CameraIntrinsics::default();
    // The sheet's middle: 0.7 - 0.305 m from the camera, its white margin or a square.
    let centre = (k.height / 2) as usize * k.width as usize + (k.width / 2) as usize;
    assert!(
        (above.depth_m[centre] - 0.395).abs() < 1e-3,
        "{}",
        above.depth_m[centre]
    );
    let grey = above.color[centre][0] * 255.0;
    assert!(
        (grey - 220.0).abs() < 1.0 || (grey - 25.0).abs() < 1.0,
        "{grey}"
    );
    // Under the table the sheet is hidden: the render is the bare scene's.
    let (bare, below) = render_with_board(-0.05);
    let changed: Vec<usize> = (0..bare.color.len())
        .filter(|i| bare.color[*i] != below.color[*i] || bare.depth_m[*i] != below.depth_m[*i])
        .collect();
    assert!(
        changed.is_empty(),
        "{} pixels changed, the first at {:?}: {:?} {} -> {:?} {}",
        changed.len(),
        changed
            .first()
            .map(|i| (i % k.width as usize, i / k.width as usize)),
        changed.first().map(|i| bare.color[*i]),
        changed.first().map_or(0.0, |i| bare.depth_m[*i]),
        changed.first().map(|i| below.color[*i]),
        changed.first().map_or(0.0, |i| below.depth_m[*i]),
    );
}

#[test]
fn a_held_board_through_a_fruit_or_the_table_is_not_clear() {
    use tactex_core::charuco::CharucoBoard;
    use tactex_sim::render::board_view::SheetLook;
    use tactex_sim::world::HeldBoard;
    let world = sphere_world();
    let board = CharucoBoard::default();
    let (w_mm, h_mm) = board.size_mm();
    let held = HeldBoard {
        board,
        board_in_tool: Pose::new(
            DVec3::new(-w_mm / 2.0 * 1e-3, h_mm / 2.0 * 1e-3, 0.005),
            glam::DQuat::from_rotation_x(std::f64::consts::PI),
        ),
        look: SheetLook::default(),
    };
    let at = |z: f64| Pose::new(DVec3::new(0.0, 0.0, z), glam::DQuat::IDENTITY);
    // The sphere (8 cm across) stands under the table's middle: a sheet at 5 cm cuts it.
    assert!(held.clears(&world, &at(0.3)));
    assert!(!held.clears(&world, &at(0.05)));
    // Tilted 60 degrees about x, 8 cm up beside the sphere: the sheet's lower edge (85 mm
    // from the middle) comes within 7 mm of the table.
    let tilted = Pose::new(
        DVec3::new(0.2, 0.0, 0.08),
        glam::DQuat::from_rotation_x(1.05),
    );
    assert!(!held.clears(&world, &tilted));
}
