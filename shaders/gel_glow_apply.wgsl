// Glow, last pass: the shaded frame becomes the flat gel's shading plus the glow.

@group(0) @binding(1) var<storage, read> flat: array<f32>;
@group(0) @binding(2) var<storage, read> glow: array<f32>;
@group(0) @binding(3) var<storage, read_write> shaded: array<f32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_frame(id)) {
        return;
    }
    let pixel = id.y * params.width + id.x;
    let k = (id.z * pixel_count() + pixel) * 3u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        shaded[k + c] = flat[pixel * 3u + c] + glow[k + c];
    }
}
