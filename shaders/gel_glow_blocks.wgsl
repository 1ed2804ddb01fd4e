// Glow, pass 1 of a term: the term's source (the shading's change from the flat gel's
// shading, its magnitude, the gel's indentation, or the change times the indentation)
// averaged over each block of the term's grid, edges extended (`gel_glow::block_means`):
// invocation (x, y) is block (x, y).

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> flat: array<f32>;
@group(0) @binding(3) var<storage, read> shaded: array<f32>;
@group(0) @binding(4) var<storage, read> heights: array<f32>;
@group(0) @binding(5) var<storage, read_write> blocks: array<f32>;

fn source(frame: u32, x: u32, y: u32) -> vec3<f32> {
    let pixel = y * params.width + x;
    let k = (frame * pixel_count() + pixel) * 3u;
    let f = pixel * 3u;
    let change = vec3<f32>(shaded[k] - flat[f], shaded[k + 1u] - flat[f + 1u], shaded[k + 2u] - flat[f + 2u]);
    let indentation = heights[frame * pixel_count() + pixel];
    switch term.source {
        case 1u: {
            return vec3<f32>(length(change), 0.0, 0.0);
        }
        case 2u: {
            return vec3<f32>(indentation, 0.0, 0.0);
        }
        case 3u: {
            return change * indentation;
        }
        default: {
            return change;
        }
    }
}

// The pixel of an axis of `len` pixels that offset i into the term's blocks stands for.
fn block_pixel(i: u32, len: u32) -> u32 {
    return min(max(i, term.factor) - term.factor, len - 1u);
}

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_blocks(id, term.factor)) {
        return;
    }
    let d = term.factor;
    var sum = vec3<f32>(0.0);
    for (var dy = 0u; dy < d; dy = dy + 1u) {
        let y = block_pixel(id.y * d + dy, params.height);
        for (var dx = 0u; dx < d; dx = dx + 1u) {
            sum = sum + source(id.z, block_pixel(id.x * d + dx, params.width), y);
        }
    }
    let out = block_index(id.z, id.x, id.y, d) * 3u;
    let mean = sum / f32(d * d);
    blocks[out] = mean.x;
    blocks[out + 1u] = mean.y;
    blocks[out + 2u] = mean.z;
}
