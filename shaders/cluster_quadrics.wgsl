// Per cluster (a whole cell): gathers the area-weighted planes of its members' faces (members in
// sorted (key, id) order, each member's faces in CSR order) relative to the cell centre, then
// places its vertex as stages::place does: the least error of the regularised minimum clamped
// into the cell, the best member and the centroid, ties to the earlier; one member stays put.
// Relies on adjacency_sort having ordered each vertex's faces: the sums are in a fixed order.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;        // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;                // per face × 3
@group(0) @binding(3) var<storage, read> offsets: array<u32>;                // per vertex + 1
@group(0) @binding(4) var<storage, read> vertex_faces: array<u32>;           // per corner
@group(0) @binding(5) var<storage, read> face_normals: array<vec4<f32>>;     // per face
@group(0) @binding(6) var<storage, read> sort_vals: array<u32>;              // per vertex, sorted
@group(0) @binding(7) var<storage, read> cell_head: array<u32>;              // per vertex + 1
@group(0) @binding(8) var<storage, read> cell_start: array<u32>;             // per cell + 1
@group(0) @binding(9) var<storage, read> cell_key: array<u32>;               // per cell
@group(0) @binding(10) var<storage, read_write> cluster_placed: array<ClusterPlaced>; // per cell
@group(0) @binding(11) var<storage, read_write> cluster_quadric: array<Quadric>;     // per cell

const REGULARISE: f32 = 1e-3;

fn compact3(k0: u32) -> u32 {
    var x = k0 & 0x09249249u;
    x = (x | (x >> 2u)) & 0x030c30c3u;
    x = (x | (x >> 4u)) & 0x0300f00fu;
    x = (x | (x >> 8u)) & 0x030000ffu;
    return (x | (x >> 16u)) & 0x3ffu;
}

fn pos_of(v: u32) -> vec3<f32> {
    return positions[v].xyz;
}

// (A + eps I) y = eps c - b, eps = REGULARISE × trace(A) / 3 (twin of regularised_minimum).
fn regularised_minimum(q: Quadric, c: vec3<f32>) -> Optimum {
    let a01 = q.q0.y; let a02 = q.q0.z; let a12 = q.q1.x;
    let tr = q.q0.x + q.q0.w + q.q1.y;
    if (!(tr > 0.0) || !is_finite(tr)) {
        return Optimum(false, vec3<f32>(0.0));
    }
    let eps = REGULARISE * tr / 3.0;
    let a00 = q.q0.x + eps; let a11 = q.q0.w + eps; let a22 = q.q1.y + eps;
    let r = vec3<f32>(eps * c.x - q.q1.z, eps * c.y - q.q1.w, eps * c.z - q.q2.x);
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    if (!(det > 0.0) || !is_finite(det)) {
        return Optimum(false, vec3<f32>(0.0));
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let inv = 1.0 / det;
    let y = vec3<f32>(
        (c00 * r.x + c01 * r.y + c02 * r.z) * inv,
        (c01 * r.x + c11 * r.y + c12 * r.z) * inv,
        (c02 * r.x + c12 * r.y + c22 * r.z) * inv,
    );
    if (!is_finite(y.x) || !is_finite(y.y) || !is_finite(y.z)) {
        return Optimum(false, vec3<f32>(0.0));
    }
    return Optimum(true, y);
}

@compute @workgroup_size(256)
fn cluster_quadrics(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * WG;
    if (k >= cell_head[cluster.vertex_count]) {
        return;
    }
    let first = cell_start[k];
    let last = cell_start[k + 1u];
    var o = pos_of(sort_vals[first]);
    var lo = o;
    var hi = o;
    // A lone member is its own origin and box (cluster_quadric's rule); a shared cell's origin
    // is its centre (Grid::cell_box).
    if (last - first > 1u) {
        let key = cell_key[k];
        let c = vec3<f32>(vec3<u32>(compact3(key), compact3(key >> 1u), compact3(key >> 2u)));
        let h = cluster.lo_h.w;
        lo = vec3<f32>(cluster.lo_h.x + c.x * h, cluster.lo_h.y + c.y * h, cluster.lo_h.z + c.z * h);
        hi = vec3<f32>(lo.x + h, lo.y + h, lo.z + h);
        o = 0.5 * (lo + hi);
    }
    var q = Quadric(vec4<f32>(0.0), vec4<f32>(0.0), vec4<f32>(0.0));
    for (var i = first; i < last; i = i + 1u) {
        let m = sort_vals[i];
        for (var j = offsets[m]; j < offsets[m + 1u]; j = j + 1u) {
            let f = vertex_faces[j];
            let pl = face_normals[f];
            if (pl.w <= 0.0) {
                continue;
            }
            let d = dot(pl.xyz, o - pos_of(indices[3u * f]));
            q = quadric_add(q, quadric_from_plane(pl.xyz, d, pl.w));
        }
    }
    if (last - first == 1u) {
        let m = sort_vals[first];
        cluster_placed[k] = ClusterPlaced(vec4<f32>(pos_of(m), 0.0), m, PLACE_SINGLE, 0u, 0u);
        cluster_quadric[k] = quadric_shift(q, pos_of(m) - o);
        return;
    }
    var centroid = vec3<f32>(0.0);
    for (var i = first; i < last; i = i + 1u) {
        centroid = centroid + (pos_of(sort_vals[i]) - o);
    }
    centroid = centroid * (1.0 / f32(last - first));
    var best_e = quadric_eval(q, centroid);
    var best_y = centroid;
    var how = PLACE_CENTROID;
    var member_e = 0.0;
    var member_y = centroid;
    for (var i = first; i < last; i = i + 1u) {
        let y = pos_of(sort_vals[i]) - o;
        let e = quadric_eval(q, y);
        if (i == first || e < member_e) {
            member_e = e;
            member_y = y;
        }
    }
    if (member_e < best_e) {
        best_e = member_e;
        best_y = member_y;
        how = PLACE_MEMBER;
    }
    let opt = regularised_minimum(q, centroid);
    if (opt.ok) {
        let y = clamp(opt.y, lo - o, hi - o);
        let e = quadric_eval(q, y);
        if (e <= best_e) {
            best_e = e;
            best_y = y;
            how = PLACE_SOLVE;
        }
    }
    var attr = sort_vals[first];
    var attr_d = 0.0;
    for (var i = first; i < last; i = i + 1u) {
        let d = (pos_of(sort_vals[i]) - o) - best_y;
        let dd = dot(d, d);
        if (i == first || dd < attr_d) {
            attr_d = dd;
            attr = sort_vals[i];
        }
    }
    cluster_placed[k] = ClusterPlaced(vec4<f32>(o + best_y, 0.0), attr, how, 0u, 0u);
    cluster_quadric[k] = quadric_shift(q, best_y);
}
