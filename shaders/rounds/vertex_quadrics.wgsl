// Each vertex gathers the area-weighted plane quadrics of its faces and Hoppe's constraint plane
// of each border edge at it, and of each attribute-seam edge (its two faces use different
// attribute vertices at an end; the plane is perpendicular to their mean normal, as the greedy
// reference's, so a sliding seam keeps its course), relative to its own position (first round).
// A gather in sorted face order, not float atomics, so the sums never depend on thread timing.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;    // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;            // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;            // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;       // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>; // per face
@group(0) @binding(6) var<storage, read> face_extra: array<FaceExtra>;   // per face
@group(0) @binding(7) var<storage, read_write> quadrics: array<Quadric>; // per vertex

// The faces of the list range [lo, hi) containing u: how many, and the first other than f (f
// when none). One scan for both: counting and then looking for the other face took two, and
// this stage was 1.08 s of lavapipe time on the 1M scan (0.70 s with one).
fn edge_faces(lo: u32, hi: u32, f: u32, u: u32) -> vec2<u32> {
    var n = 0u;
    var other = f;
    for (var i = lo; i < hi; i = i + 1u) {
        let g = vertex_faces[i];
        if (has(face_of(g), u)) {
            n = n + 1u;
            if (other == f && g != f) { other = g; }
        }
    }
    return vec2<u32>(n, other);
}

// The constraint plane through edge e (from the vertex) perpendicular to `surface`, weighted by
// the border weight and the squared edge length; zero when degenerate.
fn edge_plane(e: vec3<f32>, surface: vec3<f32>) -> Quadric {
    let c = cross(e, surface);
    let l = length(c);
    if (l > 0.0) {
        return quadric_from_plane(c * (1.0 / l), 0.0, params.border_weight * dot(e, e));
    }
    return Quadric(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
}

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
                if (u == v) { continue; }
                let e = positions[u].xyz - pv;
                let faces = edge_faces(lo, hi, f, u);
                let n = faces.x;
                if (n == 1u) {
                    q = quadric_add(q, edge_plane(e, fnrm.xyz));
                } else if (n == 2u) {
                    // Once per edge: from the first of its two faces in the (sorted) list. In
                    // the first round every corner still has its input attribute vertex.
                    let g = faces.y;
                    if (g > f && (corner_attr(f, v) != corner_attr(g, v)
                        || corner_attr(f, u) != corner_attr(g, u))) {
                        let avg = fnrm.xyz + face_normals[g].xyz;
                        q = quadric_add(q, edge_plane(e, avg));
                    }
                }
            }
        }
    }
    quadrics[v] = q;
}
