// Per centre fc_decide chose this round: it claims every unclaimed vertex within its radius and
// itself, and flags itself in fc_head. Relies on the round's balls being disjoint (fc_decide), so
// no two centres write one vertex; each reads fc_centre only inside its own ball (distance
// first), where nobody else writes. fc_decided is fresh for every vertex unclaimed this round,
// and a stale 1 belongs to a centre of an earlier round, which fc_centre then shows.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<uniform> floating: FloatParams;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;  // per vertex
@group(0) @binding(3) var<storage, read> sort_vals: array<u32>;        // per vertex, by (cell, rank)
@group(0) @binding(4) var<storage, read> cell_head: array<u32>;        // per vertex + 1, scanned
@group(0) @binding(5) var<storage, read> cell_start: array<u32>;       // per cell + 1
@group(0) @binding(6) var<storage, read> cell_key: array<u32>;         // per cell
@group(0) @binding(7) var<storage, read> fc_decided: array<u32>;       // per vertex
@group(0) @binding(8) var<storage, read_write> fc_centre: array<u32>;  // per vertex
@group(0) @binding(9) var<storage, read_write> fc_head: array<u32>;    // per vertex + 1

@compute @workgroup_size(256)
fn fc_claim(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let c = gid.x + gid.y * nwg.x * WG;
    if (c >= cluster.vertex_count || fc_decided[c] == 0u || fc_centre[c] != UNCLAIMED) {
        return;
    }
    let p = positions[c].xyz;
    let rc = radius(floating.r, c);
    let cc = vec3<i32>(cell_coords(cluster, p));
    let dims = vec3<i32>(cluster.dims.xyz);
    for (var a = 0u; a < 27u; a = a + 1u) {
        let q = cc + around(a);
        if (any(q < vec3<i32>(0)) || any(q >= dims)) {
            continue;
        }
        let k = find_cell(morton3(vec3<u32>(q)));
        if (k == NO_CELL) {
            continue;
        }
        for (var i = cell_start[k]; i < cell_start[k + 1u]; i = i + 1u) {
            let u = sort_vals[i];
            let d = positions[u].xyz - p;
            if (u != c && dot3(d, d) <= rc * rc && fc_centre[u] == UNCLAIMED) {
                fc_centre[u] = c;
            }
        }
    }
    fc_centre[c] = c;
    fc_head[c] = 1u;
}
