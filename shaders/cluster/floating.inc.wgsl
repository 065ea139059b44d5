// The floating cells' uniform and helpers; prepended (after common.wgsl and cluster.wgsl) to the
// stages that bind FloatParams. Twin of FloatParams in src/compute/types.rs and of
// cluster/floating.rs's radius and ranks: keep in sync.

// Centres' radii spread over ±JITTER/2 about the nominal one (floating::JITTER).
const JITTER: f32 = 0.2;

struct FloatParams {
    r: f32,
    slot: u32,
    _pad0: u32,
    _pad1: u32,
}

// The radius of centre v for the nominal radius r (floating::radius). The hash over 2^32 is a
// product by a power of two, exact, as the CPU's division by u32::MAX as f32 (= 2^32) is.
fn radius(r: f32, v: u32) -> f32 {
    let u = f32(tie_rank(v ^ 0x9e3779b9u)) * 2.3283064365386963e-10;
    return r * (1.0 + JITTER * (u - 0.5));
}

// Whether u's rank is above v's: the rank word fc_ranks wrote, then the id (floating::ranks packs
// the id below the word, so the higher id wins a tie).
fn outranks(rank_u: u32, u: u32, rank_v: u32, v: u32) -> bool {
    return rank_u > rank_v || (rank_u == rank_v && u > v);
}

// The a-th of the 3×3×3 cells around a cell, as an offset: its own cell first (where a vertex
// that outranks it most often lies, and the search stops at the first), then the 26 others.
fn around(a: u32) -> vec3<i32> {
    var i = 13u;
    if (a > 0u) {
        i = a - 1u;
        if (a > 13u) {
            i = a;
        }
    }
    return vec3<i32>(i32(i % 3u) - 1, i32((i / 3u) % 3u) - 1, i32(i / 9u) - 1);
}
