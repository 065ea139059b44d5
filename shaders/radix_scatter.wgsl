// Per block: sorts the block stably by the pass's digit in workgroup memory (four 2-bit splits,
// each ranked by a workgroup scan, no atomics), then writes key i of digit d to the scanned
// digit_counts[d * blocks + b] + (i - first slot of d in the block). Stable, so the sort's output
// after every pass is the unique one, equal to the CPU twin's. No workgroup waits on another.

@group(0) @binding(0) var<uniform> radix: RadixParams;
@group(0) @binding(1) var<storage, read> keys: array<u32>;           // per vertex
@group(0) @binding(2) var<storage, read> vals: array<u32>;           // per vertex
@group(0) @binding(3) var<storage, read> digit_counts: array<u32>;   // 256 per block + 1, scanned
@group(0) @binding(4) var<storage, read_write> keys_out: array<u32>; // per vertex
@group(0) @binding(5) var<storage, read_write> vals_out: array<u32>; // per vertex

var<workgroup> sk: array<u32, 1024>;
var<workgroup> sv: array<u32, 1024>;
// Per thread, its counts of bins 0 and 1 (lo) and 2 and 3 (hi) as 16-bit fields (totals <= 1024).
var<workgroup> scan_lo: array<u32, 256>;
var<workgroup> scan_hi: array<u32, 256>;
var<workgroup> run_start: array<u32, 256>;

fn digit_of(k: u32) -> u32 {
    return (k >> radix.shift) & 255u;
}

fn unpack(lo: u32, hi: u32) -> vec4<u32> {
    return vec4<u32>(lo & 0xffffu, lo >> 16u, hi & 0xffffu, hi >> 16u);
}

@compute @workgroup_size(256)
fn radix_scatter(@builtin(workgroup_id) wid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>,
                 @builtin(local_invocation_index) li: u32) {
    let b = wid.x + wid.y * nwg.x;
    if (b >= radix.blocks) {
        return;
    }
    let base = b * SORT_BLOCK;
    let valid = min(radix.n - base, SORT_BLOCK);
    // Slots past the end hold digit 255 and come last in the block, so they stay behind every
    // real key through the stable splits.
    for (var j = 0u; j < 4u; j = j + 1u) {
        let i = li * 4u + j;
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
        var k: array<u32, 4>;
        var v: array<u32, 4>;
        var bins: array<u32, 4>;
        var cnt = vec4<u32>(0u);
        for (var j = 0u; j < 4u; j = j + 1u) {
            k[j] = sk[li * 4u + j];
            v[j] = sv[li * 4u + j];
            bins[j] = (digit_of(k[j]) >> bit) & 3u;
            cnt[bins[j]] = cnt[bins[j]] + 1u;
        }
        scan_lo[li] = cnt.x | (cnt.y << 16u);
        scan_hi[li] = cnt.z | (cnt.w << 16u);
        workgroupBarrier();
        // Hillis–Steele inclusive scan of the packed counts.
        for (var s = 1u; s < 256u; s = s << 1u) {
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
        let total = unpack(scan_lo[255], scan_hi[255]);
        let before = unpack(scan_lo[li], scan_hi[li]) - cnt;
        var next = vec4<u32>(0u, total.x, total.x + total.y, total.x + total.y + total.z) + before;
        // Everyone has read the scan and its own keys before the block is rewritten.
        workgroupBarrier();
        for (var j = 0u; j < 4u; j = j + 1u) {
            let d = bins[j];
            sk[next[d]] = k[j];
            sv[next[d]] = v[j];
            next[d] = next[d] + 1u;
        }
        workgroupBarrier();
    }
    for (var j = 0u; j < 4u; j = j + 1u) {
        let i = li * 4u + j;
        let d = digit_of(sk[i]);
        if (i == 0u || digit_of(sk[i - 1u]) != d) {
            run_start[d] = i;
        }
    }
    workgroupBarrier();
    for (var j = 0u; j < 4u; j = j + 1u) {
        let i = li * 4u + j;
        if (i < valid) {
            let d = digit_of(sk[i]);
            let slot = digit_counts[d * radix.blocks + b] + i - run_start[d];
            keys_out[slot] = sk[i];
            vals_out[slot] = sv[i];
        }
    }
}
