// Stage 4, exposure: the marker dots darken the shaded gel (anti-aliased over one pixel),
// then seeded camera noise and 8-bit quantisation, packed as RGBA8.

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

fn unit(h: u32) -> f32 {
    return (f32(h >> 8u) + 1.0) / 16777216.0;
}

// Three standard normal draws for (frame seed, pixel) by Box-Muller: the first pair gives red
// and green (cosine and sine), the second blue.
fn gaussian3(seed: u32, pixel: u32) -> vec3<f32> {
    let key = pcg(seed ^ pcg(pixel));
    let r1 = sqrt(-2.0 * log(unit(pcg(key))));
    let t1 = 6.28318530717958647692 * unit(pcg(key ^ 0x9e3779b9u));
    let r2 = sqrt(-2.0 * log(unit(pcg(key ^ 0x85ebca6bu))));
    let t2 = 6.28318530717958647692 * unit(pcg(key ^ 0xc2b2ae35u));
    return vec3<f32>(r1 * cos(t1), r1 * sin(t1), r2 * cos(t2));
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
    let noise = gaussian3(frame_seeds[id.z], pixel);
    var packed = 0xff000000u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        let noisy = colour[c] + params.noise_sigma * noise[c];
        packed = packed | (u32(clamp(floor(noisy + 0.5), 0.0, 255.0)) << (8u * c));
    }
    pixels[id.z * pixel_count() + pixel] = packed;
}
