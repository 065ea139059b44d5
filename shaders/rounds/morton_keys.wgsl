// Per input vertex that is the first at its position: its welded vertex's Morton code on the
// 1024³ grid over the box, keyed for the radix sort with the welded vertex as its value; the
// slots past the welded vertices get a key that sorts last. The code is the host's
// (`mesh::morton::grid_codes`) bit for bit: the quotient is taken in f64 and rounded to f32,
// which is the correctly rounded f32 quotient (f64 carries more than twice f32's digits), where
// an f32 division on a GPU may be off by an ulp or two.

@group(0) @binding(0) var<uniform> prep: PrepParams;
@group(0) @binding(1) var<storage, read> in_positions: array<f32>;         // per input vertex × 3
@group(0) @binding(2) var<storage, read> weld_first: array<u32>;           // per input vertex
@group(0) @binding(3) var<storage, read> welded_id: array<u32>;            // per input vertex + 1, scanned
@group(0) @binding(4) var<storage, read_write> welded_input: array<u32>;   // per welded vertex
@group(0) @binding(5) var<storage, read_write> sort_keys: array<u32>;      // per input vertex
@group(0) @binding(6) var<storage, read_write> sort_vals: array<u32>;      // per input vertex

// The low 10 bits of x spread to every third bit (`mesh::morton::morton3`).
fn spread3(x: u32) -> u32 {
    var y = x & 0x3ffu;
    y = (y | (y << 16u)) & 0x030000ffu;
    y = (y | (y << 8u)) & 0x0300f00fu;
    y = (y | (y << 4u)) & 0x030c30c3u;
    return (y | (y << 2u)) & 0x09249249u;
}

@compute @workgroup_size(256)
fn morton_keys(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= prep.vertex_count) {
        return;
    }
    if (weld_first[v] == v) {
        let w = welded_id[v];
        welded_input[w] = v;
        var q: vec3<u32>;
        for (var i = 0u; i < 3u; i = i + 1u) {
            let d = in_positions[3u * v + i] - prep.grid[i];
            let t = f32(f64(d) / f64(prep.grid.w));
            q[i] = u32(t * 1023.0);
        }
        sort_keys[w] = spread3(q.x) | (spread3(q.y) << 1u) | (spread3(q.z) << 2u);
        sort_vals[w] = w;
    }
    if (v >= welded_id[prep.vertex_count]) {
        sort_keys[v] = PREP_PAD;
        sort_vals[v] = v;
    }
}
