//! The simulated world every sim device shares: objects resting on the table (settled by
//! rapier3d), the tool (GelSight pad) pose, and the simulated clock.

use crate::mesh::{self, MeshError, TriMesh};
use crate::render::board_view::SheetLook;
use glam::{DQuat, DVec3};
use rapier3d::prelude::*;
use std::sync::{Arc, Mutex};
use tactex_core::charuco::CharucoBoard;
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::hardness::scale::Hardness;
use tactex_core::scene::{ObjectKind, Scene, Table};

/// One object as the twin simulates it.
#[derive(Clone, Debug)]
pub struct SimObject {
    pub label: String,
    pub hardness: Hardness,
    pub poisson: f64,
    pub color: [f64; 3],
    /// The mesh in the world frame after settling.
    pub mesh: TriMesh,
    pub pose: Pose,
    /// Centre of the world-frame bounding box (ground truth for positions).
    pub centre: DVec3,
    /// How far it moved across the table while settling from where the scene put it (m).
    pub settle_shift_m: f64,
}

#[derive(Debug)]
pub struct SimWorld {
    pub objects: Vec<SimObject>,
    pub table: Table,
    pub camera_pose: Pose,
    pub intrinsics: CameraIntrinsics,
    /// Pose of the tactile pad (centre of the gel surface, tool z pointing at the object).
    pub tool: Pose,
    pub time_s: f64,
    /// A calibration board the arm holds (hand-eye calibration), moving with the tool.
    pub held_board: Option<HeldBoard>,
}

/// A ChArUco board fixed to the arm's end, as the scene camera sees it.
#[derive(Clone, Debug, PartialEq)]
pub struct HeldBoard {
    pub board: CharucoBoard,
    /// The board's frame (OpenCV's: origin at its top-left corner, x along the squares'
    /// rows, z into the sheet, the printed face looking along -z) in the tool's frame.
    pub board_in_tool: Pose,
    pub look: SheetLook,
}

/// How far the held sheet keeps from the table and the objects' boxes (m).
const SHEET_CLEARANCE_M: f64 = 0.02;
/// Spacing of the points the sheet is checked at (m): finer than any fruit.
const SHEET_CHECK_STEP_M: f64 = 0.02;

impl HeldBoard {
    /// Whether the sheet, the tool at `tool`, stays above the table (its top at z = 0) and
    /// outside every object's bounding box, each by 2 cm: a station whose board would pass
    /// through a fruit or the table is one the arm cannot hold.
    pub fn clears(&self, world: &SimWorld, tool: &Pose) -> bool {
        let (w_mm, h_mm) = self.board.size_mm();
        let m = self.look.margin_mm;
        let (x0, x1) = (-m * 1e-3, (w_mm + m) * 1e-3);
        let (y0, y1) = (-m * 1e-3, (h_mm + m) * 1e-3);
        let steps = |span: f64| (span / SHEET_CHECK_STEP_M).ceil().max(1.0) as usize;
        let (nx, ny) = (steps(x1 - x0), steps(y1 - y0));
        let boxes: Vec<(DVec3, DVec3)> = world
            .objects
            .iter()
            .map(|o| {
                let (lo, hi) = o.mesh.bounds();
                (
                    lo - DVec3::splat(SHEET_CLEARANCE_M),
                    hi + DVec3::splat(SHEET_CLEARANCE_M),
                )
            })
            .collect();
        let sheet = tool.compose(&self.board_in_tool);
        (0..=nx).all(|i| {
            (0..=ny).all(|j| {
                let x = x0 + (x1 - x0) * i as f64 / nx as f64;
                let y = y0 + (y1 - y0) * j as f64 / ny as f64;
                let p = sheet.transform_point(DVec3::new(x, y, 0.0));
                p.z > SHEET_CLEARANCE_M
                    && !boxes
                        .iter()
                        .any(|(lo, hi)| p.cmpge(*lo).all() && p.cmple(*hi).all())
            })
        })
    }
}

pub type SharedWorld = Arc<Mutex<SimWorld>>;

#[derive(Debug, thiserror::Error)]
pub enum WorldError {
    #[error("{scene}: objects[{index}].mesh: {source}")]
    Mesh {
        scene: String,
        index: usize,
        source: MeshError,
    },
    #[error("{scene}: objects[{index}]: {message}")]
    Object {
        scene: String,
        index: usize,
        message: String,
    },
}

/// An object that moved further than this while settling was not placed where it can rest.
pub const SETTLE_LIMIT_M: f64 = 0.01;

/// Height the tool parks at before a run (m).
pub const TOOL_PARK_Z_M: f64 = 0.35;
/// How far beyond the table's -x edge (the arm's side) the tool parks: out of the scene
/// camera's view while it grounds the objects, as a real arm is parked.
pub const TOOL_PARK_OUTSIDE_M: f64 = 0.05;

