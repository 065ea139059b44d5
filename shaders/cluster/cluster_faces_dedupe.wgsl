// Per cluster: sorts its bucket by (second cluster, third cluster, face id) and unkeeps every
// face equal to the one before it, so of each exact repeat the lowest face id stays. Buckets are
// small (a few faces per cluster); each face lies in one bucket, so the writes never collide.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> face_key: array<u32>;             // per face × 3
@group(0) @binding(2) var<storage, read> bucket_offsets: array<u32>;       // per vertex + 1
@group(0) @binding(3) var<storage, read_write> bucket_faces: array<u32>;   // per kept face
@group(0) @binding(4) var<storage, read_write> face_keep: array<u32>;      // per face + 1

// (b, c, f) of face f before (b, c, g) of face g.
fn before(f: u32, g: u32) -> bool {
    let fb = face_key[3u * f + 1u];
    let gb = face_key[3u * g + 1u];
    if (fb != gb) {
        return fb < gb;
    }
    let fc = face_key[3u * f + 2u];
    let gc = face_key[3u * g + 2u];
    if (fc != gc) {
        return fc < gc;
    }
    return f < g;
}

@compute @workgroup_size(256)
fn cluster_faces_dedupe(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * WG;
    if (k >= cluster.vertex_count) {
        return;
    }
    let lo = bucket_offsets[k];
    let hi = bucket_offsets[k + 1u];
    for (var i = lo + 1u; i < hi; i = i + 1u) {
        let x = bucket_faces[i];
        var j = i;
        loop {
            if (j <= lo) { break; }
            let y = bucket_faces[j - 1u];
            if (!before(x, y)) { break; }
            bucket_faces[j] = y;
            j = j - 1u;
        }
        bucket_faces[j] = x;
    }
    for (var i = lo + 1u; i < hi; i = i + 1u) {
        let f = bucket_faces[i];
        let g = bucket_faces[i - 1u];
        if (face_key[3u * f + 1u] == face_key[3u * g + 1u] && face_key[3u * f + 2u] == face_key[3u * g + 2u]) {
            face_keep[f] = 0u;
        }
    }
}
