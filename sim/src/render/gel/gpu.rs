//! The WGSL compute renderer: the stages of `shaders/` (four, and five more for a glow) as
//! wgpu compute pipelines, a whole batch of presses per dispatch (the frame is the third
//! dispatch dimension), read back as RGBA8 and unpacked.

use super::cpu::flat_shading;
use super::{
    GelGlow, GelImageFields, GelRenderer, PressFrame, RenderError, RenderParams, SensorOptics,
    Shading,
};
use crate::render::device::GpuDevice;
use image::RgbImage;
use tactex_core::tactile::gel_glow::{blur_factor, blur_kernel};
use wgpu::util::DeviceExt;

const COMMON: &str = include_str!("../../../../shaders/common.wgsl");

/// Each stage's own source; the shared prelude (`common.wgsl`) goes in front of it.
pub const SHADER_SOURCES: [(&str, &str); 9] = [
    (
        "gel_slopes",
        include_str!("../../../../shaders/gel_slopes.wgsl"),
    ),
    (
        "gel_shading",
        include_str!("../../../../shaders/gel_shading.wgsl"),
    ),
    (
        "marker_displacement",
        include_str!("../../../../shaders/marker_displacement.wgsl"),
    ),
    (
        "sensor_exposure",
        include_str!("../../../../shaders/sensor_exposure.wgsl"),
    ),
    (
        "gel_glow_blocks",
        include_str!("../../../../shaders/gel_glow_blocks.wgsl"),
    ),
    (
        "gel_glow_rows",
        include_str!("../../../../shaders/gel_glow_rows.wgsl"),
    ),
    (
        "gel_glow_columns",
        include_str!("../../../../shaders/gel_glow_columns.wgsl"),
    ),
    (
        "gel_glow_spread",
        include_str!("../../../../shaders/gel_glow_spread.wgsl"),
    ),
    (
        "gel_glow_apply",
        include_str!("../../../../shaders/gel_glow_apply.wgsl"),
    ),
];

// Indices into SHADER_SOURCES.
const SLOPES: usize = 0;
const SHADING: usize = 1;
const MARKERS: usize = 2;
const EXPOSURE: usize = 3;
const GLOW_BLOCKS: usize = 4;
const GLOW_ROWS: usize = 5;
const GLOW_COLUMNS: usize = 6;
const GLOW_SPREAD: usize = 7;
const GLOW_APPLY: usize = 8;

/// The complete WGSL module of a stage, as the device compiles it.
pub fn shader_source(stage: &str) -> Option<String> {
    SHADER_SOURCES
        .iter()
        .find(|(name, _)| *name == stage)
        .map(|(_, body)| format!("{COMMON}\n{body}"))
}

/// Frames per dispatch at most: bounds device memory (about 2.7 MB per 320x240 frame).
const MAX_FRAMES_PER_DISPATCH: usize = 64;

pub struct GpuRenderer {
    gpu: GpuDevice,
    /// One per entry of SHADER_SOURCES.
    pipelines: [wgpu::ComputePipeline; 9],
}