/// Where the tool waits before a run: pointing down beyond the table's -x edge.
pub fn tool_park_pose(table: &Table) -> Pose {
    Pose::tool_down(DVec3::new(
        -table.size_m[0] / 2.0 - TOOL_PARK_OUTSIDE_M,
        0.0,
        TOOL_PARK_Z_M,
    ))
}

impl SimWorld {
    /// Builds the objects' meshes, drops them onto the table and lets them settle.
    pub fn from_scene(scene: &Scene) -> Result<SimWorld, WorldError> {
        let shown = scene.path.display().to_string();
        let mut locals = Vec::new();
        for (index, o) in scene.objects.iter().enumerate() {
            let local = match &o.kind {
                ObjectKind::Fruit { shape, size_m, .. } => {
                    mesh::fruit(*shape, DVec3::from_array(*size_m))
                }
                ObjectKind::Sphere { radius_m } => mesh::ellipsoid(DVec3::splat(*radius_m)),
                ObjectKind::Ellipsoid { radii_m } => mesh::ellipsoid(DVec3::from_array(*radii_m)),
                ObjectKind::Box { size_m } => mesh::cuboid(DVec3::from_array(*size_m)),
                ObjectKind::Mesh { path, scale } => {
                    let m = mesh::load(path).map_err(|source| WorldError::Mesh {
                        scene: shown.clone(),
                        index,
                        source,
                    })?;
                    let (lo, hi) = m.bounds();
                    let centre = (lo + hi) / 2.0;
                    if let Some(size_m) = m.size_off_table_m(*scale) {
                        let [least, most] = tactex_core::scene::OBJECT_SIZE_M;
                        return Err(WorldError::Object {
                            scene: shown.clone(),
                            index,
                            message: format!(
                                "the mesh is {} m across at scale {}: not a size an object on a table has ({least} to {most} m); set objects[{index}].scale to the mesh's unit in metres",
                                tactex_core::printable::short_number(size_m),
                                tactex_core::printable::short_number(*scale)
                            ),
                        });
                    }
                    TriMesh {
                        vertices: m.vertices.iter().map(|v| (*v - centre) * *scale).collect(),
                        triangles: m.triangles,
                    }
                }
            };
            locals.push(local);
        }

        let mut physics = PhysicsWorld::new();
        physics.gravity = Vector::new(0.0, 0.0, -9.81);
        let [tx, ty] = scene.table.size_m.map(|s| s as f32 / 2.0);
        physics.colliders.insert(
            ColliderBuilder::cuboid(tx + 0.5, ty + 0.5, 0.05)
                .translation(Vector::new(0.0, 0.0, -0.05))
                .friction(0.9),
        );
        let mut handles = Vec::new();
        let mut starts = Vec::new();
        for (index, (o, local)) in scene.objects.iter().zip(&locals).enumerate() {
            let yaw = DQuat::from_rotation_z(o.yaw_deg.to_radians());
            let rotated = local.transformed(yaw, DVec3::ZERO);
            let (lo, _) = rotated.bounds();
            // Rest the lowest point 1 mm above the table and let it drop.
            let start = DVec3::new(o.position_m[0], o.position_m[1], -lo.z + 1e-3);
            // Snapping can leave a degenerate point set for rapier's f32 quickhull (about one
            // random fruit in 1500): a coarser grid, then the raw vertices, are tried next.
            let collider = [1e-3, 1.7e-3]
                .into_iter()
                .map(|grid| hull_points(local, grid))
                .chain(std::iter::once(raw_points(local)))
                .find_map(|points| ColliderBuilder::convex_hull(&points))
                .ok_or_else(|| WorldError::Object {
                    scene: shown.clone(),
                    index,
                    message: "cannot build a convex hull of the mesh".into(),
                })?
                .friction(0.9)
                .density(1000.0);
            let body = RigidBodyBuilder::dynamic()
                .pose(rapier3d::math::Pose::from_parts(
                    Vector::new(start.x as f32, start.y as f32, start.z as f32),
                    rapier3d::math::Rotation::from_rotation_z(o.yaw_deg.to_radians() as f32),
                ))
                .linear_damping(2.0)
                .angular_damping(6.0);
            let handle = physics.bodies.insert(body);
            physics
                .colliders
                .insert_with_parent(collider, handle, &mut physics.bodies);
            handles.push(handle);
            starts.push(start);
        }
        for _ in 0..180 {
            physics.step();
        }

        let mut objects = Vec::new();
        for ((o, local), (handle, start)) in scene
            .objects
            .iter()
            .zip(&locals)
            .zip(handles.iter().zip(&starts))
        {
            let body = &physics.bodies[*handle];
            let t = body.translation();
            let r = body.rotation();
            let pose = Pose::new(
                DVec3::new(t.x as f64, t.y as f64, t.z as f64),
                DQuat::from_xyzw(r.x as f64, r.y as f64, r.z as f64, r.w as f64).normalize(),
            );
            let mesh = local.transformed(pose.rotation, pose.position);
            let (lo, hi) = mesh.bounds();
            objects.push(SimObject {
                label: o.label.clone(),
                hardness: o.hardness,
                poisson: o.poisson,
                color: o.color,
                mesh,
                pose,
                centre: (lo + hi) / 2.0,
                settle_shift_m: (pose.position - *start).truncate().length(),
            });
        }
        Ok(SimWorld {
            objects,
            table: scene.table.clone(),
            camera_pose: scene.camera_pose,
            intrinsics: scene.intrinsics,
            tool: tool_park_pose(&scene.table),
            time_s: 0.0,
            held_board: None,
        })
    }

