// Per kept face, in the sorted order: its corners as the dense numbers of their classes (the
// rounds' indices) and its extras: each corner's first input vertex at its position and the
// input face it is. The host's upload names welded vertices there; the first input vertex of
// each is the same choice numbered in the input, which the output is built from.

@group(0) @binding(0) var<storage, read> in_indices: array<u32>;           // per input face × 3
@group(0) @binding(1) var<storage, read> weld_first: array<u32>;           // per input vertex
@group(0) @binding(2) var<storage, read> welded_id: array<u32>;            // per input vertex + 1, scanned
@group(0) @binding(3) var<storage, read> class_of: array<u32>;             // per welded vertex
@group(0) @binding(4) var<storage, read> class_used: array<u32>;           // per class + 1, scanned
@group(0) @binding(5) var<storage, read> sort_vals: array<u32>;            // per input face, sorted
@group(0) @binding(6) var<storage, read> prep_counts: array<u32>;          // PrepCounts
@group(0) @binding(7) var<storage, read_write> indices: array<u32>;        // per kept face × 3
@group(0) @binding(8) var<storage, read_write> face_extra: array<FaceExtra>; // per kept face

@compute @workgroup_size(256)
fn prep_faces(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let i = gid.x + gid.y * nwg.x * WG;
    if (i >= prep_counts[0]) {
        return;
    }
    let f = sort_vals[i];
    var a: vec3<u32>;
    for (var j = 0u; j < 3u; j = j + 1u) {
        a[j] = weld_first[in_indices[3u * f + j]];
        indices[3u * i + j] = class_used[class_of[welded_id[a[j]]]];
    }
    face_extra[i] = FaceExtra(a.x, a.y, a.z, f);
}
