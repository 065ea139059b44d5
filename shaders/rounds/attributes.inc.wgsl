// The appearance channels the rounds carry: Hoppe's memory-efficient attribute quadric (H. Hoppe,
// New quadric metric for simplifying meshes with appearance attributes, IEEE Visualization
// 1999), as src/quadric/attributes.rs gives the greedy reference, in f32. Per attribute vertex
// of the welded input: its m weighted values (attr_values) and its sums (attr_sums, stride
// 4m + 1: G per channel (3 each), then D per channel, then W), relative to its vertex's
// position like the quadrics; each face's p-only part is folded into the vertex quadric. Twin of
// src/rounds/cpu/attributes.rs; prepended to the stages that bind attr_values and attr_sums.

// Params.attributes: m in bits 0-3, the colour channels (the first) in bits 4-7, bit 8 when two
// UV channels follow them (src/compute/types.rs's attr_layout).
fn attr_m() -> u32 { return params.attributes & 0xfu; }
fn attr_colors() -> u32 { return (params.attributes >> 4u) & 0xfu; }
fn attr_has_uv() -> bool { return ((params.attributes >> 8u) & 1u) != 0u; }
fn attr_stride() -> u32 { return 4u * attr_m() + 1u; }

// Channel j's G of attribute vertex x.
fn attr_g(x: u32, j: u32) -> vec3<f32> {
    let o = x * attr_stride() + 3u * j;
    return vec3<f32>(attr_sums[o], attr_sums[o + 1u], attr_sums[o + 2u]);
}

// Channel j's D of attribute vertex x, measured from its vertex's position moved by t.
fn attr_d(x: u32, j: u32, t: vec3<f32>) -> f32 {
    return attr_sums[x * attr_stride() + 3u * attr_m() + j] + dot3(attr_g(x, j), t);
}

fn attr_w(x: u32) -> f32 {
    return attr_sums[x * attr_stride() + 4u * attr_m()];
}

// q less what the best values take away for the group of attribute vertices a and b (their
// sums measured from their vertices moved by ta and tb): the error once every channel takes
// (G·y + D) / W. A group without area takes nothing away.
fn attr_reduce_pair(q: Quadric, a: u32, ta: vec3<f32>, b: u32, tb: vec3<f32>) -> Quadric {
    let w = attr_w(a) + attr_w(b);
    if (!(w > 0.0)) { return q; }
    let inv = 1.0 / w;
    var r = q;
    for (var j = 0u; j < attr_m(); j = j + 1u) {
        let g = attr_g(a, j) + attr_g(b, j);
        let d = attr_d(a, j, ta) + attr_d(b, j, tb);
        r.q0 = r.q0 - vec4<f32>(g.x * g.x * inv, g.x * g.y * inv, g.x * g.z * inv, g.y * g.y * inv);
        r.q1 = r.q1 - vec4<f32>(g.y * g.z * inv, g.z * g.z * inv, d * g.x * inv, d * g.y * inv);
        r.q2 = r.q2 - vec4<f32>(d * g.z * inv, d * d * inv, 0.0, 0.0);
    }
    return r;
}

// q with attribute vertex x's sums (measured from its vertex moved by t) held at attribute
// vertex v's values: the error of a survivor that keeps its values.
fn attr_hold(q: Quadric, x: u32, t: vec3<f32>, v: u32) -> Quadric {
    let m = attr_m();
    let w = attr_w(x);
    var r = q;
    for (var j = 0u; j < m; j = j + 1u) {
        let s = attr_values[v * m + j];
        let g = attr_g(x, j);
        r.q1 = vec4<f32>(r.q1.x, r.q1.y, r.q1.z - s * g.x, r.q1.w - s * g.y);
        r.q2 = vec4<f32>(r.q2.x - s * g.z, r.q2.y + (w * s * s - 2.0 * s * attr_d(x, j, t)), r.q2.z, r.q2.w);
    }
    return r;
}
