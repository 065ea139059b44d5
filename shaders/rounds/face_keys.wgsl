// Per input face: its corners' classes; a face with three distinct classes is kept, keyed by
// its lowest class for the radix sort (stable, so faces of one lowest class stay in input
// order, as the host's counting sort leaves them) and marks its classes used; any other face
// gets a key that sorts after every class, and is dropped.

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> in_indices: array<u32>;               // per input face × 3
@group(0) @binding(2) var<storage, read> weld_first: array<u32>;               // per input vertex
@group(0) @binding(3) var<storage, read> welded_id: array<u32>;                // per input vertex + 1, scanned
@group(0) @binding(4) var<storage, read> class_of: array<u32>;                 // per welded vertex
@group(0) @binding(5) var<storage, read_write> sort_keys: array<u32>;          // per input face
@group(0) @binding(6) var<storage, read_write> sort_vals: array<u32>;          // per input face
@group(0) @binding(7) var<storage, read_write> class_used: array<atomic<u32>>; // per class + 1
@group(0) @binding(8) var<storage, read_write> prep_counts: array<atomic<u32>>; // PrepCounts

@compute @workgroup_size(256)
fn face_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= prep.face_count) {
        return;
    }
    var c: vec3<u32>;
    for (var j = 0u; j < 3u; j = j + 1u) {
        c[j] = class_of[welded_id[weld_first[in_indices[3u * f + j]]]];
    }
    sort_vals[f] = f;
    if (c.x == c.y || c.y == c.z || c.x == c.z) {
        sort_keys[f] = PREP_PAD;
        return;
    }
    sort_keys[f] = min(c.x, min(c.y, c.z));
    // Every store writes 1 and the count only adds: the result is the same in any order.
    for (var j = 0u; j < 3u; j = j + 1u) {
        atomicStore(&class_used[c[j]], 1u);
    }
    atomicAdd(&prep_counts[0], 1u);
}
