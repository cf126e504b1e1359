// fairmesh viewport shader: flat-shaded triangles (one normal per triangle, from the screen-space
// derivatives of the world position, so positions are uploaded once and shared by all corners),
// an optional per-vertex heat map (viridis), and a wireframe drawn as lines over the filled mesh.

struct Uniforms {
    view_proj: mat4x4<f32>,
    // xyz: camera position in world space.
    eye: vec4<f32>,
    // xyz: direction towards the key light, world space, unit length.
    light_dir: vec4<f32>,
    base_color: vec4<f32>,
    wire_color: vec4<f32>,
    // x: scalar mapped to blue, y: scalar mapped to red, z: 1 when scalars are a heat map, 2
    // when they are a mask (0 to 1) tinted over the base colour.
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

// Viridis for t in 0..1: the ten sRGB key colours of `src/render/colormap.rs` (which the legend
// uses), interpolated in sRGB as there, then made linear because the target is an sRGB format.
fn viridis(t: f32) -> vec3<f32> {
    var keys = array<vec3<f32>, 10>(
        vec3<f32>(68.0, 1.0, 84.0),
        vec3<f32>(72.0, 40.0, 120.0),
        vec3<f32>(62.0, 74.0, 137.0),
        vec3<f32>(49.0, 104.0, 142.0),
        vec3<f32>(38.0, 130.0, 142.0),
        vec3<f32>(31.0, 158.0, 137.0),
        vec3<f32>(53.0, 183.0, 121.0),
        vec3<f32>(109.0, 205.0, 89.0),
        vec3<f32>(180.0, 222.0, 44.0),
        vec3<f32>(253.0, 231.0, 37.0),
    );
    let x = clamp(t, 0.0, 1.0) * 9.0;
    let i = min(u32(floor(x)), 8u);
    let f = x - f32(i);
    let srgb = mix(keys[i], keys[i + 1u], f) / 255.0;
    let low = srgb / 12.92;
    let high = pow((srgb + 0.055) / 1.055, vec3<f32>(2.4));
    return select(high, low, srgb <= vec3<f32>(0.04045));
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
    if (u.scalar_range.z > 1.5) {
        // The painted region in a warm orange, as strong as its weight.
        albedo = mix(albedo, vec3<f32>(0.95, 0.28, 0.06), 0.5 * clamp(in.scalar, 0.0, 1.0));
    } else if (u.scalar_range.z > 0.5) {
        let span = max(u.scalar_range.y - u.scalar_range.x, 1e-20);
        albedo = viridis((in.scalar - u.scalar_range.x) / span);
    }
    if (!front) {
        // Back faces (holes, inverted patches) in a cooler, darker tone.
        albedo = albedo * vec3<f32>(0.55, 0.6, 0.8);
    }
    let key = max(dot(normal, u.light_dir.xyz), 0.0);
    let fill = max(dot(normal, to_eye), 0.0);
    var shade = 0.08 + 0.72 * key + 0.25 * fill;
    if (u.scalar_range.z > 0.5 && u.scalar_range.z < 1.5) {
        // Flatter lighting for the heat map, so its colours read as the legend shows them.
        shade = 0.55 + 0.3 * key + 0.2 * fill;
    }
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
