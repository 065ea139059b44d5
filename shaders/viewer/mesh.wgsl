// Draws the simplifier's own buffers: its u32 indices and positions (vec4, normalized frame),
// read by the vertex shader (vertex pulling: the draw runs one invocation per corner, so a seam
// vertex can show each side's texture coordinate), plus extras the viewer keeps beside them:
// per vertex the distance to the original surface (heatmap) and a smooth normal, per corner a
// texture coordinate and a vertex colour. Flat normals come from screen-space derivatives, so the flat modes need
// none of the extras; the triangle-quality mode reads each face's three corners in the vertex
// shader (corner / 3 is the face), so it needs none either.
// Relies on: the per-vertex extras hold one entry per vertex of the GpuMesh drawn with them and
// the UVs and colours one per corner (SceneMesh sizes them so), as the indirect draw may reach any corner
// and vertex the rounds kept.

// One per drawn instance (dynamic uniform offset). Keep in sync with `ViewUniform` in
// src/viewer/render.rs.
struct View {
    // Clip from the mesh's own (normalized) frame: instance placement included.
    view_proj: mat4x4<f32>,
    // The camera in the mesh's frame, for the headlight.
    eye: vec4<f32>,
    // x: mode (0 shaded, 1 normals, 2 heatmap, 3 texture, 4 quality, 5 vertex colour, 6 DAG
    // clusters, 7 DAG levels), y: error at the top of the colour ramp, z: 1 for smooth shading,
    // w: the DAG's deepest level (for 7).
    mode: vec4<f32>,
}

@group(0) @binding(0) var<uniform> view: View;
@group(1) @binding(0) var albedo: texture_2d<f32>;
@group(1) @binding(1) var albedo_sampler: sampler;
@group(2) @binding(0) var<storage, read> indices: array<u32>;         // per corner
@group(2) @binding(1) var<storage, read> positions: array<vec4<f32>>; // per vertex
@group(2) @binding(2) var<storage, read> errors: array<f32>;          // per vertex
@group(2) @binding(3) var<storage, read> normals: array<f32>;         // per vertex × 3
@group(2) @binding(4) var<storage, read> uvs: array<vec2<f32>>;       // per corner
@group(2) @binding(5) var<storage, read> colors: array<u32>;          // per corner, RGBA8

struct VOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) local: vec3<f32>,
    @location(1) error: f32,
    @location(2) normal: vec3<f32>,
    @location(3) uv: vec2<f32>,
    // The face's smallest angle in degrees, the same at its three corners.
    @location(4) @interpolate(flat) min_angle: f32,
    @location(5) color: vec4<f32>,
    // A DAG's cluster as the cut numbered its draw's instance: its level in the top 8 bits,
    // its number below (0 for a mesh).
    @location(6) @interpolate(flat) cluster: u32,
}

// The smallest angle (degrees) of the triangle (a, b, c); 0 for a degenerate one. The frame
// is the mesh's scaled uniformly, so its angles are the mesh's.
fn smallest_angle(a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> f32 {
    let ab = b - a;
    let bc = c - b;
    let ca = a - c;
    let la = length(ab);
    let lb = length(bc);
    let lc = length(ca);
    if (la * lb * lc <= 0.0) {
        return 0.0;
    }
    // The angle at each corner, between its two edges leaving it.
    let at_a = acos(clamp(dot(ab, -ca) / (la * lc), -1.0, 1.0));
    let at_b = acos(clamp(dot(bc, -ab) / (lb * la), -1.0, 1.0));
    let at_c = 3.14159265 - at_a - at_b;
    return degrees(min(at_a, min(at_b, at_c)));
}

@vertex
fn vs_main(@builtin(vertex_index) corner: u32, @builtin(instance_index) cluster: u32) -> VOut {
    let v = indices[corner];
    let position = positions[v];
    var o: VOut;
    o.clip = view.view_proj * vec4<f32>(position.xyz, 1.0);
    o.local = position.xyz;
    o.error = errors[v];
    o.normal = vec3<f32>(normals[3u * v], normals[3u * v + 1u], normals[3u * v + 2u]);
    o.uv = uvs[corner];
    o.color = unpack4x8unorm(colors[corner]);
    o.cluster = cluster;
    let first = corner - corner % 3u;
    o.min_angle = smallest_angle(
        positions[indices[first]].xyz,
        positions[indices[first + 1u]].xyz,
        positions[indices[first + 2u]].xyz,
    );
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
    if (mode == 4u) {
        // Red for a sliver, blue for an equilateral face (its smallest angle is 60).
        return vec4<f32>(ramp(1.0 - v.min_angle / 60.0) * light, 1.0);
    }
    if (mode == 5u) {
        return vec4<f32>(v.color.rgb * light, 1.0);
    }
    if (mode == 6u) {
        // A hash of the cluster's number as a hue: neighbours get unrelated colours.
        var h = v.cluster & 0xffffffu;
        h = (h ^ (h >> 16u)) * 0x7feb352du;
        h = (h ^ (h >> 15u)) * 0x846ca68bu;
        h = h ^ (h >> 16u);
        let c = vec3<f32>(f32(h & 255u), f32((h >> 8u) & 255u), f32((h >> 16u) & 255u)) / 255.0;
        return vec4<f32>((0.3 + 0.7 * c) * light, 1.0);
    }
    if (mode == 7u) {
        let level = f32(v.cluster >> 24u);
        return vec4<f32>(ramp(level / max(view.mode.w, 1.0)) * light, 1.0);
    }
    return vec4<f32>(vec3<f32>(0.82, 0.78, 0.70) * light, 1.0);
}

// The wireframe overlay: the same triangles drawn as lines over the surface.
@fragment
fn fs_wire(v: VOut) -> @location(0) vec4<f32> {
    return vec4<f32>(0.08, 0.09, 0.11, 1.0);
}
