// Per kept face: its id into the bucket of its first cluster. The order within a bucket depends
// on thread timing; cluster_faces_dedupe sorts it. Relies on bucket_cursor being cleared.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> face_key: array<u32>;                    // per face × 3
@group(0) @binding(2) var<storage, read> face_keep: array<u32>;                   // per face + 1
@group(0) @binding(3) var<storage, read> bucket_offsets: array<u32>;              // per vertex + 1
@group(0) @binding(4) var<storage, read_write> bucket_cursor: array<atomic<u32>>; // per vertex
@group(0) @binding(5) var<storage, read_write> bucket_faces: array<u32>;          // per kept face

@compute @workgroup_size(256)
fn cluster_faces_fill(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= cluster.face_count || face_keep[f] == 0u) {
        return;
    }
    let a = face_key[3u * f];
    bucket_faces[bucket_offsets[a] + atomicAdd(&bucket_cursor[a], 1u)] = f;
}
