// Per block: sorts the block stably by the pass's digit in workgroup memory (four 2-bit splits,
// each ranked by a workgroup scan, no atomics), then writes key i of digit d to the scanned
// digit_counts[d * blocks + b] + (i - first slot of d in the block). Stable, so the sort's output
// after every pass is the unique one, equal to the CPU twin's. No workgroup waits on another.
//
// 64 threads of 16 keys each, not 256 of 4: lavapipe (a CPU driver) runs a workgroup as SIMD
// chunks of 8 invocations and switches between all of them at every barrier, so a scan over 64
// threads (6 steps, 8 chunks) waits far less than one over 256 (8 steps, 32 chunks). On the
// 1M-triangle scan a scatter went from 0.09 s to 0.04 s there (docs/PERFORMANCE.md); 64
// threads is one wave on a GPU.

@group(0) @binding(0) var<uniform> radix: RadixParams;
@group(0) @binding(1) var<storage, read> keys: array<u32>;           // per vertex
@group(0) @binding(2) var<storage, read> vals: array<u32>;           // per vertex
@group(0) @binding(3) var<storage, read> digit_counts: array<u32>;   // 256 per block + 1, scanned
@group(0) @binding(4) var<storage, read_write> keys_out: array<u32>; // per vertex
@group(0) @binding(5) var<storage, read_write> vals_out: array<u32>; // per vertex

const SCATTER_THREADS: u32 = 64u;
const PER_THREAD: u32 = 16u; // SORT_BLOCK / SCATTER_THREADS

var<workgroup> sk: array<u32, 1024>;
var<workgroup> sv: array<u32, 1024>;
// Per thread, its counts of bins 0 and 1 (lo) and 2 and 3 (hi) as 16-bit fields (totals <= 1024).
var<workgroup> scan_lo: array<u32, 64>;
var<workgroup> scan_hi: array<u32, 64>;
var<workgroup> run_start: array<u32, 256>;

fn digit_of(k: u32) -> u32 {
    return (k >> radix.shift) & 255u;
}

// Bin d as a vector (1 at d): counts and slots without indexing a vector by a variable.
fn one_hot(d: u32) -> vec4<u32> {
    return vec4<u32>(vec4<bool>(d == 0u, d == 1u, d == 2u, d == 3u));
}

fn unpack(lo: u32, hi: u32) -> vec4<u32> {
    return vec4<u32>(lo & 0xffffu, lo >> 16u, hi & 0xffffu, hi >> 16u);
}

@compute @workgroup_size(64)
fn radix_scatter(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                 @builtin(local_invocation_index) li: u32) {
    let b = wid.x + wid.y * nwg.x;
    if (b >= radix.blocks) {
        return;
    }
    let base = b * SORT_BLOCK;
    let valid = min(radix.n - base, SORT_BLOCK);
    let first = li * PER_THREAD;
    // Slots past the end hold digit 255 and come last in the block, so they stay behind every
    // real key through the stable splits.
    for (var j = 0u; j < PER_THREAD; j = j + 1u) {
        let i = first + j;
        if (i < valid) {
            sk[i] = keys[base + i];
            sv[i] = vals[base + i];
        } else {
            sk[i] = 0xffffffffu;
            sv[i] = 0u;
        }
    }
    workgroupBarrier();
    for (var bit = 0u; bit < 8u; bit = bit + 2u) {
        var k: array<u32, 16>;
        var v: array<u32, 16>;
        var cnt = vec4<u32>(0u);
        for (var j = 0u; j < PER_THREAD; j = j + 1u) {
            k[j] = sk[first + j];
            v[j] = sv[first + j];
            cnt = cnt + one_hot((digit_of(k[j]) >> bit) & 3u);
        }
        scan_lo[li] = cnt.x | (cnt.y << 16u);
        scan_hi[li] = cnt.z | (cnt.w << 16u);
        workgroupBarrier();
        // Hillis–Steele inclusive scan of the packed counts.
        for (var s = 1u; s < SCATTER_THREADS; s = s << 1u) {
            var a = scan_lo[li];
            var c = scan_hi[li];
            if (li >= s) {
                a = a + scan_lo[li - s];
                c = c + scan_hi[li - s];
            }
            workgroupBarrier();
            scan_lo[li] = a;
            scan_hi[li] = c;
            workgroupBarrier();
        }
        let total = unpack(scan_lo[SCATTER_THREADS - 1u], scan_hi[SCATTER_THREADS - 1u]);
        let before = unpack(scan_lo[li], scan_hi[li]) - cnt;
        var next = vec4<u32>(0u, total.x, total.x + total.y, total.x + total.y + total.z) + before;
        // Everyone has read the scan and its own keys before the block is rewritten.
        workgroupBarrier();
        for (var j = 0u; j < PER_THREAD; j = j + 1u) {
            let hot = one_hot((digit_of(k[j]) >> bit) & 3u);
            let slot = dot(next, hot);
            sk[slot] = k[j];
            sv[slot] = v[j];
            next = next + hot;
        }
        workgroupBarrier();
    }
    for (var j = 0u; j < PER_THREAD; j = j + 1u) {
        let i = first + j;
        let d = digit_of(sk[i]);
        if (i == 0u || digit_of(sk[i - 1u]) != d) {
            run_start[d] = i;
        }
    }
    workgroupBarrier();
    for (var j = 0u; j < PER_THREAD; j = j + 1u) {
        let i = first + j;
        if (i < valid) {
            let d = digit_of(sk[i]);
            let slot = digit_counts[d * radix.blocks + b] + i - run_start[d];
            keys_out[slot] = sk[i];
            vals_out[slot] = sv[i];
        }
    }
}
