// One invocation: indirect dispatch sizes for the per-edge stages (from the edge count), for
// validate (from the pass's tentative winners), for the per-candidate stages (from the live
// list) and for the trim's per-edge stages (none unless the round trims), so no invocation is
// spent past the real count.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> edge_offsets: array<u32>;   // per vertex + 1
@group(0) @binding(2) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(3) var<storage, read_write> args: array<u32, 16>; // four (x, y, z, _) grids

// Workgroups for n invocations, split over y past the 65535 per-dimension minimum every device has.
fn grid(at: u32, n: u32) {
    let groups = max((n + WG - 1u) / WG, 1u);
    let x = min(groups, 65535u);
    args[at] = x;
    args[at + 1u] = (groups + x - 1u) / x;
    args[at + 2u] = 1u;
    args[at + 3u] = 0u;
}

@compute @workgroup_size(1)
fn dispatch_args() {
    grid(0u, edge_offsets[params.vertex_count]);
    grid(4u, counters[C_TENTATIVE]);
    grid(8u, counters[C_LIVE]);
    if (params.trim != 0u) {
        grid(12u, edge_offsets[params.vertex_count]);
    } else {
        for (var i = 12u; i < 16u; i = i + 1u) {
            args[i] = 0u;
        }
    }
}
