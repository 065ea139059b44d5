// Each vertex gathers the area-weighted plane quadrics of its faces and Hoppe's constraint plane
// of each border edge at it, relative to its own position (first round). A gather in sorted face
// order, not float atomics, so the sums never depend on thread timing.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;    // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;            // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;            // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;       // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>; // per face
@group(0) @binding(6) var<storage, read_write> quadrics: array<Quadric>; // per vertex

@compute @workgroup_size(256)
fn vertex_quadrics(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let pv = positions[v].xyz;
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    var q = Quadric(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var i = lo; i < hi; i = i + 1u) {
        let f = vertex_faces[i];
        let fnrm = face_normals[f];
        let t = face_of(f);
        if (fnrm.w > 0.0) {
            let d = dot(fnrm.xyz, pv - positions[t.x].xyz);
            q = quadric_add(q, quadric_from_plane(fnrm.xyz, d, fnrm.w));
        }
        if (params.border_weight > 0.0) {
            for (var k = 0u; k < 3u; k = k + 1u) {
                let u = t[k];
                if (u != v && count_containing(lo, hi, u) == 1u) {
                    let e = positions[u].xyz - pv;
                    let c = cross(e, fnrm.xyz);
                    let l = length(c);
                    if (l > 0.0) {
                        let w = params.border_weight * dot(e, e);
                        q = quadric_add(q, quadric_from_plane(c * (1.0 / l), 0.0, w));
                    }
                }
            }
        }
    }
    quadrics[v] = q;
}
