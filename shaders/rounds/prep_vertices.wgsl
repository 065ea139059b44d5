// Per used class, at its dense number: its position in the normalized frame, (p - centre) ×
// scale in f64 rounded to f32 as the host's `mesh::prepare::normalize` does, no flags (the
// plain meshes prepared here have no seams), and its first input vertex.

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> in_positions: array<f32>;         // per input vertex × 3
@group(0) @binding(2) var<storage, read> welded_id: array<u32>;            // per input vertex + 1, scanned
@group(0) @binding(3) var<storage, read> welded_input: array<u32>;         // per welded vertex
@group(0) @binding(4) var<storage, read> class_welded: array<u32>;         // per class
@group(0) @binding(5) var<storage, read> class_used: array<u32>;           // per class + 1, scanned
@group(0) @binding(6) var<storage, read_write> positions: array<vec4<f32>>; // per used class
@group(0) @binding(7) var<storage, read_write> flags: array<u32>;          // per used class
@group(0) @binding(8) var<storage, read_write> vertex_attr: array<u32>;    // per used class

@compute @workgroup_size(256)
fn prep_vertices(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = gid.x + gid.y * nwg.x * WG;
    if (c >= welded_id[prep.vertex_count] || class_used[c + 1u] == class_used[c]) {
        return;
    }
    let d = class_used[c];
    let v = welded_input[class_welded[c]];
    var q: vec3<f32>;
    for (var i = 0u; i < 3u; i = i + 1u) {
        q[i] = f32((f64(in_positions[3u * v + i]) - prep.frame[i]) * prep.frame.w);
    }
    positions[d] = vec4<f32>(q, 1.0);
    flags[d] = 0u;
    vertex_attr[d] = v;
}
