// Structs and helpers of the clustering stages; prepended (after common.wgsl) to the stages that
// bind ClusterParams or RadixParams. Twin of the cluster structs in src/gpu/types.rs: keep in sync.

// A locked vertex's key: one cell of its own, above every Morton key (< 2^30).
const SINGLETON: u32 = 0x80000000u;
// Keys one radix workgroup takes: 256 threads × 4 contiguous keys.
const SORT_BLOCK: u32 = 1024u;

const PLACE_SINGLE: u32 = 0u;
const PLACE_SOLVE: u32 = 1u;
const PLACE_MEMBER: u32 = 2u;
const PLACE_CENTROID: u32 = 3u;

struct ClusterParams {
    lo_h: vec4<f32>,
    dims: vec4<u32>,
    vertex_count: u32,
    face_count: u32,
    inv_h: f32,
    _pad1: u32,
}

struct RadixParams {
    n: u32,
    blocks: u32,
    shift: u32,
    _pad: u32,
}

struct ClusterPlaced {
    pos: vec4<f32>,
    attr: u32,
    how: u32,
    _pad0: u32,
    _pad1: u32,
}
