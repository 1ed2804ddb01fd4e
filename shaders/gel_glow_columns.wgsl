// Glow, pass 2 of a term: the row-blurred source blurred down each column, edges extended,
// mixed across channels and added to the glow.

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> kernel: array<f32>;
@group(0) @binding(3) var<storage, read> along_rows: array<f32>;
@group(0) @binding(4) var<storage, read_write> glow: array<f32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_frame(id)) {
        return;
    }
    let r = i32(term.radius);
    var sum = vec3<f32>(0.0);
    for (var i = -r; i <= r; i = i + 1) {
        let y = u32(clamp(i32(id.y) + i, 0, i32(params.height) - 1));
        let k = (id.z * pixel_count() + y * params.width + id.x) * 3u;
        sum = sum + kernel[term.offset + u32(i + r)] * vec3<f32>(along_rows[k], along_rows[k + 1u], along_rows[k + 2u]);
    }
    let out = (id.z * pixel_count() + id.y * params.width + id.x) * 3u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        glow[out + c] = glow[out + c] + dot(term.mix[c].xyz, sum);
    }
}
