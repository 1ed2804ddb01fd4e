// Glow, pass 2 of a term: the block means blurred along each row of blocks, edges extended:
// invocation (x, y) is block (x, y).

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> kernel: array<f32>;
@group(0) @binding(3) var<storage, read> blocks: array<f32>;
@group(0) @binding(4) var<storage, read_write> along_rows: array<f32>;

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_blocks(id, term.factor)) {
        return;
    }
    let last = i32(block_count(params.width, term.factor)) - 1;
    let r = i32(term.radius);
    var sum = vec3<f32>(0.0);
    for (var i = -r; i <= r; i = i + 1) {
        let x = u32(clamp(i32(id.x) + i, 0, last));
        let k = block_index(id.z, x, id.y, term.factor) * 3u;
        sum = sum + kernel[term.offset + u32(i + r)] * vec3<f32>(blocks[k], blocks[k + 1u], blocks[k + 2u]);
    }
    let out = block_index(id.z, id.x, id.y, term.factor) * 3u;
    along_rows[out] = sum.x;
    along_rows[out + 1u] = sum.y;
    along_rows[out + 2u] = sum.z;
}
