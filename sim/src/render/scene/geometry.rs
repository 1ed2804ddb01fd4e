//! What the camera sees, as triangles: the table top, the floor below it, every object's
//! mesh with per-vertex normals and a surface texture (a few percent of brightness variation
//! fixed to the surface, so that two fruits of one kind are not identical), and the arm's
//! end where the pad is (`tool_body`).

use super::Lighting;
use crate::world::SimWorld;
use glam::DVec3;
use tactex_core::geometry::{CameraIntrinsics, Pose};

/// Triangles with a vertex closer to the camera than this are left out (by both renderers).
pub(super) const NEAR_M: f64 = 0.01;
const TABLE_HEIGHT_M: f64 = 0.74;
const FLOOR_COLOR: [f64; 3] = [0.25, 0.24, 0.23];
const FLOOR_HALF_SIZE_M: f64 = 10.0;

#[derive(Clone, Debug, PartialEq)]
pub struct SceneTriangle {
    /// Corners, world frame.
    pub p: [DVec3; 3],
    /// Unit normals at the corners, world frame.
    pub n: [DVec3; 3],
    /// Linear colour at the corners.
    pub c: [[f64; 3]; 3],
    /// 0 for the table, the floor and the arm, i + 1 for object i.
    pub id: u16,
}

#[derive(Clone, Debug)]
pub struct SceneGeometry {
    pub intrinsics: CameraIntrinsics,
    /// Camera pose in the world (z forward, x right, y down).
    pub camera: Pose,
    pub lighting: Lighting,
    /// Only triangles wholly in front of the near plane.
    pub triangles: Vec<SceneTriangle>,
}

/// A value in [-0.5, 0.5) fixed to a point on a surface (0.5 mm cells) and a seed.
fn surface_noise(v: DVec3, seed: u64) -> f64 {
    let q = (v * 2000.0).round();
    let mut h = seed
        ^ (q.x as i64 as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ (q.y as i64 as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
        ^ (q.z as i64 as u64).wrapping_mul(0x1656_67B1_9E37_79F9);
    h ^= h >> 29;
    h = h.wrapping_mul(0xBF58_476D_1CE4_E5B9);
    h ^= h >> 32;
    (h % 10_000) as f64 / 10_000.0 - 0.5
}

/// A flat quad (corners in order round it) with one normal, of the table, floor or arm (id 0).
pub(super) fn flat_quad(
    corners: [DVec3; 4],
    normal: DVec3,
    color: [f64; 3],
    out: &mut Vec<SceneTriangle>,
) {
    for idx in [[0, 1, 2], [0, 2, 3]] {
        out.push(SceneTriangle {
            p: idx.map(|i| corners[i]),
            n: [normal; 3],
            c: [color; 3],
            id: 0,
        });
    }
}

impl SceneGeometry {
    pub fn of_world(world: &SimWorld) -> Self {
        let mut triangles = Vec::new();
        let [hx, hy] = world.table.size_m.map(|s| s / 2.0);
        flat_quad(
            [
                DVec3::new(-hx, -hy, 0.0),
                DVec3::new(hx, -hy, 0.0),
                DVec3::new(hx, hy, 0.0),
                DVec3::new(-hx, hy, 0.0),
            ],
            DVec3::Z,
            world.table.color,
            &mut triangles,
        );
        let f = FLOOR_HALF_SIZE_M;
        flat_quad(
            [
                DVec3::new(-f, -f, -TABLE_HEIGHT_M),
                DVec3::new(f, -f, -TABLE_HEIGHT_M),
                DVec3::new(f, f, -TABLE_HEIGHT_M),
                DVec3::new(-f, f, -TABLE_HEIGHT_M),
            ],
            DVec3::Z,
            FLOOR_COLOR,
            &mut triangles,
        );
        for (k, o) in world.objects.iter().enumerate() {
            let normals = o.mesh.vertex_normals();
            let colors: Vec<[f64; 3]> = o
                .mesh
                .vertices
                .iter()
                .map(|v| {
                    let t = 1.0 + 0.08 * surface_noise(*v, k as u64 + 1);
                    o.color.map(|c| (c * t).clamp(0.0, 1.0))
                })
                .collect();
            for t in &o.mesh.triangles {
                let [a, b, c] = t.map(|i| i as usize);
                triangles.push(SceneTriangle {
                    p: [a, b, c].map(|i| o.mesh.vertices[i]),
                    n: [a, b, c].map(|i| normals[i]),
                    c: [a, b, c].map(|i| colors[i]),
                    id: (k + 1) as u16,
                });
            }
        }
        triangles.extend(super::tool_body::tool_triangles(&world.tool));
        let to_camera = world.camera_pose.inverse();
        triangles.retain(|t| t.p.iter().all(|p| to_camera.transform_point(*p).z > NEAR_M));
        Self {
            intrinsics: world.intrinsics,
            camera: world.camera_pose,
            lighting: Lighting::default(),
            triangles,
        }
    }
}
