// Per input vertex: the lowest vertex at its position (its slot's, now that every insert is
// done), and 1 where that is the vertex itself, which the prefix sum after turns into the
// welded vertices' numbers in the order of their first vertex, as the host's weld numbers them.

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> weld_table: array<u32>;           // per slot
@group(0) @binding(2) var<storage, read> weld_slot: array<u32>;            // per input vertex
@group(0) @binding(3) var<storage, read_write> weld_first: array<u32>;     // per input vertex
@group(0) @binding(4) var<storage, read_write> welded_id: array<u32>;      // per input vertex + 1

@compute @workgroup_size(256)
fn weld_resolve(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= prep.vertex_count) {
        return;
    }
    let first = weld_table[weld_slot[v]] - 1u;
    weld_first[v] = first;
    welded_id[v] = u32(first == v);
}
