// fairmesh viewport shader: triangles lit flat (one normal per triangle, from the screen-space
// derivatives of the world position, so positions are uploaded once and shared by all corners) or
// smooth (the area-weighted vertex normals the renderer computes, blended across each triangle),
// under simple or studio lighting; the surface's colour from the file's material (base colour
// factor times its base colour texture at the vertex's texture coordinates) times its vertex
// colour, or the clay colour; an optional per-vertex heat map (viridis) and painted-mask
// tint (an orange tint, or its outline over a heat map); and a wireframe drawn as lines over the
// filled mesh.

struct Uniforms {
    view_proj: mat4x4<f32>,
    // xyz: camera position in world space.
    eye: vec4<f32>,
    // xyz: direction towards the key light, world space, unit length.
    light_dir: vec4<f32>,
    // xyz: direction towards the studio fill light, world space, unit length.
    fill_dir: vec4<f32>,
    // xyz: the camera's up direction, world space, unit length.
    up: vec4<f32>,
    base_color: vec4<f32>,
    wire_color: vec4<f32>,
    // x: scalar mapped to the map's low end, y: to its high end, z: 1 when the scalars are
    // shown as a heat map, w: 1 when the mask weights (0 to 1) are shown.
    scalar_range: vec4<f32>,
    // x: 1 for smooth shading (vertex normals), y: 1 for the studio lighting, z: 1 to draw the
    // materials' colours (0: clay), w: vertex colours (+1) and texture coordinates (+2) there.
    look: vec4<f32>,
};

@group(0) @binding(0) var<uniform> u: Uniforms;

struct Material {
    // Linear RGBA.
    base_colour: vec4<f32>,
    // x: 1 when the material has a base colour texture.
    flags: vec4<f32>,
    // The texture transform (KHR_texture_transform): the texture is read at
    // (dot(uv_u.xyz, (u, v, 1)), dot(uv_v.xyz, (u, v, 1))).
    uv_u: vec4<f32>,
    uv_v: vec4<f32>,
};

@group(1) @binding(0) var<uniform> material: Material;
@group(1) @binding(1) var base_texture: texture_2d<f32>;
@group(1) @binding(2) var base_sampler: sampler;

struct MeshOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) scalar: f32,
    @location(2) normal: vec3<f32>,
    @location(3) mask: f32,
    @location(4) uv: vec2<f32>,
    @location(5) colour: vec4<f32>,
};

