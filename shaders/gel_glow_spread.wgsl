// Glow, pass 4 of a term: the blurred blocks interpolated bilinearly to every pixel (exactly
// the block where the factor is 1), mixed across channels and added to the glow.

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> blurred: array<f32>;
@group(0) @binding(3) var<storage, read_write> glow: array<f32>;

// The blocks whose centres lie either side of pixel p of an axis of `len` pixels, and the
// second one's weight (`gel_glow::between_blocks`).
struct Between {
    first: u32,
    second: u32,
    t: f32,
}

fn between(p: u32, len: u32) -> Between {
    let d = i32(term.factor);
    let n = i32(block_count(len, term.factor));
    // Block i is centred at (i - 1) d + (d - 1) / 2: in half pixels, 2 p + 1 + d from block 0's.
    let from_first = 2 * i32(p) + 1 + d;
    let i = from_first / (2 * d);
    if (i + 1 >= n) {
        return Between(u32(n - 1), u32(n - 1), 0.0);
    }
    let t = f32(from_first - 2 * (d * i)) / f32(2 * d);
    return Between(u32(i), u32(i + 1), t);
}

fn sample(frame: u32, x: u32, y: u32) -> vec3<f32> {
    let k = block_index(frame, x, y, term.factor) * 3u;
    return vec3<f32>(blurred[k], blurred[k + 1u], blurred[k + 2u]);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_frame(id)) {
        return;
    }
    let across = between(id.x, params.width);
    let down = between(id.y, params.height);
    let top = sample(id.z, across.first, down.first) * (1.0 - across.t)
        + sample(id.z, across.second, down.first) * across.t;
    let bottom = sample(id.z, across.first, down.second) * (1.0 - across.t)
        + sample(id.z, across.second, down.second) * across.t;
    let value = top * (1.0 - down.t) + bottom * down.t;
    let out = (id.z * pixel_count() + id.y * params.width + id.x) * 3u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        glow[out + c] = glow[out + c] + dot(term.mix[c].xyz, value);
    }
}
