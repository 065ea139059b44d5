// Reading the current faces and the vertex→face CSR lists; prepended (after common.wgsl) to the
// stages that bind `indices` and `vertex_faces` (WGSL resolves module-scope names in any order).

fn face_of(f: u32) -> vec3<u32> {
    return vec3<u32>(indices[3u * f], indices[3u * f + 1u], indices[3u * f + 2u]);
}

fn has(t: vec3<u32>, u: u32) -> bool {
    return t.x == u || t.y == u || t.z == u;
}

// Some face of the list range [lo, hi) of vertex_faces contains u.
fn list_has(lo: u32, hi: u32, u: u32) -> bool {
    for (var i = lo; i < hi; i = i + 1u) {
        if (has(face_of(vertex_faces[i]), u)) { return true; }
    }
    return false;
}

// Faces of the list range [lo, hi) containing u.
fn count_containing(lo: u32, hi: u32, u: u32) -> u32 {
    var n = 0u;
    for (var i = lo; i < hi; i = i + 1u) {
        if (has(face_of(vertex_faces[i]), u)) { n = n + 1u; }
    }
    return n;
}
