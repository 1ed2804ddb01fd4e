//! The reference scene renderer: a z-buffer rasterizer in f64 that samples each triangle at
//! pixel centres with perspective-correct interpolation of normal, colour and position.

use super::{CleanRender, InstanceImage, SceneGeometry, SceneRenderer};
use crate::render::device::RenderError;
use glam::{DVec2, DVec3};

#[derive(Clone, Copy, Debug, Default)]
pub struct CpuSceneRenderer;

impl SceneRenderer for CpuSceneRenderer {
    fn name(&self) -> String {
        "cpu".into()
    }

    fn render(&self, scene: &SceneGeometry) -> Result<CleanRender, RenderError> {
        let k = scene.intrinsics;
        let (w, h) = (k.width as usize, k.height as usize);
        let to_cam = scene.camera.inverse();
        let eye = scene.camera.position;
        let lighting = scene.lighting;
        let light = lighting.light;
        let mut zbuf = vec![f64::INFINITY; w * h];
        let mut color = vec![[0.0; 3]; w * h];
        let mut specular = vec![0.0; w * h];
        let mut ids = vec![0u16; w * h];
        for tri in &scene.triangles {
            let cam = tri.p.map(|p| to_cam.transform_point(p));
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
                    let p = DVec2::new(x as f64, y as f64);
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
                    let z = 1.0 / (wz[0] + wz[1] + wz[2]);
                    let i = y * w + x;
                    if z >= zbuf[i] {
                        continue;
                    }
                    zbuf[i] = z;
                    let n = ((tri.n[0] * wz[0] + tri.n[1] * wz[1] + tri.n[2] * wz[2]) * z)
                        .normalize_or(DVec3::Z);
                    let shade = lighting.ambient + lighting.diffuse * n.dot(light).max(0.0);
                    // Fruit skins are waxy: a soft Blinn-Phong highlight; the table is matte.
                    let spec = if tri.id > 0 {
                        let at = (tri.p[0] * wz[0] + tri.p[1] * wz[1] + tri.p[2] * wz[2]) * z;
                        let half = (light + (eye - at).normalize_or(DVec3::Z)).normalize();
                        lighting.specular * n.dot(half).max(0.0).powf(lighting.shininess)
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
        Ok(CleanRender {
            color,
            specular,
            depth_m,
            instances: InstanceImage::from_raw(k.width, k.height, ids).expect("sized"),
        })
    }
}
