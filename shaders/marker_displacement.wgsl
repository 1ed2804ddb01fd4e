// Stage 3, markers: each printed dot's centre moves with the gel's lateral displacement,
// sampled bilinearly at its rest position, per frame of the batch.

@group(0) @binding(1) var<storage, read> lateral_x: array<f32>;
@group(0) @binding(2) var<storage, read> lateral_y: array<f32>;
@group(0) @binding(3) var<storage, read> rest: array<vec2<f32>>;
@group(0) @binding(4) var<storage, read_write> centres: array<vec2<f32>>;

fn sample(field_x: bool, base: u32, p: vec2<f32>) -> f32 {
    let w = params.width;
    let h = params.height;
    // Pixel centres sit at integer + 1/2; clamp to the frame.
    let q = clamp(p - vec2<f32>(0.5, 0.5), vec2<f32>(0.0, 0.0), vec2<f32>(f32(w - 1u), f32(h - 1u)));
    let i0 = min(u32(floor(q.x)), w - 2u);
    let j0 = min(u32(floor(q.y)), h - 2u);
    let fx = q.x - f32(i0);
    let fy = q.y - f32(j0);
    let k = base + j0 * w + i0;
    var a: vec4<f32>;
    if (field_x) {
        a = vec4<f32>(lateral_x[k], lateral_x[k + 1u], lateral_x[k + w], lateral_x[k + w + 1u]);
    } else {
        a = vec4<f32>(lateral_y[k], lateral_y[k + 1u], lateral_y[k + w], lateral_y[k + w + 1u]);
    }
    return (a.x * (1.0 - fx) + a.y * fx) * (1.0 - fy) + (a.z * (1.0 - fx) + a.w * fx) * fy;
}

@compute @workgroup_size(64, 1, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (id.x >= params.markers || id.y >= params.frames) {
        return;
    }
    let base = id.y * pixel_count();
    let p = rest[id.x];
    let d = vec2<f32>(sample(true, base, p), sample(false, base, p)) / params.mm_per_px;
    centres[id.y * params.markers + id.x] = p + d;
}
