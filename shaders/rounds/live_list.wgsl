// Per edge: the candidates whose error is under the round's cost ceiling go on the live list,
// the others drop out. edge_costs and the selection passes then run one invocation per listed
// candidate (indirect dispatch from the count): with most edges out, a per-edge grid spent its
// SIMD lanes on them. Relies on edge_errors' candidates and cost_ceiling's ceiling.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> edge_offsets: array<u32>;           // per vertex + 1
@group(0) @binding(2) var<storage, read> candidates: array<EdgeCandidate>;   // per edge
@group(0) @binding(3) var<storage, read_write> edge_state: array<u32>;      // per edge
@group(0) @binding(4) var<storage, read_write> counters: array<atomic<u32>, 16>;
@group(0) @binding(5) var<storage, read_write> live: array<u32>;            // per listed candidate

// The workgroup reads the ceiling once and reserves its slots of the list with one global
// atomic: an atomic per edge on the same word serializes every invocation.
var<workgroup> wg_ceiling: u32;
var<workgroup> wg_count: atomic<u32>;
var<workgroup> wg_base: u32;

@compute @workgroup_size(256)
fn live_list(
    @builtin(global_invocation_id) gid: vec3<u32>,
    @builtin(num_workgroups) nwg: vec3<u32>,
    @builtin(local_invocation_index) li: u32,
) {
    if (li == 0u) {
        wg_ceiling = atomicLoad(&counters[C_CEILING]);
        atomicStore(&wg_count, 0u);
    }
    workgroupBarrier();
    let e = gid.x + gid.y * nwg.x * WG;
    // No early return: the barriers need every invocation of the workgroup.
    var listed = false;
    var slot = 0u;
    if (e < edge_offsets[params.vertex_count] && edge_state[e] == STATE_CANDIDATE) {
        if (candidates[e].cost_bits >= wg_ceiling) {
            edge_state[e] = STATE_OUT;
        } else {
            listed = true;
            slot = atomicAdd(&wg_count, 1u);
        }
    }
    workgroupBarrier();
    if (li == 0u) {
        let n = atomicLoad(&wg_count);
        if (n > 0u) { wg_base = atomicAdd(&counters[C_LIVE], n); }
    }
    workgroupBarrier();
    // The list's order depends on timing; no stage's result does (each writes its own edge).
    if (listed) { live[wg_base + slot] = e; }
}
