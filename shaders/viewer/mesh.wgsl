// Draws the simplifier's own buffers: positions (vec4, normalized frame) as the vertex buffer,
// its u32 indices, and an optional per-vertex error for the heatmap. Flat normals come from
// screen-space derivatives, so no normal buffer is needed.

struct View {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // x: mode (0 shaded, 1 normals, 2 heatmap), y: error at the top of the colour ramp.
    mode: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) error: f32,
}

@vertex
fn vs_main(@location(0) position: vec4<f32>, @location(1) error: f32) -> VOut {
    var o: VOut;
    o.clip = view.view_proj * vec4<f32>(position.xyz, 1.0);
    o.world = position.xyz;
    o.error = error;
    return o;
}

// Blue (0) through green and yellow to red (1).
fn ramp(t: f32) -> vec3<f32> {
    let x = clamp(t, 0.0, 1.0);
    return clamp(vec3<f32>(1.5 - abs(4.0 * x - 3.0), 1.5 - abs(4.0 * x - 2.0), 1.5 - abs(4.0 * x - 1.0)), vec3<f32>(0.0), vec3<f32>(1.0));
}

@fragment
fn fs_main(v: VOut) -> @location(0) vec4<f32> {
    let n = normalize(cross(dpdx(v.world), dpdy(v.world)));
    let to_eye = normalize(view.eye.xyz - v.world);
    // Headlight: lit from the camera, both sides.
    let light = 0.25 + 0.75 * abs(dot(n, to_eye));
    let mode = u32(view.mode.x);
    if (mode == 1u) {
        return vec4<f32>(0.5 * n + vec3<f32>(0.5), 1.0);
    }
    if (mode == 2u) {
        return vec4<f32>(ramp(v.error / max(view.mode.y, 1e-12)) * light, 1.0);
    }
    return vec4<f32>(vec3<f32>(0.82, 0.78, 0.70) * light, 1.0);
}
