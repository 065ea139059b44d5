// First round, when the rounds carry appearance channels: over each face of a vertex, every
// channel is the linear function g·y + d through its three corners (g in the face's plane, y
// from the vertex); the face folds area·(g gᵀ, d g, d²) into the vertex's quadric (computed or
// carried in) and adds area·g, area·d and its area to the sums of the attribute vertex its
// corner on the vertex uses, so a seam vertex gets one set per side (Hoppe 1999, section 5).
// Each attribute vertex belongs to one vertex, whose invocation alone writes its sums: a
// gather in sorted face order, no float atomics.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;     // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;             // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;             // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;        // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>;  // per face
@group(0) @binding(6) var<storage, read> face_extra: array<FaceExtra>;    // per face
@group(0) @binding(7) var<storage, read> attr_values: array<f32>;         // per attribute vertex × m
@group(0) @binding(8) var<storage, read_write> quadrics: array<Quadric>;  // per vertex
@group(0) @binding(9) var<storage, read_write> attr_sums: array<f32>;     // per attribute vertex × (4m + 1)

@compute @workgroup_size(256)
fn vertex_attributes(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let m = attr_m();
    let stride = attr_stride();
    let pv = positions[v].xyz;
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    for (var i = lo; i < hi; i = i + 1u) {
        let o = corner_attr(vertex_faces[i], v) * stride;
        for (var k = 0u; k < stride; k = k + 1u) {
            attr_sums[o + k] = 0.0;
        }
    }
    var q = quadrics[v];
    for (var i = lo; i < hi; i = i + 1u) {
        let f = vertex_faces[i];
        let area = face_normals[f].w;
        if (!(area > 0.0)) { continue; }
        let t = face_of(f);
        let x = face_extra[f];
        let p0 = positions[t.x].xyz;
        let e1 = positions[t.y].xyz - p0;
        let e2 = positions[t.z].xyz - p0;
        let a = dot3(e1, e1);
        let b = dot3(e1, e2);
        let c = dot3(e2, e2);
        let det = a * c - b * b;
        if (!(det > 0.0)) { continue; }
        let r0 = p0 - pv;
        let o = corner_attr(f, v) * stride;
        for (var j = 0u; j < m; j = j + 1u) {
            let s0 = attr_values[x.attr0 * m + j];
            let d1 = attr_values[x.attr1 * m + j] - s0;
            let d2 = attr_values[x.attr2 * m + j] - s0;
            // g = α e1 + β e2 with g·e1 = d1 and g·e2 = d2 (the Gram system of the two edges).
            let alpha = (c * d1 - b * d2) / det;
            let beta = (a * d2 - b * d1) / det;
            let g = vec3<f32>(alpha * e1.x + beta * e2.x, alpha * e1.y + beta * e2.y, alpha * e1.z + beta * e2.z);
            let d = s0 - dot3(g, r0);
            q.q0 = q.q0 + vec4<f32>(area * g.x * g.x, area * g.x * g.y, area * g.x * g.z, area * g.y * g.y);
            q.q1 = q.q1 + vec4<f32>(area * g.y * g.z, area * g.z * g.z, area * d * g.x, area * d * g.y);
            q.q2 = q.q2 + vec4<f32>(area * d * g.z, area * d * d, 0.0, 0.0);
            attr_sums[o + 3u * j] = attr_sums[o + 3u * j] + area * g.x;
            attr_sums[o + 3u * j + 1u] = attr_sums[o + 3u * j + 1u] + area * g.y;
            attr_sums[o + 3u * j + 2u] = attr_sums[o + 3u * j + 2u] + area * g.z;
            attr_sums[o + 3u * m + j] = attr_sums[o + 3u * m + j] + area * d;
        }
        attr_sums[o + 4u * m] = attr_sums[o + 4u * m] + area;
    }
    quadrics[v] = q;
}
