// Sorts each vertex's face list (insertion sort; valences are small), so every later gather
// visits faces in the same order on every run and on CPU and GPU.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> offsets: array<u32>;            // per vertex + 1
@group(0) @binding(2) var<storage, read_write> vertex_faces: array<u32>; // per corner

@compute @workgroup_size(256)
fn adjacency_sort(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= params.vertex_count) {
        return;
    }
    let lo = offsets[v];
    let hi = offsets[v + 1u];
    for (var i = lo + 1u; i < hi; i = i + 1u) {
        let x = vertex_faces[i];
        var j = i;
        loop {
            if (j <= lo) { break; }
            let y = vertex_faces[j - 1u];
            if (y <= x) { break; }
            vertex_faces[j] = y;
            j = j - 1u;
        }
        vertex_faces[j] = x;
    }
}
