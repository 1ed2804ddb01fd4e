//! The simulated RGB-D camera: a CPU z-buffer rasterizer of the table and the objects at the
//! scene's intrinsics and pose, with ambient plus directional light (Lambertian with a soft
//! specular highlight), per-object surface texture, seeded per-frame colour noise and the
//! RealSense D435 depth noise model (`depth_noise`).

use crate::depth_noise::{CleanDepth, RealSenseNoise};
use crate::world::SharedWorld;
use glam::{DVec2, DVec3};
use image::{ImageBuffer, Luma, Rgb, RgbImage};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};
use tactex_core::devices::{DeviceError, RgbdCamera};
use tactex_core::frames::{DepthImage, RgbdFrame};
use tactex_core::geometry::{CameraIntrinsics, Pose};

/// Instance ids per pixel: 0 for the table and floor, i + 1 for object i.
pub type InstanceImage = ImageBuffer<Luma<u16>, Vec<u16>>;

/// The mask (255 inside) of one instance id.
pub fn instance_mask(instances: &InstanceImage, id: u16) -> image::GrayImage {
    let (w, h) = instances.dimensions();
    image::GrayImage::from_fn(w, h, |x, y| {
        Luma([if instances.get_pixel(x, y)[0] == id {
            255
        } else {
            0
        }])
    })
}

/// A noise-free render with ground truth.
#[derive(Clone)]
pub struct CleanRender {
    pub color: Vec<[f64; 3]>,
    /// The specular part of `color` (grey level in [0, 1]); specular spots lose depth.
    pub specular: Vec<f64>,
    pub depth_m: Vec<f64>,
    pub instances: InstanceImage,
}

pub struct SimCamera {
    world: SharedWorld,
    intrinsics: CameraIntrinsics,
    pose: Pose,
    clean: Option<CleanRender>,
    rng: ChaCha8Rng,
    /// Colour noise (grey levels, 1 sigma).
    pub color_noise: f64,
    pub depth_noise: RealSenseNoise,
    pub frame_rate_hz: f64,
}

const LIGHT: DVec3 = DVec3::new(0.25, 0.35, 0.9);
const TABLE_HEIGHT_M: f64 = 0.74;
const FLOOR_COLOR: [f64; 3] = [0.25, 0.24, 0.23];

struct Tri {
    p: [DVec3; 3],
    n: [DVec3; 3],
    c: [[f64; 3]; 3],
    id: u16,
}

