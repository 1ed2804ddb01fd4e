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
    // The size of the blocks the source is averaged over before the blur (1: every pixel), as
    // `gel_glow::blur_factor`.
    factor: u32,
}

// Blocks of size d along an axis of `len` pixels: one outside each end and those covering it
// (`gel_glow::block_count`).
fn block_count(len: u32, d: u32) -> u32 {
    return (len + d - 1u) / d + 2u;
}

// Where block (x, y) of a frame's grid of blocks of size d is kept: frame after frame.
fn block_index(frame: u32, x: u32, y: u32, d: u32) -> u32 {
    let w = block_count(params.width, d);
    return (frame * block_count(params.height, d) + y) * w + x;
}

// Whether an invocation of a per-block stage falls outside the batch's grids of blocks.
fn outside_blocks(id: vec3<u32>, d: u32) -> bool {
    return id.x >= block_count(params.width, d) || id.y >= block_count(params.height, d)
        || id.z >= params.frames;
}

fn pixel_count() -> u32 {
    return params.width * params.height;
}

// Whether an invocation of a per-pixel stage falls outside the batch (workgroups overhang).
fn outside_frame(id: vec3<u32>) -> bool {
    return id.x >= params.width || id.y >= params.height || id.z >= params.frames;
}
