// Per sorted slot: 1 where a cell starts (the first slot, a key unlike the one before, or a
// SINGLETON, one cell per locked vertex). Relies on sort_keys being sorted; the exclusive scan of
// these numbers the cells densely in key order.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> sort_keys: array<u32>;       // per vertex, sorted
@group(0) @binding(2) var<storage, read_write> cell_head: array<u32>; // per vertex + 1

@compute @workgroup_size(256)
fn cell_heads(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= cluster.vertex_count) {
        return;
    }
    let k = sort_keys[i];
    var head = 0u;
    if (i == 0u || k != sort_keys[i - 1u] || k == SINGLETON) {
        head = 1u;
    }
    cell_head[i] = head;
}