impl GpuRenderer {
    pub fn new(adapter: &wgpu::Adapter) -> Result<Self, RenderError> {
        let gpu = GpuDevice::open(adapter, "tactex gel renderer")?;
        let pipelines = SHADER_SOURCES.map(|(stage, _)| {
            let module = gpu
                .device
                .create_shader_module(wgpu::ShaderModuleDescriptor {
                    label: Some(stage),
                    source: wgpu::ShaderSource::Wgsl(
                        shader_source(stage).expect("listed stage").into(),
                    ),
                });
            gpu.device
                .create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                    label: Some(stage),
                    layout: None,
                    module: &module,
                    entry_point: Some("main"),
                    compilation_options: Default::default(),
                    cache: None,
                })
        });
        gpu.take_errors()?;
        Ok(Self { gpu, pipelines })
    }

    fn storage(&self, label: &str, bytes: &[u8]) -> wgpu::Buffer {
        // Zero-sized bindings are invalid: pad empty inputs to one word.
        let contents: &[u8] = if bytes.is_empty() { &[0; 16] } else { bytes };
        self.gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE,
            })
    }

    fn scratch(&self, label: &str, bytes: u64, extra: wgpu::BufferUsages) -> wgpu::Buffer {
        self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some(label),
            size: bytes.max(16),
            usage: wgpu::BufferUsages::STORAGE | extra,
            mapped_at_creation: false,
        })
    }

    fn bind(&self, stage: usize, buffers: &[&wgpu::Buffer]) -> wgpu::BindGroup {
        let entries: Vec<wgpu::BindGroupEntry> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        self.gpu
            .device
            .create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some(SHADER_SOURCES[stage].0),
                layout: &self.pipelines[stage].get_bind_group_layout(0),
                entries: &entries,
            })
    }

    fn render_chunk(
        &self,
        optics: &SensorOptics,
        frames: &[PressFrame],
        shared: &OpticsBuffers,
    ) -> Result<Vec<RgbImage>, RenderError> {
        let n = optics.pixel_count();
        let count = frames.len();
        let params = RenderParams::new(optics, count as u32);
        let uniform = self
            .gpu
            .device
            .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some("render params"),
                contents: bytemuck::bytes_of(&params),
                usage: wgpu::BufferUsages::UNIFORM,
            });
        let gather = |pick: fn(&GelImageFields) -> &[f32]| -> Vec<f32> {
            let mut all = Vec::with_capacity(n * count);
            for f in frames {
                all.extend_from_slice(pick(f.fields));
            }
            all
        };
        let heights = self.storage("heights", bytemuck::cast_slice(&gather(|f| &f.normal_mm)));
        let lateral_x = self.storage(
            "lateral x",
            bytemuck::cast_slice(&gather(|f| &f.lateral_x_mm)),
        );
        let lateral_y = self.storage(
            "lateral y",
            bytemuck::cast_slice(&gather(|f| &f.lateral_y_mm)),
        );
        let seeds: Vec<u32> = frames.iter().map(|f| f.seed).collect();
        let seeds = self.storage("frame seeds", bytemuck::cast_slice(&seeds));
        let frame_px = (n * count) as u64;
        let slopes = self.scratch("slopes", frame_px * 8, wgpu::BufferUsages::empty());
        let shaded = self.scratch("shaded", frame_px * 12, wgpu::BufferUsages::empty());
        let markers = (optics.markers.len() * count) as u64;
        let centres = self.scratch("marker centres", markers * 8, wgpu::BufferUsages::empty());
        let pixels = self.scratch("pixels", frame_px * 4, wgpu::BufferUsages::COPY_SRC);
        let readback = self.gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: frame_px * 4,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let (w, h) = (optics.width, optics.height);
        let tiles = [w.div_ceil(8), h.div_ceil(8), count as u32];
        // The stages in order, each with its bind group and dispatch size.
        let mut steps = vec![
            (
                SLOPES,
                self.bind(SLOPES, &[&uniform, &heights, &slopes]),
                tiles,
            ),
            (
                SHADING,
                self.bind(
                    SHADING,
                    &[
                        &uniform,
                        &slopes,
                        &shared.background,
                        &shared.table,
                        &shaded,
                    ],
                ),
                tiles,
            ),
        ];
        let mut glow_sum = None;
        if let Some(glow) = &shared.glow {
            // A term's blocks (the finest, of one pixel, with one outside each edge) are
            // averaged into `blurred`, blurred along rows into `along_rows` and down columns
            // back into `blurred`.
            let blocks_px = (glow_blocks_per_frame(w, h) * count) as u64;
            let along_rows = self.scratch(
                "glow along rows",
                blocks_px * 12,
                wgpu::BufferUsages::empty(),
            );
            let blurred = self.scratch("glow blurred", blocks_px * 12, wgpu::BufferUsages::empty());
            let sum = self.scratch("glow", frame_px * 12, wgpu::BufferUsages::COPY_DST);
            for (term, factor) in &glow.terms {
                let d = *factor;
                let grid = [
                    (w.div_ceil(d) + 2).div_ceil(8),
                    (h.div_ceil(d) + 2).div_ceil(8),
                    count as u32,
                ];
                steps.push((
                    GLOW_BLOCKS,
                    self.bind(
                        GLOW_BLOCKS,
                        &[&uniform, term, &glow.flat, &shaded, &heights, &blurred],
                    ),
                    grid,
                ));
                steps.push((
                    GLOW_ROWS,
                    self.bind(
                        GLOW_ROWS,
                        &[&uniform, term, &glow.kernel, &blurred, &along_rows],
                    ),
                    grid,
                ));
                steps.push((
                    GLOW_COLUMNS,
                    self.bind(
                        GLOW_COLUMNS,
                        &[&uniform, term, &glow.kernel, &along_rows, &blurred],
                    ),
                    grid,
                ));
                steps.push((
                    GLOW_SPREAD,
                    self.bind(GLOW_SPREAD, &[&uniform, term, &blurred, &sum]),
                    tiles,
                ));
            }
            steps.push((
                GLOW_APPLY,
                self.bind(GLOW_APPLY, &[&uniform, &glow.flat, &sum, &shaded]),
                tiles,
            ));
            glow_sum = Some(sum);
        }
        steps.push((
            MARKERS,
            self.bind(
                MARKERS,
                &[&uniform, &lateral_x, &lateral_y, &shared.rest, &centres],
            ),
            [(optics.markers.len() as u32).div_ceil(64), count as u32, 1],
        ));
        steps.push((
            EXPOSURE,
            self.bind(EXPOSURE, &[&uniform, &shaded, &centres, &seeds, &pixels]),
            tiles,
        ));
        let mut encoder = self
            .gpu
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("gel render"),
            });
        if let Some(sum) = &glow_sum {
            encoder.clear_buffer(sum, 0, None);
        }
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("gel render"),
                timestamp_writes: None,
            });
            for (stage, group, [x, y, z]) in &steps {
                if *x == 0 || *y == 0 || *z == 0 {
                    continue;
                }
                pass.set_pipeline(&self.pipelines[*stage]);
                pass.set_bind_group(0, group, &[]);
                pass.dispatch_workgroups(*x, *y, *z);
            }
        }
        encoder.copy_buffer_to_buffer(&pixels, 0, &readback, 0, frame_px * 4);
        self.gpu.submit_and_read(encoder, &readback, |bytes| {
            let packed: &[u32] = bytemuck::cast_slice(bytes);
            packed
                .chunks_exact(n)
                .map(|frame| {
                    let mut bytes = Vec::with_capacity(3 * n);
                    for p in frame {
                        bytes.extend_from_slice(&p.to_le_bytes()[..3]);
                    }
                    RgbImage::from_raw(w, h, bytes).expect("sized from the frame")
                })
                .collect()
        })
    }
}

