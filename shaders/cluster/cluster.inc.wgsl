// Structs and helpers of the clustering stages; prepended (after common.wgsl) to the stages that
// bind ClusterParams or RadixParams. Twin of the cluster structs in src/compute/types.rs: keep in
// sync.

// A locked vertex's key: one cell of its own, above every Morton key (< 2^30).
const SINGLETON: u32 = 0x80000000u;
// Keys one radix workgroup takes: 256 threads × 4 contiguous keys.
const SORT_BLOCK: u32 = 1024u;
// A floating cell's vertex not yet claimed by a centre (fc_centre).
const UNCLAIMED: u32 = 0xffffffffu;

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

// The low 10 bits of x spread to every third bit (twin of mesh::morton::morton3's part).
fn spread3(x0: u32) -> u32 {
    var x = x0 & 0x3ffu;
    x = (x | (x << 16u)) & 0x030000ffu;
    x = (x | (x << 8u)) & 0x0300f00fu;
    x = (x | (x << 4u)) & 0x030c30c3u;
    return (x | (x << 2u)) & 0x09249249u;
}

fn morton3(c: vec3<u32>) -> u32 {
    return spread3(c.x) | (spread3(c.y) << 1u) | (spread3(c.z) << 2u);
}

// The grid cell of p (twin of Grid::coords): subtract, multiply by the inverse cell size,
// truncate, clamp. Correctly rounded in Vulkan, so every device finds the same cell.
fn cell_coords(c: ClusterParams, p: vec3<f32>) -> vec3<u32> {
    let q = max((p - c.lo_h.xyz) * c.inv_h, vec3<f32>(0.0));
    return min(vec3<u32>(q), c.dims.xyz - vec3<u32>(1u));
}
