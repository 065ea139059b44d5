// Per unclaimed vertex: it becomes a centre this round when no unclaimed vertex within the sum of
// their radii outranks it (Low & Tan's most important vertex first, as parallel rounds). Two
// centres of a round are then farther apart than their radii's sum: their balls are disjoint.
// Relies on each hash cell's members being sorted by rank, highest first (the scan stops at the
// first that does not outrank v), and on cells 2·r_max wide: any reach lies in the 27 around.
// Integer atomics only count the round's unclaimed vertices (the host stops at a round of none).

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<uniform> floating: FloatParams;
@group(0) @binding(2) var<storage, read> positions: array<vec4<f32>>;       // per vertex
@group(0) @binding(3) var<storage, read> fc_rank: array<u32>;               // per vertex
@group(0) @binding(4) var<storage, read> sort_vals: array<u32>;             // per vertex, by (cell, rank)
@group(0) @binding(5) var<storage, read> cell_head: array<u32>;             // per vertex + 1, scanned
@group(0) @binding(6) var<storage, read> cell_start: array<u32>;            // per cell + 1
@group(0) @binding(7) var<storage, read> cell_key: array<u32>;              // per cell
@group(0) @binding(8) var<storage, read> fc_centre: array<u32>;             // per vertex
@group(0) @binding(9) var<storage, read_write> fc_decided: array<u32>;      // per vertex
@group(0) @binding(10) var<storage, read_write> fc_live: array<atomic<u32>>; // per round slot

@compute @workgroup_size(256)
fn fc_decide(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= cluster.vertex_count || fc_centre[v] != UNCLAIMED) {
        return;
    }
    atomicAdd(&fc_live[floating.slot], 1u);
    let p = positions[v].xyz;
    let rank = fc_rank[v];
    let rv = radius(floating.r, v);
    let c = vec3<i32>(cell_coords(cluster, p));
    let dims = vec3<i32>(cluster.dims.xyz);
    var outranked = false;
    for (var a = 0u; a < 27u && !outranked; a = a + 1u) {
        let q = c + around(a);
        if (any(q < vec3<i32>(0)) || any(q >= dims)) {
            continue;
        }
        let k = find_cell(morton3(vec3<u32>(q)));
        if (k == NO_CELL) {
            continue;
        }
        for (var i = cell_start[k]; i < cell_start[k + 1u]; i = i + 1u) {
            let u = sort_vals[i];
            if (!outranks(fc_rank[u], u, rank, v)) {
                break;
            }
            if (fc_centre[u] == UNCLAIMED) {
                let d = positions[u].xyz - p;
                let reach = rv + radius(floating.r, u);
                if (dot3(d, d) <= reach * reach) {
                    outranked = true;
                    break;
                }
            }
        }
    }
    fc_decided[v] = select(1u, 0u, outranked);
}