/// The optics' buffers, shared by every chunk of a batch.
struct OpticsBuffers {
    background: wgpu::Buffer,
    table: wgpu::Buffer,
    rest: wgpu::Buffer,
    glow: Option<GlowBuffers>,
}

/// The glow's inputs: the flat gel's shading, every term's kernel back to back, and one
/// uniform block per term with its block size.
struct GlowBuffers {
    flat: wgpu::Buffer,
    kernel: wgpu::Buffer,
    terms: Vec<(wgpu::Buffer, u32)>,
}

/// The most blocks a glow term's grid has for a frame: blocks of one pixel, one outside
/// each edge.
fn glow_blocks_per_frame(width: u32, height: u32) -> usize {
    (width as usize + 2) * (height as usize + 2)
}

/// A glow term as the glow stages read it (`GlowTerm` in shaders/common.wgsl).
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GlowTermBlock {
    mix: [[f32; 4]; 3],
    offset: u32,
    radius: u32,
    source: u32,
    factor: u32,
}

impl GpuRenderer {
    fn glow_buffers(&self, optics: &SensorOptics, glow: &GelGlow) -> GlowBuffers {
        let p = RenderParams::new(optics, 1);
        let flat: Vec<f32> = flat_shading(&p, optics).into_iter().flatten().collect();
        let mut kernel = Vec::new();
        let mut terms = Vec::new();
        for term in glow.terms() {
            let k = blur_kernel(term.sigma_px);
            let factor = blur_factor(term.sigma_px) as u32;
            let block = GlowTermBlock {
                mix: term.mix.map(|r| [r[0], r[1], r[2], 0.0]),
                offset: kernel.len() as u32,
                radius: (k.len() / 2) as u32,
                source: term.source.code(),
                factor,
            };
            kernel.extend(k);
            terms.push((
                self.gpu
                    .device
                    .create_buffer_init(&wgpu::util::BufferInitDescriptor {
                        label: Some("glow term"),
                        contents: bytemuck::bytes_of(&block),
                        usage: wgpu::BufferUsages::UNIFORM,
                    }),
                factor,
            ));
        }
        GlowBuffers {
            flat: self.storage("flat shading", bytemuck::cast_slice(&flat)),
            kernel: self.storage("glow kernels", bytemuck::cast_slice(&kernel)),
            terms,
        }
    }
}

