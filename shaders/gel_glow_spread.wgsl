// Glow, pass 3 of a term: the blur at the term's samples interpolated bilinearly to every
// pixel (exactly the sample where the step is 1), mixed across channels and added to the
// glow.

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> blurred: array<f32>;
@group(0) @binding(3) var<storage, read_write> glow: array<f32>;

// The samples around pixel p of an axis of `len` pixels, and the second one's weight.
struct Between {
    first: u32,
    second: u32,
    t: f32,
}

fn between(p: u32, len: u32) -> Between {
    let n = sample_count(len, term.step);
    let first = min(p / term.step, n - 1u);
    let second = min(first + 1u, n - 1u);
    let a = sample_at(first, len, term.step);
    let b = sample_at(second, len, term.step);
    var t = 0.0;
    if (b > a) {
        t = f32(p - a) / f32(b - a);
    }
    return Between(first, second, t);
}

fn sample(frame: u32, x: u32, y: u32) -> vec3<f32> {
    let k = (frame * pixel_count() + y * params.width + x) * 3u;
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