fn hash_noise(v: DVec3, seed: u64) -> f64 {
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

impl SimCamera {
    pub fn new(world: SharedWorld, seed: u64) -> Self {
        let (intrinsics, pose) = {
            let w = world.lock().expect("world lock");
            (w.intrinsics, w.camera_pose)
        };
        Self {
            world,
            intrinsics,
            pose,
            clean: None,
            rng: ChaCha8Rng::seed_from_u64(seed ^ 0x00ca_3e7a),
            color_noise: 2.0,
            depth_noise: RealSenseNoise::default(),
            frame_rate_hz: 30.0,
        }
    }

    fn triangles(&self) -> Vec<Tri> {
        let world = self.world.lock().expect("world lock");
        let mut tris = Vec::new();
        let flat = |corners: [DVec3; 4], color: [f64; 3], tris: &mut Vec<Tri>| {
            for idx in [[0, 1, 2], [0, 2, 3]] {
                tris.push(Tri {
                    p: idx.map(|i| corners[i]),
                    n: [DVec3::Z; 3],
                    c: [color; 3],
                    id: 0,
                });
            }
        };
        let [hx, hy] = world.table.size_m.map(|s| s / 2.0);
        flat(
            [
                DVec3::new(-hx, -hy, 0.0),
                DVec3::new(hx, -hy, 0.0),
                DVec3::new(hx, hy, 0.0),
                DVec3::new(-hx, hy, 0.0),
            ],
            world.table.color,
            &mut tris,
        );
        let f = 10.0;
        flat(
            [
                DVec3::new(-f, -f, -TABLE_HEIGHT_M),
                DVec3::new(f, -f, -TABLE_HEIGHT_M),
                DVec3::new(f, f, -TABLE_HEIGHT_M),
                DVec3::new(-f, f, -TABLE_HEIGHT_M),
            ],
            FLOOR_COLOR,
            &mut tris,
        );
        for (k, o) in world.objects.iter().enumerate() {
            let normals = o.mesh.vertex_normals();
            // Surface texture: a few percent of brightness variation fixed to the surface.
            let colors: Vec<[f64; 3]> = o
                .mesh
                .vertices
                .iter()
                .map(|v| {
                    let t = 1.0 + 0.08 * hash_noise(*v, k as u64 + 1);
                    o.color.map(|c| (c * t).clamp(0.0, 1.0))
                })
                .collect();
            for t in &o.mesh.triangles {
                let [a, b, c] = t.map(|i| i as usize);
                tris.push(Tri {
                    p: [a, b, c].map(|i| o.mesh.vertices[i]),
                    n: [a, b, c].map(|i| normals[i]),
                    c: [a, b, c].map(|i| colors[i]),
                    id: (k + 1) as u16,
                });
            }
        }
        tris
    }

    /// Renders the scene without noise, with instance ids (the ground truth).
    pub fn render_clean(&self) -> CleanRender {
        let k = self.intrinsics;
        let (w, h) = (k.width as usize, k.height as usize);
        let to_cam = self.pose.inverse();
        let light = LIGHT.normalize();
        let mut zbuf = vec![f64::INFINITY; w * h];
        let mut color = vec![[0.0; 3]; w * h];
        let mut specular = vec![0.0; w * h];
        let mut ids = vec![0u16; w * h];
        let eye = self.pose.position;
        for tri in self.triangles() {
            let cam = tri.p.map(|p| to_cam.transform_point(p));
            if cam.iter().any(|p| p.z <= 0.01) {
                continue;
            }
            let s = cam.map(|p| DVec2::new(k.fx * p.x / p.z + k.cx, k.fy * p.y / p.z + k.cy));
            let area = (s[1] - s[0]).perp_dot(s[2] - s[0]);
            if area.abs() < 1e-12 {
                continue;
            }
            let lo = s[0].min(s[1]).min(s[2]).floor().max(DVec2::ZERO);
            let hi = s[0]
                .max(s[1])
                .max(s[2])
                .ceil()
                .min(DVec2::new(w as f64 - 1.0, h as f64 - 1.0));
            if lo.x > hi.x || lo.y > hi.y {
                continue;
            }
            for y in lo.y as usize..=hi.y as usize {
                for x in lo.x as usize..=hi.x as usize {
                    let p = DVec2::new(x as f64 + 0.5, y as f64 + 0.5);
                    let b = [
                        (s[2] - s[1]).perp_dot(p - s[1]) / area,
                        (s[0] - s[2]).perp_dot(p - s[2]) / area,
                        (s[1] - s[0]).perp_dot(p - s[0]) / area,
                    ];
                    if b.iter().any(|v| *v < -1e-9) {
                        continue;
                    }
                    // Perspective-correct interpolation: weights over 1/z.
                    let wz = [b[0] / cam[0].z, b[1] / cam[1].z, b[2] / cam[2].z];
                    let inv_z = wz[0] + wz[1] + wz[2];
                    let z = 1.0 / inv_z;
                    let i = y * w + x;
                    if z >= zbuf[i] {
                        continue;
                    }
                    zbuf[i] = z;
                    let n = ((tri.n[0] * wz[0] + tri.n[1] * wz[1] + tri.n[2] * wz[2]) * z)
                        .normalize_or(DVec3::Z);
                    let shade = 0.38 + 0.62 * n.dot(light).max(0.0);
                    // Fruit skins are waxy: a soft Blinn-Phong highlight; the table is matte.
                    let spec = if tri.id > 0 {
                        let at = (tri.p[0] * wz[0] + tri.p[1] * wz[1] + tri.p[2] * wz[2]) * z;
                        let half = (light + (eye - at).normalize_or(DVec3::Z)).normalize();
                        0.35 * n.dot(half).max(0.0).powi(60)
                    } else {
                        0.0
                    };
                    specular[i] = spec;
                    color[i] = std::array::from_fn(|c| {
                        ((tri.c[0][c] * wz[0] + tri.c[1][c] * wz[1] + tri.c[2][c] * wz[2])
                            * z
                            * shade
                            + spec)
                            .min(1.0)
                    });
                    ids[i] = tri.id;
                }
            }
        }
        let depth_m = zbuf
            .into_iter()
            .map(|z| if z.is_finite() { z } else { 0.0 })
            .collect();
        CleanRender {
            color,
            specular,
            depth_m,
            instances: InstanceImage::from_raw(w as u32, h as u32, ids).expect("sized"),
        }
    }
}

impl RgbdCamera for SimCamera {
    fn name(&self) -> &str {
        "sim-rgbd"
    }

    fn intrinsics(&self) -> CameraIntrinsics {
        self.intrinsics
    }

    fn pose(&self) -> Pose {
        self.pose
    }

    fn capture(&mut self) -> Result<RgbdFrame, DeviceError> {
        if self.clean.is_none() {
            self.clean = Some(self.render_clean());
        }
        let clean = self.clean.as_ref().expect("rendered");
        let k = self.intrinsics;
        let unit = Normal::new(0.0, 1.0).expect("valid");
        let rng = &mut self.rng;
        let mut color = RgbImage::new(k.width, k.height);
        for (p, c) in color.pixels_mut().zip(&clean.color) {
            *p = Rgb(std::array::from_fn(|i| {
                (c[i] * 255.0 + self.color_noise * unit.sample(rng))
                    .round()
                    .clamp(0.0, 255.0) as u8
            }));
        }
        let depth = self.depth_noise.apply(
            &CleanDepth {
                width: k.width as usize,
                height: k.height as usize,
                depth_m: &clean.depth_m,
                color: &clean.color,
                specular: &clean.specular,
                fx: k.fx,
            },
            rng,
        );
        let mut world = self.world.lock().expect("world lock");
        world.time_s += 1.0 / self.frame_rate_hz;
        Ok(RgbdFrame {
            color,
            depth_m: DepthImage::from_raw(k.width, k.height, depth).expect("sized"),
            timestamp_s: world.time_s,
        })
    }
}
