// Per face: a kept face's clusters and input id to its slot, in face order. Relies on face_keep
// holding the exclusive scan of the keep flags (total at [face_count]).

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> face_key: array<u32>;                // per face × 3
@group(0) @binding(2) var<storage, read> face_keep: array<u32>;               // per face + 1, scanned
@group(0) @binding(3) var<storage, read_write> cluster_faces: array<u32>;     // per kept face × 3
@group(0) @binding(4) var<storage, read_write> face_origin: array<u32>;       // per kept face

@compute @workgroup_size(256)
fn cluster_faces_compact(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= cluster.face_count) {
        return;
    }
    let s = face_keep[f];
    if (face_keep[f + 1u] == s) {
        return;
    }
    cluster_faces[3u * s] = face_key[3u * f];
    cluster_faces[3u * s + 1u] = face_key[3u * f + 1u];
    cluster_faces[3u * s + 2u] = face_key[3u * f + 2u];
    face_origin[s] = f;
}
