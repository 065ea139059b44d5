// Grouped rounds, one invocation after `group_faces`: which groups have reached their target,
// how many have not, the faces they are over and all their faces (the next round's plan), and the counts zeroed
// for the next round. A loop over the groups: a DAG level has a few thousand at most.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> group_target: array<u32>;         // per group
@group(0) @binding(2) var<storage, read_write> group_count: array<u32>;    // per group
@group(0) @binding(3) var<storage, read_write> group_closed: array<u32>;   // per group
@group(0) @binding(4) var<storage, read_write> counters: array<atomic<u32>, 16>;

@compute @workgroup_size(1)
fn group_open() {
    var open = 0u;
    var excess = 0u;
    var faces = 0u;
    for (var g = 0u; g < params.groups; g = g + 1u) {
        let n = group_count[g];
        let t = group_target[g];
        group_closed[g] = select(0u, 1u, n <= t);
        if (n > t) {
            open = open + 1u;
            excess = excess + (n - t);
            faces = faces + n;
        }
        group_count[g] = 0u;
    }
    atomicStore(&counters[C_OPEN_GROUPS], open);
    atomicStore(&counters[C_OPEN_EXCESS], excess);
    atomicStore(&counters[C_OPEN_FACES], faces);
}
