// Exclusive prefix sum of scan.n u32 values in place, the total written at data[n]: per-block
// sums, one workgroup scanning the block sums, then each block's local scan plus its offset.
// Relies on data holding n + 1 values and block_sums one per SCAN_BLOCK elements.

@group(0) @binding(0) var<uniform> scan: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;       // n + 1
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>; // per block

var<workgroup> sh: array<u32, 256>;

fn load(i: u32) -> u32 {
    if (i < scan.n) {
        return data[i];
    }
    return 0u;
}

@compute @workgroup_size(256)
fn prefix_sum_reduce(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                     @builtin(local_invocation_index) li: u32) {
    let block = wid.x + wid.y * nwg.x;
    let base = block * SCAN_BLOCK + li * 4u;
    sh[li] = load(base) + load(base + 1u) + load(base + 2u) + load(base + 3u);
    workgroupBarrier();
    for (var s = 128u; s > 0u; s = s >> 1u) {
        if (li < s) {
            sh[li] = sh[li] + sh[li + s];
        }
        workgroupBarrier();
    }
    if (li == 0u) {
        block_sums[block] = sh[0];
    }
}

@compute @workgroup_size(1)
fn prefix_sum_spine() {
    let blocks = max((scan.n + SCAN_BLOCK - 1u) / SCAN_BLOCK, 1u);
    var run = 0u;
    for (var b = 0u; b < blocks; b = b + 1u) {
        let x = block_sums[b];
        block_sums[b] = run;
        run = run + x;
    }
    data[scan.n] = run;
}

@compute @workgroup_size(256)
fn prefix_sum_apply(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                    @builtin(local_invocation_index) li: u32) {
    let block = wid.x + wid.y * nwg.x;
    let base = block * SCAN_BLOCK + li * 4u;
    let x0 = load(base);
    let x1 = load(base + 1u);
    let x2 = load(base + 2u);
    let x3 = load(base + 3u);
    let total = x0 + x1 + x2 + x3;
    sh[li] = total;
    workgroupBarrier();
    // Hillis–Steele inclusive scan of the 256 thread sums.
    for (var s = 1u; s < 256u; s = s << 1u) {
        var v = sh[li];
        if (li >= s) {
            v = v + sh[li - s];
        }
        workgroupBarrier();
        sh[li] = v;
        workgroupBarrier();
    }
    var run = block_sums[block] + sh[li] - total;
    if (base < scan.n) { data[base] = run; }
    run = run + x0;
    if (base + 1u < scan.n) { data[base + 1u] = run; }
    run = run + x1;
    if (base + 2u < scan.n) { data[base + 2u] = run; }
    run = run + x2;
    if (base + 3u < scan.n) { data[base + 3u] = run; }
}