@vertex
fn vs_mesh(
    @location(0) position: vec3<f32>,
    @location(1) scalar: f32,
    @location(2) normal: vec3<f32>,
    @location(3) mask: f32,
    @location(4) uv: vec2<f32>,
    @location(5) colour: vec4<f32>,
) -> MeshOut {
    var out: MeshOut;
    out.mask = mask;
    out.uv = uv;
    out.colour = colour;
    out.clip = u.view_proj * vec4<f32>(position, 1.0);
    out.world = position;
    out.scalar = scalar;
    out.normal = normal;
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

// The unit normal to light this pixel with, turned towards the viewer's side of the surface.
fn surface_normal(in: MeshOut, front: bool, to_eye: vec3<f32>) -> vec3<f32> {
    // Both derivatives lie in the triangle's plane, so their cross product is the face normal.
    let across = cross(dpdx(in.world), dpdy(in.world));
    var face = to_eye;
    if (dot(across, across) > 0.0) {
        face = normalize(across);
    }
    // Light the side that faces the camera, whichever way the triangle is wound.
    if (dot(face, to_eye) < 0.0) {
        face = -face;
    }
    // A vertex with no usable triangle has a zero normal: such pixels stay flat.
    let blended = in.normal;
    if (u.look.x < 0.5 || dot(blended, blended) < 1e-8) {
        return face;
    }
    var smooth_normal = normalize(blended);
    // Seen from behind (a hole's inside, an inverted patch), the normal turns with the face.
    if (!front) {
        smooth_normal = -smooth_normal;
    }
    // Where interpolation tips the normal away from the eye (the silhouette), bend it back to
    // the face's side so outlines do not go black.
    let behind = dot(smooth_normal, to_eye);
    if (behind < 0.0) {
        smooth_normal = normalize(smooth_normal - to_eye * (behind * 1.05));
    }
    return smooth_normal;
}

// A heat map's colours are lit with less contrast, so they read as the legend shows them, plus
// a little grey key light: the map's darkest colour is nearly black, and without it a mesh at
// distance 0 everywhere (before, against itself) would show as a flat silhouette.
fn heat_shape(key: f32) -> vec3<f32> {
    return vec3<f32>(0.10 * key);
}

// Key, fill and rim lights, sky/ground ambient and a soft key highlight.
fn studio(albedo: vec3<f32>, n: vec3<f32>, to_eye: vec3<f32>, heat: bool) -> vec3<f32> {
    let up = u.up.xyz;
    let key = max(dot(n, u.light_dir.xyz), 0.0);
    // Wrapped fill: soft, reaches a little past the terminator.
    let fill = max((dot(n, u.fill_dir.xyz) + 0.3) / 1.3, 0.0);
    let sky = 0.5 + 0.5 * dot(n, up);
    let ambient = mix(vec3<f32>(0.10, 0.09, 0.08), vec3<f32>(0.20, 0.22, 0.26), sky);
    let facing = max(dot(n, to_eye), 0.0);
    let rim = pow(1.0 - facing, 3.0) * (0.35 + 0.65 * sky);
    let half_way = normalize(u.light_dir.xyz + to_eye);
    let highlight = pow(max(dot(n, half_way), 0.0), 40.0) * key;
    var diffuse = ambient + vec3<f32>(1.0, 0.95, 0.88) * (0.78 * key)
        + vec3<f32>(0.55, 0.63, 0.78) * (0.32 * fill);
    var shape = vec3<f32>(0.0);
    if (heat) {
        diffuse = vec3<f32>(0.42) + 0.62 * diffuse;
        shape = heat_shape(key);
    }
    return albedo * diffuse + shape + vec3<f32>(0.20) * highlight + vec3<f32>(0.55, 0.62, 0.75) * (0.30 * rim);
}

// One key light above left of the viewer and light from the eye.
fn simple(albedo: vec3<f32>, n: vec3<f32>, to_eye: vec3<f32>, heat: bool) -> vec3<f32> {
    let key = max(dot(n, u.light_dir.xyz), 0.0);
    let fill = max(dot(n, to_eye), 0.0);
    if (heat) {
        let half_way = normalize(u.light_dir.xyz + to_eye);
        let highlight = pow(max(dot(n, half_way), 0.0), 24.0) * key;
        return albedo * (0.5 + 0.35 * key + 0.2 * fill) + heat_shape(key)
            + vec3<f32>(0.10) * highlight;
    }
    return albedo * (0.08 + 0.72 * key + 0.25 * fill);
}

@fragment
fn fs_mesh(in: MeshOut, @builtin(front_facing) front: bool) -> @location(0) vec4<f32> {
    let to_eye = normalize(u.eye.xyz - in.world);
    let normal = surface_normal(in, front, to_eye);
    // Sampled before any branch (implicit derivatives need every pixel of the quad); a mesh
    // with no material samples a white texel.
    let placed = vec3<f32>(in.uv, 1.0);
    let texel = textureSample(
        base_texture,
        base_sampler,
        vec2<f32>(dot(material.uv_u.xyz, placed), dot(material.uv_v.xyz, placed)),
    );
    var albedo = u.base_color.rgb;
    if (u.look.z > 0.5) {
        albedo = material.base_colour.rgb;
        let extras = u32(u.look.w + 0.5);
        if (material.flags.x > 0.5 && (extras & 2u) != 0u) {
            albedo = albedo * texel.rgb;
        }
        if ((extras & 1u) != 0u) {
            albedo = albedo * in.colour.rgb;
        }
    }
    let heat = u.scalar_range.z > 0.5;
    let mask = u.scalar_range.w > 0.5;
    // Derivatives before any branch (they need every pixel of the quad).
    let mask_step = fwidth(in.mask);
    if (heat) {
        let span = max(u.scalar_range.y - u.scalar_range.x, 1e-20);
        albedo = viridis((in.scalar - u.scalar_range.x) / span);
        if (mask) {
            // Over a heat map the painted region's edge (weight one half) is outlined in
            // orange, so the map's colours still read as its legend says.
            let across = abs(in.mask - 0.5) / max(mask_step, 1e-6);
            if (across < 1.0 && mask_step > 0.0) {
                albedo = vec3<f32>(0.95, 0.28, 0.06);
            }
        }
    } else if (mask) {
        // The painted region in a warm orange, as strong as its weight.
        albedo = mix(albedo, vec3<f32>(0.95, 0.28, 0.06), 0.5 * clamp(in.mask, 0.0, 1.0));
    }
    if (!front) {
        // Back faces (holes, inverted patches) in a cooler, darker tone.
        albedo = albedo * vec3<f32>(0.55, 0.6, 0.8);
    }
    if (u.look.y > 0.5) {
        return vec4<f32>(studio(albedo, normal, to_eye, heat), 1.0);
    }
    return vec4<f32>(simple(albedo, normal, to_eye, heat), 1.0);
}

@vertex
fn vs_line(@location(0) position: vec3<f32>) -> @builtin(position) vec4<f32> {
    return u.view_proj * vec4<f32>(position, 1.0);
}

@fragment
fn fs_line() -> @location(0) vec4<f32> {
    return u.wire_color;
}
