// Per vertex: its cluster (its centre's number, centres numbered in vertex order by the scan of
// the centre flags) and its id, the pairs the radix sort orders into each cluster's members in
// vertex order: a counting sort, so the gather after it sums in a fixed order. Relies on every
// vertex being claimed.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> fc_centre: array<u32>;       // per vertex
@group(0) @binding(2) var<storage, read> fc_head: array<u32>;         // per vertex + 1, scanned
@group(0) @binding(3) var<storage, read_write> sort_keys: array<u32>; // per vertex
@group(0) @binding(4) var<storage, read_write> sort_vals: array<u32>; // per vertex

@compute @workgroup_size(256)
fn fc_cluster_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= cluster.vertex_count) {
        return;
    }
    sort_keys[v] = fc_head[fc_centre[v]];
    sort_vals[v] = v;
}
