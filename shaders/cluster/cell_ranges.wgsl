// Per sorted slot: where each cell starts (cell_start, one more entry, the end), its key, and each
// vertex's cell. Relies on cell_head holding the exclusive scan of the heads (total at [n]), so a
// slot's head is cell_head[i + 1] - cell_head[i].

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> cell_head: array<u32>;         // per vertex + 1, scanned
@group(0) @binding(2) var<storage, read> sort_keys: array<u32>;         // per vertex, sorted
@group(0) @binding(3) var<storage, read> sort_vals: array<u32>;         // per vertex, sorted
@group(0) @binding(4) var<storage, read_write> cell_start: array<u32>;  // per cell + 1
@group(0) @binding(5) var<storage, read_write> vertex_cell: array<u32>; // per vertex
@group(0) @binding(6) var<storage, read_write> cell_key: array<u32>;    // per cell

@compute @workgroup_size(256)
fn cell_ranges(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    let n = cluster.vertex_count;
    if (i >= n) {
        return;
    }
    let before = cell_head[i];
    let head = cell_head[i + 1u] - before;
    if (head == 1u) {
        cell_start[before] = i;
        cell_key[before] = sort_keys[i];
    }
    vertex_cell[sort_vals[i]] = before + head - 1u;
    if (i == n - 1u) {
        cell_start[cell_head[n]] = n;
    }
}