impl GelRenderer for GpuRenderer {
    fn name(&self) -> String {
        self.gpu.name.clone()
    }

    fn render_batch(
        &mut self,
        optics: &SensorOptics,
        frames: &[PressFrame],
    ) -> Result<Vec<RgbImage>, RenderError> {
        optics.check_frames(frames)?;
        let per_frame = match optics.glow {
            Some(_) => glow_blocks_per_frame(optics.width, optics.height),
            None => optics.pixel_count(),
        } as u64
            * 12;
        if per_frame > self.gpu.limits.max_storage_buffer_binding_size {
            return Err(super::invalid(
                "optics.size",
                format!(
                    "a {} x {} frame needs {per_frame} bytes per buffer; the device binds at most {}",
                    optics.width, optics.height, self.gpu.limits.max_storage_buffer_binding_size
                ),
            ));
        }
        let chunk = ((self.gpu.limits.max_storage_buffer_binding_size / per_frame) as usize)
            .clamp(1, MAX_FRAMES_PER_DISPATCH);
        let background: Vec<f32> = optics.background.iter().flatten().copied().collect();
        let table: &[f32] = match &optics.shading {
            Shading::Table(t) => &t.coefficients,
            Shading::Lights(_) => &[],
        };
        let shared = OpticsBuffers {
            background: self.storage("background", bytemuck::cast_slice(&background)),
            table: self.storage("shading table", bytemuck::cast_slice(table)),
            rest: self.storage("marker rest", bytemuck::cast_slice(&optics.markers)),
            glow: optics.glow.as_ref().map(|g| self.glow_buffers(optics, g)),
        };
        let mut out = Vec::with_capacity(frames.len());
        for part in frames.chunks(chunk) {
            out.extend(self.render_chunk(optics, part, &shared)?);
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::device::shader_checks::{struct_size, validated};

    #[test]
    fn every_shader_parses_and_validates_with_naga() {
        for (stage, _) in SHADER_SOURCES {
            let module = validated(stage, &shader_source(stage).unwrap());
            assert!(
                module.entry_points.iter().any(|e| e.name == "main"),
                "{stage} has no main entry point"
            );
        }
    }

    #[test]
    fn glow_term_block_matches_the_shader_layout() {
        let source = shader_source("gel_glow_rows").unwrap();
        assert_eq!(
            struct_size(&source, "GlowTerm"),
            std::mem::size_of::<GlowTermBlock>()
        );
    }

    #[test]
    fn uniform_block_matches_the_shader_layout() {
        let source = shader_source("gel_slopes").unwrap();
        assert_eq!(
            struct_size(&source, "RenderParams"),
            std::mem::size_of::<RenderParams>()
        );
    }
}
