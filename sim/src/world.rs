//! The simulated world every sim device shares: objects resting on the table (settled by
//! rapier3d), the tool (GelSight pad) pose, and the simulated clock.

use crate::mesh::{self, MeshError, TriMesh};
use glam::{DQuat, DVec3};
use rapier3d::prelude::*;
use std::sync::{Arc, Mutex};
use tactex_core::geometry::{CameraIntrinsics, Pose};
use tactex_core::hardness::Hardness;
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
    /// Largest distance any object moved while settling (m).
    pub settle_shift_m: f64,
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

/// Height the tool parks at before a run (m).
pub const TOOL_PARK_Z_M: f64 = 0.35;

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
        let mut settle_shift_m: f64 = 0.0;
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
            settle_shift_m = settle_shift_m.max((pose.position - *start).truncate().length());
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
            });
        }
        Ok(SimWorld {
            objects,
            table: scene.table.clone(),
            camera_pose: scene.camera_pose,
            intrinsics: scene.intrinsics,
            tool: Pose::tool_down(DVec3::new(0.0, 0.0, TOOL_PARK_Z_M)),
            time_s: 0.0,
            settle_shift_m,
        })
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
            world.settle_shift_m < 0.005,
            "moved {} m while settling",
            world.settle_shift_m
        );
        for o in &world.objects {
            let (lo, _) = o.mesh.bounds();
            assert!(lo.z.abs() < 0.002, "{} rests at {} m", o.label, lo.z);
        }
        let orange = &world.objects[0];
        assert!((orange.centre.truncate() - glam::DVec2::new(0.1, 0.05)).length() < 0.005);
    }
}
