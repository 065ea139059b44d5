// Per vertex: the Morton key of its grid cell (SINGLETON when locked) and its id, the pairs the
// radix sort orders. Relies on the same f32 arithmetic as Grid::key (subtract, multiply by the
// inverse cell size, truncate): correctly rounded in Vulkan, so every device finds the same cell.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(2) var<storage, read> locked: array<u32>;          // per vertex
@group(0) @binding(3) var<storage, read_write> sort_keys: array<u32>; // per vertex
@group(0) @binding(4) var<storage, read_write> sort_vals: array<u32>; // per vertex

@compute @workgroup_size(256)
fn cell_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= cluster.vertex_count) {
        return;
    }
    var key = SINGLETON;
    if (locked[v] == 0u) {
        key = morton3(cell_coords(cluster, positions[v].xyz));
    }
    sort_keys[v] = key;
    sort_vals[v] = v;
}
