// A cluster's quadric gathered from its members' faces, and its vertex placed; prepended (after
// common.wgsl, cluster.wgsl and mesh.wgsl) to the stages that bind cluster_placed
// (cluster_quadrics, fc_quadrics), which bind every buffer read here. Twin of
// cluster::stages::{cluster_quadric, place}: keep in sync.

const REGULARISE: f32 = 1e-3;

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

// The area-weighted planes of the faces of members sort_vals[first..last] (each member's faces
// in CSR order, which adjacency_sort fixed), relative to o: the sums in a fixed order.
fn gather_members(first: u32, last: u32, o: vec3<f32>) -> Quadric {
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
    return q;
}

struct Placement {
    placed: ClusterPlaced,
    quadric: Quadric,
}

// stages::place: a lone member stays put; otherwise the least error of the regularised minimum
// clamped into [lo, hi], the best member and the centroid, ties to the earlier; the attributes
// of the member nearest the vertex. q is relative to o; the quadric returned to the vertex.
fn place_members(q: Quadric, first: u32, last: u32, o: vec3<f32>, lo: vec3<f32>, hi: vec3<f32>) -> Placement {
    if (last - first == 1u) {
        let m = sort_vals[first];
        return Placement(ClusterPlaced(vec4<f32>(pos_of(m), 0.0), m, PLACE_SINGLE, 0u, 0u),
                         quadric_shift(q, pos_of(m) - o));
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
    return Placement(ClusterPlaced(vec4<f32>(o + best_y, 0.0), attr, how, 0u, 0u),
                     quadric_shift(q, best_y));
}
