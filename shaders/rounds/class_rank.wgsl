// Per slot of the sorted Morton keys: the welded vertex there is position class `i` (the
// classes in (code, welded vertex) order, as the host's `mesh::morton::spatial_order`).

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> welded_id: array<u32>;            // per input vertex + 1, scanned
@group(0) @binding(2) var<storage, read> sort_vals: array<u32>;            // per input vertex, sorted
@group(0) @binding(3) var<storage, read_write> class_of: array<u32>;       // per welded vertex
@group(0) @binding(4) var<storage, read_write> class_welded: array<u32>;   // per class

@compute @workgroup_size(256)
fn class_rank(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= welded_id[prep.vertex_count]) {
        return;
    }
    let w = sort_vals[i];
    class_of[w] = i;
    class_welded[i] = w;
}
