// Per vertex: its rank word (the grade's bits less the low 8, then 8 bits of a hash of the id, so
// near-equal grades rank by the hash and not in an id wave; floating::ranks) and, at slot
// n - 1 - v, the pair the rank sort orders: the inverted word with the id. The stable radix sort
// then leaves the vertices by rank, highest first (a tie of words to the higher id, as the CPU's
// u64 rank has the id below the word). The word is exact given the grade; a grade an ulp off on
// another device changes it only across a 256-ulp step.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> fc_grade: array<f32>;        // per vertex
@group(0) @binding(2) var<storage, read_write> fc_rank: array<u32>;   // per vertex
@group(0) @binding(3) var<storage, read_write> sort_keys: array<u32>; // per vertex
@group(0) @binding(4) var<storage, read_write> sort_vals: array<u32>; // per vertex

@compute @workgroup_size(256)
fn fc_ranks(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    let n = params.vertex_count;
    if (v >= n) {
        return;
    }
    let g = fc_grade[v];
    // Non-negative (NaN too) to 0: a non-negative f32 orders as its bits.
    let bits = select(0u, bitcast<u32>(g), g > 0.0);
    let rank = (bits & 0xffffff00u) | (tie_rank(v) & 0xffu);
    fc_rank[v] = rank;
    sort_keys[n - 1u - v] = ~rank;
    sort_vals[n - 1u - v] = v;
}
