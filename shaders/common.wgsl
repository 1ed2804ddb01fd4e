// Shared by every GelSight stage (prepended to each stage's source): the frame geometry and
// render settings, laid out exactly as the Rust `RenderParams` (uniform layout, 112 bytes).
struct RenderParams {
    // Unit directions from the gel towards the red, green and blue lights (w unused).
    lights: array<vec4<f32>, 3>,
    width: u32,
    height: u32,
    frames: u32,
    // 0: analytic coloured lights over the background; 1: calibrated gradient table.
    shading: u32,
    mm_per_px: f32,
    ambient: f32,
    light_gain: f32,
    noise_sigma: f32,
    vignette: f32,
    marker_radius_px: f32,
    marker_darkness: f32,
    markers: u32,
    mag_bins: u32,
    dir_bins: u32,
    mag_max: f32,
    // Gain on the light reaching the camera: after the marker dots, before the noise.
    exposure: f32,
}

@group(0) @binding(0) var<uniform> params: RenderParams;

// One glow term as the glow stages read it (the Rust `GlowTermBlock`, 64 bytes).
struct GlowTerm {
    // Rows of the 3x3 mix into the output (w unused).
    mix: array<vec4<f32>, 3>,
    // Where the term's kernel starts in the stages' kernel array, and its radius (taps -r..=r).
    offset: u32,
    radius: u32,
    // The source (GlowSource::code): 0 the change, 1 its magnitude (in channel 0), 2 the
    // gel's indentation in mm (in channel 0), 3 the change times the indentation.
    source: u32,
    // The spacing of the grid the blur is computed on (1: every pixel), as `blur_step`.
    step: u32,
}

// Samples a blur with `step` takes along an axis of `len` pixels: every step-th and the last
// (`blur_samples`).
fn sample_count(len: u32, step: u32) -> u32 {
    if ((len - 1u) % step == 0u) {
        return (len - 1u) / step + 1u;
    }
    return (len - 1u) / step + 2u;
}

// The pixel sample j of an axis of `len` pixels lies at.
fn sample_at(j: u32, len: u32, step: u32) -> u32 {
    return min(j * step, len - 1u);
}

fn pixel_count() -> u32 {
    return params.width * params.height;
}

// Whether an invocation of a per-pixel stage falls outside the batch (workgroups overhang).
fn outside_frame(id: vec3<u32>) -> bool {
    return id.x >= params.width || id.y >= params.height || id.z >= params.frames;
}
