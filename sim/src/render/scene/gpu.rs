//! The wgpu scene renderer: one raster pass (`shaders/scene_raster.wgsl`) into colour, depth
//! and instance-id targets with a depth buffer, read back and unpacked into a `CleanRender`.
//! Vertices go up in f32 (world frame); the CPU reference works in f64, so the two agree to
//! f32 precision, and silhouette pixels whose centre lies within the rasterizer's snapping
//! distance of an edge may go either way.

use super::geometry::NEAR_M;
use super::{CleanRender, InstanceImage, SceneGeometry, SceneRenderer};
use crate::render::device::{GpuDevice, RenderError};
use wgpu::util::DeviceExt;

pub const SCENE_SHADER: &str = include_str!("../../../../shaders/scene_raster.wgsl");

const FAR_M: f32 = 1000.0;
const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba32Float;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Float;
const INSTANCE_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::R32Uint;
const Z_BUFFER_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The shader's uniform block (see `scene_raster.wgsl`).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct SceneParams {
    world_to_camera: [[f32; 4]; 4],
    focal_centre: [f32; 4],
    viewport: [f32; 4],
    light: [f32; 4],
    eye: [f32; 4],
    shading: [f32; 4],
}

impl SceneParams {
    fn new(scene: &SceneGeometry) -> Self {
        let k = scene.intrinsics;
        let l = scene.lighting;
        let to_camera = scene.camera.inverse();
        let m = glam::DMat4::from_rotation_translation(to_camera.rotation, to_camera.position);
        let v4 = |v: glam::DVec3, w: f64| [v.x as f32, v.y as f32, v.z as f32, w as f32];
        Self {
            world_to_camera: m.to_cols_array_2d().map(|c| c.map(|x| x as f32)),
            // The raster samples pixel x at x + 0.5; the intrinsics put its centre at x.
            focal_centre: [k.fx, k.fy, k.cx + 0.5, k.cy + 0.5].map(|x| x as f32),
            viewport: [
                k.width as f32,
                k.height as f32,
                (NEAR_M / 2.0) as f32,
                FAR_M,
            ],
            light: v4(l.light, 0.0),
            eye: v4(scene.camera.position, 1.0),
            shading: [l.ambient, l.diffuse, l.specular, l.shininess].map(|x| x as f32),
        }
    }
}

/// One vertex as the pipeline reads it.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SceneVertex {
    position: [f32; 3],
    normal: [f32; 3],
    colour: [f32; 3],
    instance: u32,
}

const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 4] = wgpu::vertex_attr_array![
    0 => Float32x3, 1 => Float32x3, 2 => Float32x3, 3 => Uint32
];

pub struct GpuSceneRenderer {
    gpu: GpuDevice,
    pipeline: wgpu::RenderPipeline,
}

impl GpuSceneRenderer {
    pub fn new(adapter: &wgpu::Adapter) -> Result<Self, RenderError> {
        let gpu = GpuDevice::open(adapter, "tactex scene renderer")?;
        let device = &gpu.device;
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("scene_raster"),
            source: wgpu::ShaderSource::Wgsl(SCENE_SHADER.into()),
        });
        let target = |format| {
            Some(wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("scene_raster"),
            layout: None,
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: std::mem::size_of::<SceneVertex>() as u64,
                    step_mode: wgpu::VertexStepMode::Vertex,
                    attributes: &VERTEX_ATTRIBUTES,
                })],
            },
            // Both faces: the CPU reference does not cull either.
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleList,
                cull_mode: None,
                ..Default::default()
            },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: Z_BUFFER_FORMAT,
                depth_write_enabled: Some(true),
                depth_compare: Some(wgpu::CompareFunction::Less),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[
                    target(COLOUR_FORMAT),
                    target(DEPTH_FORMAT),
                    target(INSTANCE_FORMAT),
                ],
            }),
            multiview_mask: None,
            cache: None,
        });
        gpu.take_errors()?;
        Ok(Self { gpu, pipeline })
    }

    fn target(
        &self,
        label: &str,
        format: wgpu::TextureFormat,
        size: wgpu::Extent3d,
    ) -> wgpu::Texture {
        self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some(label),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }
}

/// Rows of a texture copy are padded to 256 bytes.
fn padded_row_bytes(width: u32, texel_bytes: u32) -> u32 {
    (width * texel_bytes).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT)
}

impl SceneRenderer for GpuSceneRenderer {
    fn name(&self) -> String {
        self.gpu.name.clone()
    }

