// Stage 2, shading: each pixel's slope -> RGB over the no-contact background, by the analytic
// coloured-light model or by the calibrated gradient table (Taxim-style bins over gradient
// magnitude and direction, each a per-channel quadratic in pixel position, interpolated
// bilinearly between bins), then lens vignetting.

@group(0) @binding(1) var<storage, read> slopes: array<vec2<f32>>;
@group(0) @binding(2) var<storage, read> background: array<f32>;
@group(0) @binding(3) var<storage, read> table: array<f32>;
@group(0) @binding(4) var<storage, read_write> shaded: array<f32>;

const TAU: f32 = 6.28318530717958647692;

// Table node (magnitude m, direction d), channel c, at normalised position (u, v).
fn table_node(m: u32, d: u32, c: u32, u: f32, v: f32) -> f32 {
    let k = ((m * params.dir_bins + d) * 3u + c) * 6u;
    return table[k] + table[k + 1u] * u + table[k + 2u] * v + table[k + 3u] * u * u
        + table[k + 4u] * u * v + table[k + 5u] * v * v;
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = params.width;
    let h = params.height;
    if (outside_frame(id)) {
        return;
    }
    let pixel = id.y * w + id.x;
    let g = slopes[id.z * pixel_count() + pixel];
    let bg = vec3<f32>(background[pixel * 3u], background[pixel * 3u + 1u], background[pixel * 3u + 2u]);
    let u = (f32(id.x) + 0.5) / f32(w) - 0.5;
    let v = (f32(id.y) + 0.5) / f32(h) - 0.5;
    var colour: vec3<f32>;
    if (params.shading == 0u) {
        let n = normalize(vec3<f32>(-g.x, -g.y, 1.0));
        var gain: vec3<f32>;
        for (var c = 0u; c < 3u; c = c + 1u) {
            let l = params.lights[c].xyz;
            gain[c] = (params.ambient + params.light_gain * max(dot(n, l), 0.0))
                / (params.ambient + params.light_gain * l.z);
        }
        colour = bg * gain;
    } else {
        let mag = min(length(g), params.mag_max);
        let fm = mag / params.mag_max * f32(params.mag_bins - 1u);
        let m0 = min(u32(floor(fm)), params.mag_bins - 2u);
        let tm = fm - f32(m0);
        let fd = (atan2(g.y, g.x) + TAU * 0.5) / TAU * f32(params.dir_bins);
        let fd0 = floor(fd);
        let td = fd - fd0;
        let d0 = u32(fd0) % params.dir_bins;
        let d1 = (d0 + 1u) % params.dir_bins;
        let pu = 2.0 * u;
        let pv = 2.0 * v;
        for (var c = 0u; c < 3u; c = c + 1u) {
            let lo = table_node(m0, d0, c, pu, pv) * (1.0 - td) + table_node(m0, d1, c, pu, pv) * td;
            let hi = table_node(m0 + 1u, d0, c, pu, pv) * (1.0 - td)
                + table_node(m0 + 1u, d1, c, pu, pv) * td;
            colour[c] = bg[c] + lo * (1.0 - tm) + hi * tm;
        }
    }
    let fade = 1.0 - params.vignette * (u * u + v * v);
    let out = (id.z * pixel_count() + pixel) * 3u;
    for (var c = 0u; c < 3u; c = c + 1u) {
        shaded[out + c] = colour[c] * fade;
    }
}
