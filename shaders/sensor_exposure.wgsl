// Stage 4, exposure: the marker dots darken the shaded gel (anti-aliased over one pixel), the
// camera's exposure gain, then seeded camera noise and 8-bit quantisation, packed as RGBA8.

@group(0) @binding(1) var<storage, read> shaded: array<f32>;
@group(0) @binding(2) var<storage, read> centres: array<vec2<f32>>;
@group(0) @binding(3) var<storage, read> frame_seeds: array<u32>;
@group(0) @binding(4) var<storage, read_write> pixels: array<u32>;

// PCG hash (O'Neill; Jarzynski & Olano 2020): the same counter-based generator as the CPU path.
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// The 24-bit count behind a uniform draw: 1..=2^24, exact in f32.
fn count(h: u32) -> f32 {
    return f32((h >> 8u) + 1u);
}

// ln(n / 2^24), n = count(h) = m 2^e, m in [1, 2): ln m = 2 atanh((m - 1)/(m + 1)) by its
// series, the CPU path's polynomial (no built-in log, whose precision the device chooses).
fn ln_unit(h: u32) -> f32 {
    let bits = bitcast<u32>(count(h));
    let e = f32(i32(bits >> 23u) - 127 - 24);
    let m = bitcast<f32>((bits & 0x007fffffu) | 0x3f800000u);
    let t = (m - 1.0) / (m + 1.0);
    let t2 = t * t;
    let series = 1.0 + t2 * (1.0 / 3.0 + t2 * (1.0 / 5.0 + t2 * (1.0 / 7.0 + t2 * (1.0 / 9.0))));
    return e * 0.69314718055994530942 + 2.0 * t * series;
}

// (cos, sin) of 2 pi u from the half angle a = pi u - pi/2 in (-pi/2, pi/2], as on the CPU.
fn cis_unit(h: u32) -> vec2<f32> {
    let a = 3.14159265358979323846 * (count(h) * (1.0 / 16777216.0) - 0.5);
    let a2 = a * a;
    let s = a * (1.0 + a2 * (-1.0 / 6.0 + a2 * (1.0 / 120.0
        + a2 * (-1.0 / 5040.0 + a2 * (1.0 / 362880.0 - a2 / 39916800.0)))));
    let c = 1.0 + a2 * (-0.5 + a2 * (1.0 / 24.0 + a2 * (-1.0 / 720.0
        + a2 * (1.0 / 40320.0 + a2 * (-1.0 / 3628800.0 + a2 / 479001600.0)))));
    return vec2<f32>(s * s - c * c, -2.0 * s * c);
}

// Three standard normal draws for (frame seed, pixel) by Box-Muller: the first pair gives red
// and green (cosine and sine), the second blue.
fn gaussian3(seed: u32, pixel: u32) -> vec3<f32> {
    let key = pcg(seed ^ pcg(pixel));
    let r1 = sqrt(-2.0 * ln_unit(pcg(key)));
    let a1 = cis_unit(pcg(key ^ 0x9e3779b9u));
    let r2 = sqrt(-2.0 * ln_unit(pcg(key ^ 0x85ebca6bu)));
    let a2 = cis_unit(pcg(key ^ 0xc2b2ae35u));
    return vec3<f32>(r1 * a1.x, r1 * a1.y, r2 * a2.x);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = params.width;
    if (outside_frame(id)) {
        return;
    }
    let pixel = id.y * w + id.x;
    let k = (id.z * pixel_count() + pixel) * 3u;
    var colour = vec3<f32>(shaded[k], shaded[k + 1u], shaded[k + 2u]);
    let here = vec2<f32>(f32(id.x) + 0.5, f32(id.y) + 0.5);
    let reach = params.marker_radius_px + 0.5;
    for (var m = 0u; m < params.markers; m = m + 1u) {
        let d = distance(here, centres[id.z * params.markers + m]);
        if (d < reach) {
            colour = colour * (1.0 - params.marker_darkness * min(reach - d, 1.0));
        }
    }
    colour = colour * params.exposure;
    let noise = gaussian3(frame_seeds[id.z], pixel);
    var packed = 0xff000000u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        let noisy = colour[c] + params.noise_sigma * noise[c];
        packed = packed | (u32(clamp(floor(noisy + 0.5), 0.0, 255.0)) << (8u * c));
    }
    pixels[id.z * pixel_count() + pixel] = packed;
}
