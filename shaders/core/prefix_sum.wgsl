// Exclusive prefix sum of scan.n u32 values in place, the total written at data[n]: per-block
// sums, one workgroup scanning the block sums, then each block's local scan plus its offset.
// Relies on data holding n + 1 values and block_sums one per SCAN_BLOCK elements.
//
// 64 threads of 16 elements each, not 256 of 4: lavapipe (a CPU driver) runs a workgroup as
// SIMD chunks of 8 invocations and switches between all of them at every barrier, so a scan of
// 64 thread sums (6 steps, 8 chunks) waits far less than one of 256 (8 steps, 32 chunks). On
// the 1M-triangle scan a face-sized scan went from 0.035 s to 0.011 s there
// (docs/PERFORMANCE.md); 64 threads is one wave on a GPU.

@group(0) @binding(0) var<uniform> scan: ScanParams;
@group(0) @binding(1) var<storage, read_write> data: array<u32>;       // n + 1
@group(0) @binding(2) var<storage, read_write> block_sums: array<u32>; // per block

const SCAN_THREADS: u32 = 64u;
const SCAN_PER_THREAD: u32 = 16u; // SCAN_BLOCK / SCAN_THREADS

var<workgroup> sh: array<u32, 64>;

fn load(i: u32) -> u32 {
    if (i < scan.n) {
        return data[i];
    }
    return 0u;
}

@compute @workgroup_size(64)
fn prefix_sum_reduce(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                     @builtin(local_invocation_index) li: u32) {
    let block = wid.x + wid.y * nwg.x;
    let base = block * SCAN_BLOCK + li * SCAN_PER_THREAD;
    var sum = 0u;
    for (var j = 0u; j < SCAN_PER_THREAD; j = j + 1u) {
        sum = sum + load(base + j);
    }
    sh[li] = sum;
    workgroupBarrier();
    for (var s = SCAN_THREADS / 2u; s > 0u; s = s >> 1u) {
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

@compute @workgroup_size(64)
fn prefix_sum_apply(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                    @builtin(local_invocation_index) li: u32) {
    let block = wid.x + wid.y * nwg.x;
    let base = block * SCAN_BLOCK + li * SCAN_PER_THREAD;
    var x: array<u32, 16>;
    var total = 0u;
    for (var j = 0u; j < SCAN_PER_THREAD; j = j + 1u) {
        x[j] = load(base + j);
        total = total + x[j];
    }
    sh[li] = total;
    workgroupBarrier();
    // Hillis–Steele inclusive scan of the thread sums.
    for (var s = 1u; s < SCAN_THREADS; s = s << 1u) {
        var v = sh[li];
        if (li >= s) {
            v = v + sh[li - s];
        }
        workgroupBarrier();
        sh[li] = v;
        workgroupBarrier();
    }
    var run = block_sums[block] + sh[li] - total;
    for (var j = 0u; j < SCAN_PER_THREAD; j = j + 1u) {
        if (base + j < scan.n) {
            data[base + j] = run;
        }
        run = run + x[j];
    }
}
