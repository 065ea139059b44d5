// Per block of SORT_BLOCK keys: how many hold each 8-bit digit (bits radix.shift..+8), written
// digit-major (digit_counts[d * blocks + b]) so that one exclusive scan gives every (digit, block)
// its first output slot, earlier blocks first. Integer atomics only count: order does not matter.

@group(0) @binding(0) var<uniform> radix: RadixParams;
@group(0) @binding(1) var<storage, read> keys: array<u32>;               // per vertex
@group(0) @binding(2) var<storage, read_write> digit_counts: array<u32>; // 256 per block + 1

var<workgroup> hist: array<atomic<u32>, 256>;

@compute @workgroup_size(256)
fn radix_count(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
               @builtin(local_invocation_index) li: u32) {
    let b = wid.x + wid.y * nwg.x;
    if (b >= radix.blocks) {
        return;
    }
    atomicStore(&hist[li], 0u);
    workgroupBarrier();
    for (var k = 0u; k < 4u; k = k + 1u) {
        let i = b * SORT_BLOCK + li * 4u + k;
        if (i < radix.n) {
            atomicAdd(&hist[(keys[i] >> radix.shift) & 255u], 1u);
        }
    }
    workgroupBarrier();
    digit_counts[li * radix.blocks + b] = atomicLoad(&hist[li]);
}
