// Stage 1, surface normals: slopes (dw/dx, dw/dy) of the gel's normal indentation w by central
// differences (one-sided at the frame edge), per pixel and frame of the batch.

@group(0) @binding(1) var<storage, read> heights: array<f32>;
@group(0) @binding(2) var<storage, read_write> slopes: array<vec2<f32>>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = params.width;
    let h = params.height;
    if (outside_frame(id)) {
        return;
    }
    let base = id.z * pixel_count();
    let x0 = select(id.x - 1u, 0u, id.x == 0u);
    let x1 = min(id.x + 1u, w - 1u);
    let y0 = select(id.y - 1u, 0u, id.y == 0u);
    let y1 = min(id.y + 1u, h - 1u);
    let gx = (heights[base + id.y * w + x1] - heights[base + id.y * w + x0])
        / (f32(x1 - x0) * params.mm_per_px);
    let gy = (heights[base + y1 * w + id.x] - heights[base + y0 * w + id.x])
        / (f32(y1 - y0) * params.mm_per_px);
    slopes[base + id.y * w + id.x] = vec2<f32>(gx, gy);
}
