// Per slot of the rank order: the vertex's cell in the hash grid (cells 2·r_max wide) and its id,
// the pairs the radix sort orders. Relies on fc_order holding the vertices by rank, highest
// first: the sort is stable, so each cell's members come out by rank, as fc_decide's early stop
// needs. Locked vertices are keyed like the others: they are claimed from the start.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(2) var<storage, read> fc_order: array<u32>;        // per vertex, by rank
@group(0) @binding(3) var<storage, read_write> sort_keys: array<u32>; // per vertex
@group(0) @binding(4) var<storage, read_write> sort_vals: array<u32>; // per vertex

@compute @workgroup_size(256)
fn fc_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= cluster.vertex_count) {
        return;
    }
    let v = fc_order[i];
    sort_keys[i] = morton3(cell_coords(cluster, positions[v].xyz));
    sort_vals[i] = v;
}
