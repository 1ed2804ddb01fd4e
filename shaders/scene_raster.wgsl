// The RGB-D scene renderer's raster pipeline: pinhole projection at the camera's intrinsics
// (pixel x's centre at u = x, as in OpenCV and the CPU reference: the Rust side adds half a
// pixel to the principal point), depth test on camera z, and per fragment
// ambient plus Lambert light with a Blinn-Phong highlight on objects (id > 0). Four outputs:
// colour with the specular share in alpha, camera-frame depth in metres, and the instance id.
// `SceneParams` is laid out exactly as the Rust struct of the same name (uniform, 144 bytes).

struct SceneParams {
    // World to camera frame (column-major, camera z forward, y down).
    world_to_camera: mat4x4<f32>,
    // fx, fy, cx, cy in pixels.
    focal_centre: vec4<f32>,
    // width, height (pixels), near, far (metres).
    viewport: vec4<f32>,
    // xyz: unit direction towards the light, world frame.
    light: vec4<f32>,
    // xyz: camera position, world frame.
    eye: vec4<f32>,
    // ambient, diffuse, specular peak, shininess.
    shading: vec4<f32>,
}

@group(0) @binding(0) var<uniform> params: SceneParams;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) colour: vec3<f32>,
    @location(3) instance: u32,
}

struct VertexOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) colour: vec3<f32>,
    @location(3) camera_z: f32,
    @location(4) @interpolate(flat) instance: u32,
}

@vertex
fn vs_main(v: VertexIn) -> VertexOut {
    let cam = (params.world_to_camera * vec4<f32>(v.position, 1.0)).xyz;
    // Pixel coordinates times z, so that the divide by w = z gives the pinhole projection.
    let px = params.focal_centre.x * cam.x + params.focal_centre.z * cam.z;
    let py = params.focal_centre.y * cam.y + params.focal_centre.w * cam.z;
    let near = params.viewport.z;
    let far = params.viewport.w;
    var out: VertexOut;
    out.clip = vec4<f32>(
        2.0 * px / params.viewport.x - cam.z,
        cam.z - 2.0 * py / params.viewport.y,
        far * (cam.z - near) / (far - near),
        cam.z,
    );
    out.world = v.position;
    out.normal = v.normal;
    out.colour = v.colour;
    out.camera_z = cam.z;
    out.instance = v.instance;
    return out;
}

struct FragmentOut {
    @location(0) colour: vec4<f32>,
    @location(1) depth: f32,
    @location(2) instance: u32,
}

@fragment
fn fs_main(in: VertexOut) -> FragmentOut {
    var n = vec3<f32>(0.0, 0.0, 1.0);
    if (length(in.normal) > 0.0) {
        n = normalize(in.normal);
    }
    let light = params.light.xyz;
    let shade = params.shading.x + params.shading.y * max(dot(n, light), 0.0);
    var spec = 0.0;
    if (in.instance > 0u) {
        // Fruit skins are waxy: a soft highlight; the table is matte.
        var view = params.eye.xyz - in.world;
        if (length(view) > 0.0) {
            view = normalize(view);
        } else {
            view = vec3<f32>(0.0, 0.0, 1.0);
        }
        let half_way = normalize(light + view);
        spec = params.shading.z * pow(max(dot(n, half_way), 0.0), params.shading.w);
    }
    var out: FragmentOut;
    out.colour = vec4<f32>(min(in.colour * shade + vec3<f32>(spec), vec3<f32>(1.0)), spec);
    out.depth = in.camera_z;
    out.instance = in.instance;
    return out;
}
