// fairmesh viewport shader: flat-shaded triangles (one normal per triangle, from the screen-space
// derivatives of the world position, so positions are uploaded once and shared by all corners),
// an optional per-vertex heat map, and a wireframe drawn as lines over the filled mesh.

struct Uniforms {
    view_proj: mat4x4<f32>,
    // xyz: camera position in world space.
    eye: vec4<f32>,
    // xyz: direction towards the key light, world space, unit length.
    light_dir: vec4<f32>,
    base_color: vec4<f32>,
    wire_color: vec4<f32>,
    // x: scalar mapped to blue, y: scalar mapped to red, z: 1 when scalars are shown.
    scalar_range: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) scalar: f32,
};

@vertex
fn vs_mesh(@location(0) position: vec3<f32>, @location(1) scalar: f32) -> MeshOut {
    var out: MeshOut;
    out.clip = u.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    out.scalar = scalar;
    return out;
}

// Blue - cyan - green - yellow - red ramp for t in 0..1.
fn heat(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    let r = clamp(1.5 - abs(4.0 * x - 3.0), 0.0, 1.0);
    let g = clamp(1.5 - abs(4.0 * x - 2.0), 0.0, 1.0);
    let b = clamp(1.5 - abs(4.0 * x - 1.0), 0.0, 1.0);
    return vec3<f32>(r, g, b);
}

@fragment
fn fs_mesh(in: MeshOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    // Both derivatives lie in the triangle's plane, so their cross product is the face normal:
    // flat shading without duplicating vertices per triangle.
    let across = cross(dpdx(in.world), dpdy(in.world));
    let to_eye = normalize(u.eye.xyz - in.world);
    var normal = to_eye;
    if (dot(across, across) > 0.0) {
        normal = normalize(across);
    }
    // Light the side that faces the camera, whichever way the triangle is wound.
    if (dot(normal, to_eye) < 0.0) {
        normal = -normal;
    }
    var albedo = u.base_color.rgb;
    if (u.scalar_range.z > 0.5) {
        let span = max(u.scalar_range.y - u.scalar_range.x, 1e-20);
        albedo = heat((in.scalar - u.scalar_range.x) / span);
    }
    if (!front) {
        // Back faces (holes, inverted patches) in a cooler, darker tone.
        albedo = albedo * vec3<f32>(0.55, 0.6, 0.8);
    }
    let key = max(dot(normal, u.light_dir.xyz), 0.0);
    let fill = max(dot(normal, to_eye), 0.0);
    let shade = 0.08 + 0.72 * key + 0.25 * fill;
    return vec4<f32>(albedo * shade, 1.0);
}

@vertex
fn vs_line(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return u.view_proj * vec4<f32>(position, 1.0);
}

@fragment
fn fs_line() -> @location(0) vec4<f32> {
    return u.wire_color;
}
