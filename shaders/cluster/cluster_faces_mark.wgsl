// Per face: its corners' clusters rotated so the lowest comes first (winding kept), kept when the
// three differ, and counted in the bucket of its first cluster. Integer atomics only count.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> indices: array<u32>;                      // per face × 3
@group(0) @binding(2) var<storage, read> vertex_cell: array<u32>;                  // per vertex
@group(0) @binding(3) var<storage, read_write> face_key: array<u32>;               // per face × 3
@group(0) @binding(4) var<storage, read_write> face_keep: array<u32>;              // per face + 1
@group(0) @binding(5) var<storage, read_write> bucket_counts: array<atomic<u32>>;  // per vertex + 1

@compute @workgroup_size(256)
fn cluster_faces_mark(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= cluster.face_count) {
        return;
    }
    let a = vertex_cell[indices[3u * f]];
    let b = vertex_cell[indices[3u * f + 1u]];
    let c = vertex_cell[indices[3u * f + 2u]];
    var r = vec3<u32>(c, a, b);
    if (a < b && a < c) {
        r = vec3<u32>(a, b, c);
    } else if (b < c) {
        r = vec3<u32>(b, c, a);
    }
    face_key[3u * f] = r.x;
    face_key[3u * f + 1u] = r.y;
    face_key[3u * f + 2u] = r.z;
    var keep = 0u;
    if (a != b && b != c && a != c) {
        keep = 1u;
        atomicAdd(&bucket_counts[r.x], 1u);
    }
    face_keep[f] = keep;
}
