// Shared structs, constants and quadric math of every stage; prepended to each stage's source at
// load time. Twin of src/compute/types.rs (structs) and src/compute/common.rs (math): keep in sync.

const WG: u32 = 256u;
const SCAN_BLOCK: u32 = 1024u;
const HIST_BINS: u32 = 4096u;
const HIST_SHIFT: u32 = 20u;
const INVALID_COST: u32 = 0xffffffffu;
const NO_ATTR: u32 = 0xffffffffu;

const FLAG_BORDER: u32 = 1u;
const FLAG_PINNED: u32 = 2u;
const FLAG_SEAM: u32 = 4u;
const FLAG_MOVED: u32 = 8u;
const FLAG_CLOSED: u32 = 16u;

const STATE_OUT: u32 = 0u;
const STATE_CANDIDATE: u32 = 1u;
const STATE_WON: u32 = 2u;
const STATE_TENTATIVE: u32 = 3u;
const STATE_POSTED: u32 = 4u;

struct Params {
    vertex_count: u32,
    face_count: u32,
    edge_capacity: u32,
    target_faces: u32,
    needed_faces: u32,
    ceiling_wanted: u32,
    lock_border: u32,
    trim: u32,
    cos_max_angle: f32,
    min_quality: f32,
    quality_threshold: f32,
    border_weight: f32,
    max_error2: f32,
    attributes: u32,
    color_weight: f32,
    groups: u32,
}

struct ScanParams {
    n: u32,
    _pad0: u32,
    _pad1: u32,
    _pad2: u32,
}

// Field order of Counters, for the stages that bind it as array<atomic<u32>, 16>.
const C_CANDIDATES: u32 = 0u;
const C_OVER_MAX_ERROR: u32 = 1u;
const C_CEILING: u32 = 2u;
const C_WINNERS: u32 = 3u;
const C_REMOVED: u32 = 4u;
const C_MAX_ERR2_BITS: u32 = 5u;
const C_TRIM_BIN: u32 = 6u;
const C_TRIM_BUDGET: u32 = 7u;
const C_VERTICES_OUT: u32 = 8u;
const C_FACES_OUT: u32 = 9u;
const C_TENTATIVE: u32 = 10u;
const C_LIVE: u32 = 11u;
const C_OPEN_GROUPS: u32 = 12u;
const C_OPEN_EXCESS: u32 = 13u;
const C_OPEN_FACES: u32 = 14u;
const COUNTERS: u32 = 16u;

struct Counters {
    candidates: u32,
    over_max_error: u32,
    ceiling: u32,
    winners: u32,
    removed: u32,
    max_err2_bits: u32,
    trim_bin: u32,
    trim_budget: u32,
    vertices_out: u32,
    faces_out: u32,
    tentative: u32,
    live: u32,
    open_groups: u32,
    open_excess: u32,
    open_faces: u32,
    _pad: array<u32, 1>,
}

// Keep in sync with PlanState and Planned in src/compute/types.rs.
struct PlanState {
    vertices: u32,
    faces: u32,
    target_faces: u32,
    stopped: u32,
    executed: u32,
    max_groups: u32,
    _pad0: u32,
    _pad1: u32,
}

const GRID_VERTICES: u32 = 0u;
const GRID_FACES: u32 = 1u;
const GRID_EDGE_SLOTS: u32 = 2u;
const GRID_VERTICES_OR_FACES: u32 = 3u;
const GRID_SCAN_VERTICES: u32 = 4u;
const GRID_ONE: u32 = 7u;
const GRID_TRIM_EDGE_SLOTS: u32 = 8u;
const GRID_TRIM_SCAN: u32 = 9u;
const GRID_TRIM_ONE: u32 = 10u;
const GRID_SLOTS: u32 = 11u;

struct Planned {
    params: Params,
    scans: array<ScanParams, 3>,
    grids: array<vec4<u32>, 11>,
}

// Relative to its vertex: [a00 a01 a02 a11] [a12 a22 b0 b1] [b2 c weight 0].
struct Quadric {
    q0: vec4<f32>,
    q1: vec4<f32>,
    q2: vec4<f32>,
}

struct EdgeCandidate {
    pos: vec4<f32>,
    keep: u32,
    remove: u32,
    cost_bits: u32,
    faces: u32,
}

fn invalid_candidate() -> EdgeCandidate {
    return EdgeCandidate(vec4<f32>(0.0), 0u, 0u, INVALID_COST, 0u);
}

struct FaceExtra {
    attr0: u32,
    attr1: u32,
    attr2: u32,
    origin: u32,
}

