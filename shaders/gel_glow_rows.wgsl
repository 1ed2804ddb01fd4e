// Glow, pass 1 of a term: the term's source (the shading's change from the flat gel's
// shading, its magnitude, the gel's indentation, or the change times the indentation)
// blurred along each row, edges extended, at the term's sample columns: invocation x is
// sample x, written at column x.

@group(0) @binding(1) var<uniform> term: GlowTerm;
@group(0) @binding(2) var<storage, read> kernel: array<f32>;
@group(0) @binding(3) var<storage, read> flat: array<f32>;
@group(0) @binding(4) var<storage, read> shaded: array<f32>;
@group(0) @binding(5) var<storage, read> heights: array<f32>;
@group(0) @binding(6) var<storage, read_write> along_rows: array<f32>;

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

@compute @workgroup_size(8, 8, 1)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    if (outside_frame(id) || id.x >= sample_count(params.width, term.step)) {
        return;
    }
    let at = i32(sample_at(id.x, params.width, term.step));
    let r = i32(term.radius);
    var sum = vec3<f32>(0.0);
    for (var i = -r; i <= r; i = i + 1) {
        let x = u32(clamp(at + i, 0, i32(params.width) - 1));
        sum = sum + kernel[term.offset + u32(i + r)] * source(id.z, x, id.y);
    }
    let out = (id.z * pixel_count() + id.y * params.width + id.x) * 3u;
    along_rows[out] = sum.x;
    along_rows[out + 1u] = sum.y;
    along_rows[out + 2u] = sum.z;
}