    /// What makes the world as placed not a table a question can be asked about: an object
    /// that moved over 1 cm while settling (it overlaps another, or rests unstably), one
    /// larger than the table, or a camera inside an object. `scene` names the file.
    pub fn check_as_placed(&self) -> Result<(), String> {
        let table_side = self.table.size_m[0].min(self.table.size_m[1]);
        for (i, o) in self.objects.iter().enumerate() {
            let (lo, hi) = o.mesh.bounds();
            let extent = (hi - lo).max_element();
            if extent > table_side {
                return Err(format!(
                    "objects[{i}] ({}): {extent:.2} m across, larger than the {table_side:.2} m table",
                    o.label
                ));
            }
            let moved = o.settle_shift_m;
            if moved > SETTLE_LIMIT_M {
                let other = self
                    .objects
                    .iter()
                    .enumerate()
                    .filter(|(j, _)| *j != i)
                    .min_by(|a, b| {
                        let d = |x: &SimObject| (x.centre - o.centre).truncate().length();
                        d(a.1).total_cmp(&d(b.1))
                    })
                    .map(|(j, x)| format!(" (nearest: objects[{j}], {})", x.label))
                    .unwrap_or_default();
                return Err(format!(
                    "objects[{i}] ({}) moved {moved:.3} m while settling: it overlaps another object or rests unstably{other}",
                    o.label
                ));
            }
        }
        if let Some((i, j)) = self.interpenetrating() {
            let (a, b) = (&self.objects[i], &self.objects[j]);
            return Err(format!(
                "objects[{i}] ({}) and objects[{j}] ({}) are placed in one another",
                a.label, b.label
            ));
        }
        let eye = self.camera_pose.position;
        if let Some((i, o)) = self.objects.iter().enumerate().find(|(_, o)| {
            let (lo, hi) = o.mesh.bounds();
            eye.cmpge(lo).all() && eye.cmple(hi).all()
        }) {
            return Err(format!(
                "camera: at {:?} it stands inside objects[{i}] ({})",
                eye.to_array(),
                o.label
            ));
        }
        Ok(())
    }

    /// The first pair of objects of which one is deep in the other: over a fifth of its
    /// vertices, drawn a fifth of the way in towards its centre (touching surfaces never
    /// reach that deep), lie inside the other.
    fn interpenetrating(&self) -> Option<(usize, usize)> {
        for (i, a) in self.objects.iter().enumerate() {
            let (alo, ahi) = a.mesh.bounds();
            for (j, b) in self.objects.iter().enumerate().skip(i + 1) {
                let (blo, bhi) = b.mesh.bounds();
                if alo.cmpgt(bhi).any() || blo.cmpgt(ahi).any() {
                    continue;
                }
                let deep = |x: &SimObject, y: &SimObject| {
                    let step = (x.mesh.vertices.len() / 150).max(1);
                    let samples: Vec<DVec3> = x
                        .mesh
                        .vertices
                        .iter()
                        .step_by(step)
                        .map(|v| x.centre + (*v - x.centre) * 0.8)
                        .collect();
                    // Only points in the other's box can be inside it; the winding number
                    // costs a solid angle per triangle, so the box goes first.
                    let (lo, hi) = y.mesh.bounds();
                    let inside = samples
                        .iter()
                        .filter(|p| p.cmpge(lo).all() && p.cmple(hi).all() && y.mesh.contains(**p))
                        .count();
                    inside * 5 > samples.len()
                };
                if deep(a, b) || deep(b, a) {
                    return Some((i, j));
                }
            }
        }
        None
    }

