// Per input vertex: its position into the weld's hash table (open addressing, linear probing).
// A slot holds one position, as its lowest vertex + 1 (0: empty): the first vertex to reach an
// empty slot claims it by compare-and-swap, every other vertex at that position lowers it by
// atomicMin. Which slot a position lands in depends on timing, the lowest vertex it ends with
// does not, so the weld is the host's (`mesh::weld::weld_positions`) whatever the order.

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> in_positions: array<f32>;              // per input vertex × 3
@group(0) @binding(2) var<storage, read_write> weld_table: array<atomic<u32>>;  // per slot
@group(0) @binding(3) var<storage, read_write> weld_slot: array<u32>;           // per input vertex

// Vertex v's position as the weld compares it: bits, with -0.0 as 0.0 (`mesh::weld::bits`).
fn weld_key(v: u32) -> vec3<u32> {
    var k: vec3<u32>;
    for (var i = 0u; i < 3u; i = i + 1u) {
        let x = in_positions[3u * v + i];
        k[i] = select(bitcast<u32>(x), 0u, x == 0.0);
    }
    return k;
}

// Murmur3's finalizer over the three words: any mix works, the result does not depend on it.
fn weld_hash(k: vec3<u32>) -> u32 {
    var h = (k.x * 0xcc9e2d51u) ^ (k.y * 0x1b873593u) ^ (k.z * 0x85ebca6bu);
    h = h ^ (h >> 16u);
    h = h * 0x85ebca6bu;
    h = h ^ (h >> 13u);
    h = h * 0xc2b2ae35u;
    return h ^ (h >> 16u);
}

@compute @workgroup_size(256)
fn weld_insert(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= prep.vertex_count) {
        return;
    }
    let k = weld_key(v);
    var h = weld_hash(k) & prep.table_mask;
    // The table has at least twice as many slots as vertices, so a free slot is always ahead.
    loop {
        let held = atomicLoad(&weld_table[h]);
        if (held == 0u) {
            let r = atomicCompareExchangeWeak(&weld_table[h], 0u, v + 1u);
            if (r.exchanged) {
                break;
            }
            // Taken meanwhile (or a spurious failure): look at the slot again.
            continue;
        }
        if (all(weld_key(held - 1u) == k)) {
            atomicMin(&weld_table[h], v + 1u);
            break;
        }
        h = (h + 1u) & prep.table_mask;
    }
    weld_slot[v] = h;
}
