// Glow, pass 2 of a term: the row-blurred source blurred down each sampled column, edges
// extended, at the term's sample rows: invocation (x, y) is sample (x, y), written there.

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> kernel: array<f32>;
@group(0) @binding(3) var<storage, read> along_rows: array<f32>;
@group(0) @binding(4) var<storage, read_write> blurred: array<f32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_frame(id) || id.x >= sample_count(params.width, term.step)
        || id.y >= sample_count(params.height, term.step)) {
        return;
    }
    let at = i32(sample_at(id.y, params.height, term.step));
    let r = i32(term.radius);
    var sum = vec3<f32>(0.0);
    for (var i = -r; i <= r; i = i + 1) {
        let y = u32(clamp(at + i, 0, i32(params.height) - 1));
        let k = (id.z * pixel_count() + y * params.width + id.x) * 3u;
        sum = sum + kernel[term.offset + u32(i + r)] * vec3<f32>(along_rows[k], along_rows[k + 1u], along_rows[k + 2u]);
    }
    let out = (id.z * pixel_count() + id.y * params.width + id.x) * 3u;
    blurred[out] = sum.x;
    blurred[out + 1u] = sum.y;
    blurred[out + 2u] = sum.z;
}
