// Surviving vertices move to their scanned slot with their quadric, flags and attribute vertex.
// Relies on vertex_keep being the exclusive scan of 0/1 keep flags (distinct slots).

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> vertex_keep: array<u32>;              // per vertex + 1
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;          // per vertex
@group(0) @binding(3) var<storage, read> quadrics: array<Quadric>;             // per vertex
@group(0) @binding(4) var<storage, read> flags: array<u32>;                    // per vertex
@group(0) @binding(5) var<storage, read> vertex_attr: array<u32>;              // per vertex
@group(0) @binding(6) var<storage, read_write> positions_out: array<vec4<f32>>;
@group(0) @binding(7) var<storage, read_write> quadrics_out: array<Quadric>;
@group(0) @binding(8) var<storage, read_write> flags_out: array<u32>;
@group(0) @binding(9) var<storage, read_write> vertex_attr_out: array<u32>;

@compute @workgroup_size(256)
fn compact_vertices(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count || vertex_keep[v + 1u] == vertex_keep[v]) {
        return;
    }
    let n = vertex_keep[v];
    positions_out[n] = positions[v];
    quadrics_out[n] = quadrics[v];
    flags_out[n] = flags[v];
    vertex_attr_out[n] = vertex_attr[v];
}