struct DrawArgs {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Tie-break rank of an edge among equal costs: a bijective hash (lowbias32) so that neighbours get
// unrelated ranks. Twin of cpu/common.rs::tie_rank.
fn tie_rank(e: u32) -> u32 {
    var x = e;
    x = x ^ (x >> 16u);
    x = x * 0x7feb352du;
    x = x ^ (x >> 15u);
    x = x * 0x846ca68bu;
    return x ^ (x >> 16u);
}

// a·b in cpu::common::dot's order (x, then y, then z): WGSL's dot leaves the order to the driver,
// and the floating cells compare these sums against radii where an ulp decides.
fn dot3(a: vec3<f32>, b: vec3<f32>) -> f32 {
    return a.x * b.x + a.y * b.y + a.z * b.z;
}

fn quadric_from_plane(n: vec3<f32>, d: f32, w: f32) -> Quadric {
    return Quadric(
        vec4<f32>(w * n.x * n.x, w * n.x * n.y, w * n.x * n.z, w * n.y * n.y),
        vec4<f32>(w * n.y * n.z, w * n.z * n.z, w * n.x * d, w * n.y * d),
        vec4<f32>(w * n.z * d, w * d * d, w, 0.0),
    );
}

fn quadric_add(a: Quadric, b: Quadric) -> Quadric {
    return Quadric(a.q0 + b.q0, a.q1 + b.q1, a.q2 + b.q2);
}

fn quadric_mul_a(q: Quadric, y: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(
        q.q0.x * y.x + q.q0.y * y.y + q.q0.z * y.z,
        q.q0.y * y.x + q.q0.w * y.y + q.q1.x * y.z,
        q.q0.z * y.x + q.q1.x * y.y + q.q1.y * y.z,
    );
}

fn quadric_b(q: Quadric) -> vec3<f32> {
    return vec3<f32>(q.q1.z, q.q1.w, q.q2.x);
}

// The same quadric measured from origin + t: E'(y) = E(y + t).
fn quadric_shift(q: Quadric, t: vec3<f32>) -> Quadric {
    let at = quadric_mul_a(q, t);
    let b = quadric_b(q);
    let nb = b + at;
    let c = dot(t, at) + 2.0 * dot(b, t) + q.q2.y;
    return Quadric(q.q0, vec4<f32>(q.q1.x, q.q1.y, nb.x, nb.y), vec4<f32>(nb.z, c, q.q2.z, q.q2.w));
}

fn quadric_eval(q: Quadric, y: vec3<f32>) -> f32 {
    let v = dot(y, quadric_mul_a(q, y)) + 2.0 * dot(quadric_b(q), y) + q.q2.y;
    return max(v, 0.0);
}

struct Optimum {
    ok: bool,
    y: vec3<f32>,
}

// The minimiser when A is well conditioned (determinant against the cube of the trace).
fn quadric_optimum(q: Quadric) -> Optimum {
    let a00 = q.q0.x; let a01 = q.q0.y; let a02 = q.q0.z; let a11 = q.q0.w;
    let a12 = q.q1.x; let a22 = q.q1.y;
    let c00 = a11 * a22 - a12 * a12;
    let c01 = a02 * a12 - a01 * a22;
    let c02 = a01 * a12 - a02 * a11;
    let det = a00 * c00 + a01 * c01 + a02 * c02;
    let tr = a00 + a11 + a22;
    if (!(tr > 0.0) || !(abs(det) > 1e-6 * tr * tr * tr)) {
        return Optimum(false, vec3<f32>(0.0));
    }
    let c11 = a00 * a22 - a02 * a02;
    let c12 = a01 * a02 - a00 * a12;
    let c22 = a00 * a11 - a01 * a01;
    let inv = 1.0 / det;
    let b = quadric_b(q);
    let y = vec3<f32>(
        -(c00 * b.x + c01 * b.y + c02 * b.z) * inv,
        -(c01 * b.x + c11 * b.y + c12 * b.z) * inv,
        -(c02 * b.x + c12 * b.y + c22 * b.z) * inv,
    );
    // Finite: NaN fails every comparison, infinities exceed the largest f32.
    let m = max(abs(y.x), max(abs(y.y), abs(y.z)));
    if (!(m <= 3.0e38)) {
        return Optimum(false, vec3<f32>(0.0));
    }
    return Optimum(true, y);
}

// Quality from |cross| already at hand (the flip test computes it). Twin of quality_from_area2.
fn quality_from_area2(area2: f32, p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> f32 {
    let d10 = p1 - p0;
    let d20 = p2 - p0;
    let d12 = p1 - p2;
    let longest = max(max(dot(d10, d10), dot(d20, d20)), dot(d12, d12));
    if (longest > 0.0) {
        return area2 / longest;
    }
    return 0.0;
}

fn triangle_quality(p0: vec3<f32>, p1: vec3<f32>, p2: vec3<f32>) -> f32 {
    let d10 = p1 - p0;
    let d20 = p2 - p0;
    let d12 = p1 - p2;
    let area2 = length(cross(d10, d20));
    let longest = max(max(dot(d10, d10), dot(d20, d20)), dot(d12, d12));
    if (longest > 0.0) {
        return area2 / longest;
    }
    return 0.0;
}

fn is_finite(x: f32) -> bool {
    return abs(x) <= 3.0e38;
}