    /// The furthest any object moved while settling (m).
    pub fn settle_shift_m(&self) -> f64 {
        self.objects
            .iter()
            .map(|o| o.settle_shift_m)
            .fold(0.0, f64::max)
    }

    /// For each object, whether another comes within `gap_m` of it (vertex to vertex: the
    /// meshes' vertices lie under 3 mm apart, so a touch reads as under 3 mm).
    pub fn touching(&self, gap_m: f64) -> Vec<bool> {
        let n = self.objects.len();
        let mut touching = vec![false; n];
        let near = |m: &crate::mesh::TriMesh, (lo, hi): (DVec3, DVec3)| -> Vec<DVec3> {
            let pad = DVec3::splat(gap_m);
            m.vertices
                .iter()
                .filter(|v| v.cmpge(lo - pad).all() && v.cmple(hi + pad).all())
                .copied()
                .collect()
        };
        for i in 0..n {
            for j in i + 1..n {
                let (a, b) = (&self.objects[i].mesh, &self.objects[j].mesh);
                let (a_near, b_near) = (near(a, b.bounds()), near(b, a.bounds()));
                let close = a_near.iter().any(|p| {
                    b_near
                        .iter()
                        .any(|q| p.distance_squared(*q) < gap_m * gap_m)
                });
                if close {
                    touching[i] = true;
                    touching[j] = true;
                }
            }
        }
        touching
    }

    pub fn shared(self) -> SharedWorld {
        Arc::new(Mutex::new(self))
    }
}

/// Mesh vertices snapped to a grid (m) and deduplicated: clusters of nearly coincident
/// points (tapered tips, dense scans) make convex hulls that rapier cannot rest stably.
fn hull_points(mesh: &TriMesh, grid_m: f64) -> Vec<Vector> {
    let mut keys: Vec<[i64; 3]> = mesh
        .vertices
        .iter()
        .map(|v| (*v / grid_m).round().as_i64vec3().to_array())
        .collect();
    keys.sort_unstable();
    keys.dedup();
    keys.into_iter()
        .map(|k| {
            let p = glam::I64Vec3::from_array(k).as_dvec3() * grid_m;
            Vector::new(p.x as f32, p.y as f32, p.z as f32)
        })
        .collect()
}

fn raw_points(mesh: &TriMesh) -> Vec<Vector> {
    mesh.vertices
        .iter()
        .map(|v| Vector::new(v.x as f32, v.y as f32, v.z as f32))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;
    use tactex_core::catalog::FruitCatalog;

    #[test]
    fn fruit_settle_where_they_were_put_and_rest_on_the_table() {
        let scene = Scene::parse(
            "name = \"t\"\n[[objects]]\nkind = \"orange\"\nposition_m = [0.1, 0.05]\n[[objects]]\nkind = \"banana\"\nposition_m = [-0.1, -0.05]\nyaw_deg = 30\n",
            Path::new("t.toml"),
            &FruitCatalog::builtin(),
        )
        .unwrap();
        let world = SimWorld::from_scene(&scene).unwrap();
        assert!(
            world.settle_shift_m() < 0.005,
            "moved {} m while settling",
            world.settle_shift_m()
        );
        for o in &world.objects {
            let (lo, _) = o.mesh.bounds();
            assert!(lo.z.abs() < 0.002, "{} rests at {} m", o.label, lo.z);
        }
        let orange = &world.objects[0];
        assert!((orange.centre.truncate() - glam::DVec2::new(0.1, 0.05)).length() < 0.005);
    }

    #[test]
    fn fruit_placed_in_one_another_are_found_and_touching_ones_are_not() {
        let catalog = FruitCatalog::builtin();
        let three = Scene::parse(
            "name = \"t\"\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n[[objects]]\nkind = \"apple\"\nposition_m = [0, 0]\n[[objects]]\nkind = \"lime\"\nposition_m = [0.2, 0]\n",
            Path::new("t.toml"),
            &catalog,
        )
        .unwrap();
        let world = SimWorld::from_scene(&three).unwrap();
        assert_eq!(world.interpenetrating(), Some((0, 1)));
        // Crowded tables as the evaluations draw them: half the fruits put against another,
        // settled touching. None is deep in another.
        let variation = crate::datagen::scene_random::Variation {
            touching_share: 0.6,
            ..Default::default()
        };
        let kinds = [
            "apple", "banana", "lime", "orange", "mango", "kiwi", "peach", "lemon",
        ];
        for seed in 0..6 {
            let scene =
                crate::datagen::scene_random::random_scene(&kinds, &catalog, seed, &variation)
                    .unwrap();
            let world = SimWorld::from_scene(&scene).unwrap();
            assert_eq!(world.interpenetrating(), None, "seed {seed}");
        }
    }
}
