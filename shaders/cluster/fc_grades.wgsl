// Per vertex: Low & Tan's grade, cos(θ/2) for the widest angle θ between two of its edges times
// its longest edge (floating::grade), gathered over its faces in CSR order. Min and max do not
// depend on the order; each edge direction is recomputed per pair, the same value every time.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;         // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;         // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;    // per corner
@group(0) @binding(5) var<storage, read_write> fc_grade: array<f32>;  // per vertex

@compute @workgroup_size(256)
fn fc_grades(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let pv = positions[v].xyz;
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    var longest = 0.0;
    var least = 1.0;
    // Every (face slot, corner) other than v is a direction; pair it with every later one.
    for (var i = lo; i < hi; i = i + 1u) {
        let t = face_of(vertex_faces[i]);
        for (var a = 0u; a < 3u; a = a + 1u) {
            if (t[a] == v) {
                continue;
            }
            let e = positions[t[a]].xyz - pv;
            let l = sqrt(dot3(e, e));
            if (!(l > 0.0)) {
                continue;
            }
            longest = max(longest, l);
            let da = vec3<f32>(e.x / l, e.y / l, e.z / l);
            for (var j = i; j < hi; j = j + 1u) {
                let s = face_of(vertex_faces[j]);
                var b = 0u;
                if (j == i) {
                    b = a + 1u;
                }
                for (; b < 3u; b = b + 1u) {
                    if (s[b] == v) {
                        continue;
                    }
                    let e2 = positions[s[b]].xyz - pv;
                    let l2 = sqrt(dot3(e2, e2));
                    if (!(l2 > 0.0)) {
                        continue;
                    }
                    least = min(least, dot3(da, vec3<f32>(e2.x / l2, e2.y / l2, e2.z / l2)));
                }
            }
        }
    }
    // cos(θ/2) = sqrt((1 + cos θ) / 2).
    fc_grade[v] = sqrt((1.0 + clamp(least, -1.0, 1.0)) * 0.5) * longest;
}