    fn render(&self, scene: &SceneGeometry) -> Result<CleanRender, RenderError> {
        let k = scene.intrinsics;
        let (w, h) = (k.width, k.height);
        if w == 0
            || h == 0
            || w > self.gpu.limits.max_texture_dimension_2d
            || h > self.gpu.limits.max_texture_dimension_2d
        {
            return Err(RenderError::Invalid {
                field: "camera.intrinsics".into(),
                message: format!(
                    "a {w} x {h} image; the device renders 1 to {} pixels a side",
                    self.gpu.limits.max_texture_dimension_2d
                ),
            });
        }
        let vertices: Vec<SceneVertex> = scene
            .triangles
            .iter()
            .flat_map(|t| {
                (0..3).map(move |i| SceneVertex {
                    position: t.p[i].to_array().map(|x| x as f32),
                    normal: t.n[i].to_array().map(|x| x as f32),
                    colour: t.c[i].map(|x| x as f32),
                    instance: t.id as u32,
                })
            })
            .collect();
        let params = SceneParams::new(scene);
        let uniform = self
            .gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        // An empty vertex buffer is invalid: keep one unused vertex.
        let vertex_bytes: &[u8] = if vertices.is_empty() {
            &[0; std::mem::size_of::<SceneVertex>()]
        } else {
            bytemuck::cast_slice(&vertices)
        };
        let vertex_buffer = self
            .gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("scene vertices"),
                contents: vertex_bytes,
                usage: wgpu::BufferUsages::VERTEX,
            });
        let bind_group = self
            .gpu
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("scene params"),
                layout: &self.pipeline.get_bind_group_layout(0),
                entries: &[wgpu::BindGroupEntry {
                    binding: 0,
                    resource: uniform.as_entire_binding(),
                }],
            });
        let size = wgpu::Extent3d {
            width: w,
            height: h,
            depth_or_array_layers: 1,
        };
        let colour = self.target("colour", COLOUR_FORMAT, size);
        let depth = self.target("depth", DEPTH_FORMAT, size);
        let instance = self.target("instance", INSTANCE_FORMAT, size);
        let z_buffer = self.gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("z buffer"),
            size,
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: Z_BUFFER_FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        let views = [&colour, &depth, &instance].map(|t| t.create_view(&Default::default()));
        let z_view = z_buffer.create_view(&Default::default());
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("scene render"),
            });
        {
            let attachment = |view| {
                Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                        store: wgpu::StoreOp::Store,
                    },
                })
            };
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("scene render"),
                color_attachments: &[
                    attachment(&views[0]),
                    attachment(&views[1]),
                    attachment(&views[2]),
                ],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: &z_view,
                    depth_ops: Some(wgpu::Operations {
                        load: wgpu::LoadOp::Clear(1.0),
                        store: wgpu::StoreOp::Discard,
                    }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            if !vertices.is_empty() {
                pass.set_pipeline(&self.pipeline);
                pass.set_bind_group(0, &bind_group, &[]);
                pass.set_vertex_buffer(0, vertex_buffer.slice(..));
                pass.draw(0..vertices.len() as u32, 0..1);
            }
        }
        // One readback buffer, the three images one after another.
        let rows = TEXEL_BYTES.map(|b| padded_row_bytes(w, b));
        let offsets = image_offsets(&rows, h);
        let total = ((rows[0] + rows[1] + rows[2]) * h) as u64;
        let readback = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("scene readback"),
            size: total,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        for (i, texture) in [&colour, &depth, &instance].into_iter().enumerate() {
            encoder.copy_texture_to_buffer(
                wgpu::TexelCopyTextureInfo {
                    texture,
                    mip_level: 0,
                    origin: wgpu::Origin3d::ZERO,
                    aspect: wgpu::TextureAspect::All,
                },
                wgpu::TexelCopyBufferInfo {
                    buffer: &readback,
                    layout: wgpu::TexelCopyBufferLayout {
                        offset: offsets[i],
                        bytes_per_row: Some(rows[i]),
                        rows_per_image: Some(h),
                    },
                },
                size,
            );
        }
        self.gpu
            .submit_and_read(encoder, &readback, |bytes| unpack(bytes, w, h, &rows))
    }
}

/// Bytes per texel of the colour, depth and instance-id targets.
const TEXEL_BYTES: [u32; 3] = [16, 4, 4];

/// Where each of the three images starts in the readback buffer.
fn image_offsets(rows: &[u32; 3], h: u32) -> [u64; 3] {
    [0, rows[0], rows[0] + rows[1]].map(|r| r as u64 * h as u64)
}

/// The three images, one after another in the readback buffer, rows padded to `rows` bytes.
fn unpack(bytes: &[u8], w: u32, h: u32, rows: &[u32; 3]) -> CleanRender {
    let offsets = image_offsets(rows, h);
    let n = (w * h) as usize;
    let mut out = CleanRender {
        color: Vec::with_capacity(n),
        specular: Vec::with_capacity(n),
        depth_m: Vec::with_capacity(n),
        instances: InstanceImage::new(w, h),
    };
    let row = |i: usize, y: u32| {
        let start = offsets[i] as usize + (y * rows[i]) as usize;
        &bytes[start..start + (w * TEXEL_BYTES[i]) as usize]
    };
    for y in 0..h {
        let colour_row: &[f32] = bytemuck::cast_slice(row(0, y));
        for p in colour_row.chunks_exact(4) {
            out.color.push([p[0], p[1], p[2]].map(f64::from));
            out.specular.push(p[3] as f64);
        }
        let depth_row: &[f32] = bytemuck::cast_slice(row(1, y));
        out.depth_m.extend(depth_row.iter().map(|z| *z as f64));
        let id_row: &[u32] = bytemuck::cast_slice(row(2, y));
        for (x, id) in id_row.iter().enumerate() {
            out.instances
                .put_pixel(x as u32, y, image::Luma([*id as u16]));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::device::shader_checks::{struct_size, validated};

    #[test]
    fn scene_shader_parses_and_validates_with_naga() {
        let module = validated("scene_raster", SCENE_SHADER);
        for entry in ["vs_main", "fs_main"] {
            assert!(
                module.entry_points.iter().any(|e| e.name == entry),
                "{entry}"
            );
        }
    }

    #[test]
    fn uniform_block_matches_the_shader_layout() {
        assert_eq!(
            struct_size(SCENE_SHADER, "SceneParams"),
            std::mem::size_of::<SceneParams>()
        );
    }
}
