// Per vertex: the Morton key of its grid cell (SINGLETON when locked) and its id, the pairs the
// radix sort orders. Relies on the same f32 arithmetic as Grid::key (subtract, multiply by the
// inverse cell size, truncate): correctly rounded in Vulkan, so every device finds the same cell.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>; // per vertex
@group(0) @binding(2) var<storage, read> locked: array<u32>;          // per vertex
@group(0) @binding(3) var<storage, read_write> sort_keys: array<u32>; // per vertex
@group(0) @binding(4) var<storage, read_write> sort_vals: array<u32>; // per vertex

// The low 10 bits of x spread to every third bit (twin of mesh::morton::morton3's part).
fn spread3(x0: u32) -> u32 {
    var x = x0 & 0x3ffu;
    x = (x | (x << 16u)) & 0x030000ffu;
    x = (x | (x << 8u)) & 0x0300f00fu;
    x = (x | (x << 4u)) & 0x030c30c3u;
    return (x | (x << 2u)) & 0x09249249u;
}

@compute @workgroup_size(256)
fn cell_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= cluster.vertex_count) {
        return;
    }
    var key = SINGLETON;
    if (locked[v] == 0u) {
        let q = max((positions[v].xyz - cluster.lo_h.xyz) * cluster.inv_h, vec3<f32>(0.0));
        let c = min(vec3<u32>(q), cluster.dims.xyz - vec3<u32>(1u));
        key = spread3(c.x) | (spread3(c.y) << 1u) | (spread3(c.z) << 2u);
    }
    sort_keys[v] = key;
    sort_vals[v] = v;
}
