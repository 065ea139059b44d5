// Draws the simplifier's own buffers: positions (vec4, normalized frame) as the first vertex
// buffer and its u32 indices, plus per-vertex extras the viewer keeps beside them (distance to
// the original surface for the heatmap, a smooth normal, a texture coordinate). Flat normals come
// from screen-space derivatives, so the flat modes need none of the extras.
// Relies on: every extra buffer holds one entry per vertex of the GpuMesh drawn with it
// (SceneMesh sizes them so), as the indirect draw may index any vertex the rounds kept.

// One per drawn instance (dynamic uniform offset). Keep in sync with `ViewUniform` in
// src/viewer/render.rs.
struct View {
    // Clip from the mesh's own (normalized) frame: instance placement included.
    view_proj: mat4x4<f32>,
    // The camera in the mesh's frame, for the headlight.
    eye: vec4<f32>,
    // x: mode (0 shaded, 1 normals, 2 heatmap, 3 texture), y: error at the top of the colour
    // ramp, z: 1 for smooth shading, w: unused.
    mode: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(0) var albedo: texture_2d<f32>;
@group(1) @binding(1) var albedo_sampler: sampler;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) error: f32,
    @location(2) normal: vec3<f32>,
    @location(3) uv: vec2<f32>,
}

@vertex
fn vs_main(
    @location(0) position: vec4<f32>,
    @location(1) error: f32,
    @location(2) normal: vec3<f32>,
    @location(3) uv: vec2<f32>,
) -> VOut {
    var o: VOut;
    o.clip = view.view_proj * vec4<f32>(position.xyz, 1.0);
    o.local = position.xyz;
    o.error = error;
    o.normal = normal;
    o.uv = uv;
    return o;
}

// Blue (0) through green and yellow to red (1); the legend in src/viewer/app.rs draws the same.
fn ramp(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    return clamp(vec3<f32>(1.5 - abs(4.0 * x - 3.0), 1.5 - abs(4.0 * x - 2.0), 1.5 - abs(4.0 * x - 1.0)), vec3<f32>(0.0), vec3<f32>(1.0));
}

@fragment
fn fs_main(v: VOut) -> @location(0) vec4<f32> {
    var n = normalize(cross(dpdx(v.local), dpdy(v.local)));
    if (view.mode.z > 0.5 && dot(v.normal, v.normal) > 1e-12) {
        n = normalize(v.normal);
    }
    let to_eye = normalize(view.eye.xyz - v.local);
    // Headlight: lit from the camera, both sides.
    let light = 0.25 + 0.75 * abs(dot(n, to_eye));
    let mode = u32(view.mode.x);
    if (mode == 1u) {
        return vec4<f32>(0.5 * n + vec3<f32>(0.5), 1.0);
    }
    if (mode == 2u) {
        return vec4<f32>(ramp(v.error / max(view.mode.y, 1e-12)) * light, 1.0);
    }
    if (mode == 3u) {
        // OBJ texture coordinates start at the bottom row.
        let t = textureSample(albedo, albedo_sampler, vec2<f32>(v.uv.x, 1.0 - v.uv.y));
        return vec4<f32>(t.rgb * light, 1.0);
    }
    return vec4<f32>(vec3<f32>(0.82, 0.78, 0.70) * light, 1.0);
}

// The wireframe overlay: the same triangles drawn as lines over the surface.
@fragment
fn fs_wire(v: VOut) -> @location(0) vec4<f32> {
    return vec4<f32>(0.08, 0.09, 0.11, 1.0);
}
