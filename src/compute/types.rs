//! Structs shared by the WGSL stages and their CPU twins. Keep in sync with
//! shaders/common.inc.wgsl: every struct here has a WGSL twin of the same name and layout, and
//! `tests` in `src/compute/shaders.rs` compare naga's sizes with `size_of`.
//! No `vec3` members: storage structs are packed into `vec4`s so the layouts need no padding
//! rules beyond 16-byte alignment.

use bytemuck::{Pod, Zeroable};

/// Threads per workgroup of every 1-D stage. Keep in sync with `WG` in shaders/common.inc.wgsl.
pub const WG: u32 = 256;
/// Elements one workgroup of the prefix sum scans (4 per thread). Keep in sync with
/// `SCAN_BLOCK` in shaders/common.inc.wgsl.
pub const SCAN_BLOCK: u32 = WG * 4;
/// Bins of the cost histogram: the top 12 bits of a non-negative f32 (sign, 8 exponent bits,
/// 3 mantissa bits), the resolution meshoptimizer ranks with. Keep in sync with `HIST_BINS`.
pub const HIST_BINS: u32 = 4096;
/// Shift that turns cost bits into a histogram bin.
pub const HIST_SHIFT: u32 = 20;
/// Cost bits of an edge that may not collapse (a NaN pattern: above every real cost).
pub const INVALID_COST: u32 = 0xffff_ffff;

/// Vertex flag bits (`flags` buffers). Keep in sync with shaders/common.inc.wgsl.
pub mod flag {
    /// The vertex lies on an open border.
    pub const BORDER: u32 = 1;
    /// Keeps its position and is never removed (non-manifold spot, locked border); a free
    /// neighbour may still collapse onto it.
    pub const PINNED: u32 = 2;
    /// On an attribute seam (UV, normal or colour discontinuity): keeps its position, as the
    /// greedy reference's seam vertices do. A free neighbour may collapse onto it, its corners
    /// taking the seam vertex's attributes on their side; it is removed only by sliding along
    /// the seam onto a seam neighbour, each side mapping to its own attribute vertex. Its
    /// corners' attribute vertices (`FaceExtra::attr`) are kept current for that.
    pub const SEAM: u32 = 4;
    /// Moved by a collapse: the output takes its new position (unmoved vertices keep their
    /// input coordinates bit for bit).
    pub const MOVED: u32 = 8;
    /// Grouped rounds ([`super::Params::groups`]): a free vertex whose group has reached its
    /// target; no edge at it competes. Set each round by `group_flags`.
    pub const CLOSED: u32 = 16;
}

/// Per-edge selection state (`edge_state` buffer). Keep in sync with shaders/common.inc.wgsl.
pub mod state {
    /// Invalid or already out of this round.
    pub const OUT: u32 = 0;
    /// Competes in the next selection pass.
    pub const CANDIDATE: u32 = 1;
    /// Collapses this round.
    pub const WON: u32 = 2;
    /// Picked by a selection pass, waiting for `validate`'s checks.
    pub const TENTATIVE: u32 = 3;
    /// Had the best cost at every face around it in this pass and posted its tie rank
    /// (`select_id`); `select_win` makes it TENTATIVE or a CANDIDATE again.
    pub const POSTED: u32 = 4;
}

/// Per-round constants, a uniform. Keep in sync with `Params` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Params {
    pub vertex_count: u32,
    pub face_count: u32,
    /// Upper bound on the edge count (3 × faces): per-edge stages are dispatched for this many
    /// invocations and stop at the real count, read from the edge prefix sum.
    pub edge_capacity: u32,
    pub target_faces: u32,
    /// Faces still to remove this run: `face_count - target_faces`.
    pub needed_faces: u32,
    /// How many candidates the cost ceiling lets compete.
    pub ceiling_wanted: u32,
    /// 1 under `lock_border`: border vertices are pinned.
    pub lock_border: u32,
    /// 1 when this round trims its winners so the face count lands on the target.
    pub trim: u32,
    pub cos_max_angle: f32,
    pub min_quality: f32,
    pub quality_threshold: f32,
    pub border_weight: f32,
    /// Largest allowed squared collapse error (relative to the diagonal); f32::MAX if none.
    pub max_error2: f32,
    /// The appearance channels the rounds carry ([`attr_layout`]): 0 for none.
    pub attributes: u32,
    /// The colour channels' weight: a solved colour is clamped to `0..color_weight`, the
    /// weighted value of 0..1.
    pub color_weight: f32,
    /// Groups with a target of their own (the cluster DAG's level: one run for all its
    /// groups), 0 for one target over the mesh. Grouped rounds never trim, and stop when no
    /// group is over its target.
    pub groups: u32,
}

/// [`Params::attributes`]: `m` channels in all (bits 0-3), the first `colors` of them a colour
/// (bits 4-7), then two UV channels when bit 8 is set, then the normal's three. Twin of
/// `attr_*` in shaders/rounds/attributes.inc.wgsl.
pub mod attr_layout {
    pub fn pack(m: u32, colors: u32, uv: bool) -> u32 {
        m | (colors << 4) | ((uv as u32) << 8)
    }
    pub fn channels(a: u32) -> u32 {
        a & 0xf
    }
    pub fn colors(a: u32) -> u32 {
        (a >> 4) & 0xf
    }
    pub fn uv(a: u32) -> bool {
        (a >> 8) & 1 != 0
    }
}

/// Prefix-sum size, a uniform (one buffer per scan site). Keep in sync with shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ScanParams {
    /// Elements scanned; the buffer holds `n + 1`, the total lands at index `n`.
    pub n: u32,
    pub _pad: [u32; 3],
}

/// Round counters, atomics on the GPU. Keep in sync with `Counters` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct Counters {
    /// Edges with a placement under the maximum error (`edge_errors`), less those `edge_costs`
    /// found a flip or needle in: the valid edges under the maximum error when every edge
    /// competes (an INVALID_COST ceiling), an upper bound of them otherwise.
    pub candidates: u32,
    /// Edges refused because their error exceeds the maximum (`edge_errors`; their moved faces
    /// are not checked).
    pub over_max_error: u32,
    /// Error bits below which candidates compete (from `cost_ceiling`, on the errors).
    pub ceiling: u32,
    /// Winners confirmed by `validate`, summed over the passes.
    pub winners: u32,
    /// Faces the winners remove (before trimming).
    pub removed: u32,
    /// Largest squared error of a winner, as f32 bits (non-negative floats order as integers).
    pub max_err2_bits: u32,
    /// Trimming: winners above this bin lose; within it, by edge id up to `trim_budget`.
    pub trim_bin: u32,
    pub trim_budget: u32,
    /// Vertex and face counts after compaction (copied from the prefix sums' totals).
    pub vertices_out: u32,
    pub faces_out: u32,
    /// Tentative winners listed by `select_win` in this pass (reset before each pass).
    pub tentative: u32,
    /// Candidates under the ceiling, listed by `live_list` for the per-candidate stages.
    pub live: u32,
    /// Grouped rounds: the groups still over their target after the round (`group_open`)...
    pub open_groups: u32,
    /// ...the faces they have over it, the next round's `needed_faces`...
    pub open_excess: u32,
    /// ...and all their faces, of which the ceiling lets a share compete.
    pub open_faces: u32,
    pub _pad: [u32; 1],
}

/// What the rounds' planner (`plan_round`) keeps between the rounds of a batch: the mesh's
/// counts after the last round it accepted, the target, whether the batch has stopped, and how
/// many of its rounds ran. Keep in sync with `PlanState` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct PlanState {
    pub vertices: u32,
    pub faces: u32,
    pub target_faces: u32,
    /// 1 once a round removed nothing, grew the mesh or reached the target: every later pass
    /// of the batch dispatches no workgroup.
    pub stopped: u32,
    /// Rounds of the batch that ran (the first always does).
    pub executed: u32,
    /// The device's workgroups per dimension: a grid past it is split over y.
    pub max_groups: u32,
    pub _pad: [u32; 2],
}

/// Slots of [`Planned::grids`]: the indirect grids of the stages a planned round runs over
/// a count. Keep in sync with the `GRID_*` constants in shaders/common.inc.wgsl.
pub mod grid_slot {
    pub const VERTICES: usize = 0;
    pub const FACES: usize = 1;
    pub const EDGE_SLOTS: usize = 2;
    pub const VERTICES_OR_FACES: usize = 3;
    /// `SCAN_VERTICES + i`: a prefix sum's blocks over the count `i` (vertices, faces, slots).
    pub const SCAN_VERTICES: usize = 4;
    pub const ONE: usize = 7;
    /// The trim's grids: over the edge slots, the blocks of their prefix sum, one workgroup;
    /// all zero in a round that does not trim.
    pub const TRIM_EDGE_SLOTS: usize = 8;
    pub const TRIM_SCAN: usize = 9;
    pub const TRIM_ONE: usize = 10;
    pub const COUNT: usize = 11;
}

/// The next round as `plan_round` writes it: its parameters and prefix-sum counts (copied into
/// the uniforms the stages bind) and its indirect grids ([`grid_slot`]; all zero once the batch
/// has stopped). Keep in sync with `Planned` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Planned {
    pub params: Params,
    /// Prefix sums over the vertices, the faces and the edge slots.
    pub scans: [ScanParams; 3],
    pub grids: [[u32; 4]; grid_slot::COUNT],
}

/// A vertex's quadric in f32, relative to the vertex's own position: `E(y) = yᵀAy + 2bᵀy + c`
/// with `y = x - position`. Keeping the origin at the vertex keeps `c` and `b` small, so f32
/// does not lose the tiny errors of a million-triangle scan to cancellation.
/// Layout `[a00 a01 a02 a11] [a12 a22 b0 b1] [b2 c weight 0]`.
/// Keep in sync with `Quadric` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct Quadric {
    pub q: [[f32; 4]; 3],
}

/// The best collapse of one edge. Keep in sync with `EdgeCandidate` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct EdgeCandidate {
    /// New position (xyz) and squared error relative to the diagonal (w).
    pub pos: [f32; 4],
    pub keep: u32,
    pub remove: u32,
    /// f32 bits of the quadric error from `edge_errors`, raised to the full priority (error
    /// scaled by triangle quality) by `edge_costs` under the ceiling; INVALID_COST if invalid.
    pub cost_bits: u32,
    /// Faces on the edge, 1 (border) or 2, what the collapse removes; set by `validate`.
    pub faces: u32,
}

impl EdgeCandidate {
    /// What an edge that may not collapse holds.
    pub const INVALID: EdgeCandidate = EdgeCandidate {
        pos: [0.0; 4],
        keep: 0,
        remove: 0,
        cost_bits: INVALID_COST,
        faces: 0,
    };
}

/// No attribute vertex, in the seam rules' attribute maps: (from, to) pairs for the removed
/// vertex's corners when the survivor is a seam vertex, `[NO_ATTR, to, NO_ATTR, NO_ATTR]` for a
/// free vertex moving onto the seam (all its corners take `to`), `[from₁, to₁, from₂, to₂]` for
/// a seam vertex sliding along its seam (one pair per side). `edge_errors` checks that the map
/// exists, `collapse` makes it again from the faces on the edge (locked and unchanged in
/// between): 16 more bytes per candidate would put the 1M scan's candidate buffer over
/// lavapipe's 128 MiB binding limit.
pub const NO_ATTR: u32 = u32::MAX;

/// Per-face data carried through compaction alongside the indices: the attribute vertex of
/// each corner (for seam corners) and the face's index in the input (materials, groups).
/// Keep in sync with `FaceExtra` in shaders/common.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct FaceExtra {
    pub attr: [u32; 3],
    pub origin: u32,
}

/// Indexed indirect draw arguments, as wgpu's `DrawIndexedIndirectArgs`, written by
/// `draw_args` so a renderer draws the current mesh without reading its size back. First index
/// and base vertex stay 0, so the first four words also serve a non-indexed indirect draw of
/// one invocation per corner (the viewer's vertex pulling).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct DrawArgs {
    pub index_count: u32,
    pub instance_count: u32,
    pub first_index: u32,
    pub base_vertex: i32,
    pub first_instance: u32,
}

/// Keys one workgroup of the radix sort takes (256 threads × 4 contiguous keys). Keep in sync
/// with `SORT_BLOCK` in shaders/cluster/cluster.inc.wgsl.
pub const SORT_BLOCK: u32 = WG * 4;

/// Which candidate placed a cluster's vertex (`ClusterPlaced::how`), as
/// `crate::cluster::stages::Placement`. Keep in sync with the `PLACE_*` constants in
/// shaders/cluster/cluster.inc.wgsl.
pub mod place {
    pub const SINGLE: u32 = 0;
    pub const SOLVE: u32 = 1;
    pub const MEMBER: u32 = 2;
    pub const CENTROID: u32 = 3;
}

/// The clustering stages' constants, a uniform. Keep in sync with `ClusterParams` in
/// shaders/cluster/cluster.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ClusterParams {
    /// The grid's corner (xyz) and cell size (w).
    pub lo_h: [f32; 4],
    /// Cells an axis (xyz); w unused.
    pub dims: [u32; 4],
    pub vertex_count: u32,
    pub face_count: u32,
    /// One over the cell size: cells are found by multiplying (see `Grid::inv_h`).
    pub inv_h: f32,
    pub _pad: u32,
}

/// One pass of the radix sort, a uniform (one buffer per pass, so a build records every pass
/// in one command buffer). Keep in sync with `RadixParams` in shaders/cluster/cluster.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct RadixParams {
    /// Keys sorted.
    pub n: u32,
    /// Blocks of [`SORT_BLOCK`] keys: `n.div_ceil(SORT_BLOCK)`.
    pub blocks: u32,
    /// Bit of the pass's 8-bit digit: 8 × pass.
    pub shift: u32,
    pub _pad: u32,
}

/// The preparation on the device (`crate::rounds::prepare`), a uniform. Keep in sync with
/// `PrepParams` in shaders/rounds/prepare.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct PrepParams {
    /// Input vertices and faces.
    pub vertex_count: u32,
    pub face_count: u32,
    /// Slots of the weld's hash table less one (a power of two, at least twice the vertices).
    pub table_mask: u32,
    pub _pad: u32,
    /// The Morton grid over the box: its low corner (xyz) and its longest side (w), as
    /// `mesh::morton::grid_codes` takes them.
    pub grid: [f32; 4],
    /// The frame: the box's centre (xyz) and one over its diagonal (w).
    pub frame: [f64; 4],
}

/// What the preparation on the device counted, read back once (`PrepCounts` words in the
/// shaders, which bind it as an array of atomics).
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct PrepCounts {
    /// Faces with three distinct classes.
    pub kept: u32,
    pub _pad: [u32; 3],
}

/// A cluster's vertex as `cluster_quadrics` writes it (its quadric, relative to `pos`, goes to
/// a buffer of [`Quadric`] beside). Keep in sync with `ClusterPlaced` in shaders/cluster/cluster.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct ClusterPlaced {
    /// Position (xyz) in the normalized frame; w is 0.
    pub pos: [f32; 4],
    /// The member whose attributes the vertex takes.
    pub attr: u32,
    /// One of [`place`].
    pub how: u32,
    pub _pad: [u32; 2],
}

/// The floating cells' constants, a uniform (one buffer per round slot, so a batch of rounds is
/// recorded in one command buffer). Keep in sync with `FloatParams` in shaders/cluster/floating.inc.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct FloatParams {
    /// The nominal radius; each centre's is spread about it (`cluster::floating::radius`).
    pub r: f32,
    /// The counter of unclaimed vertices `fc_decide` adds to: the round's place in its batch.
    pub slot: u32,
    pub _pad: [u32; 2],
}

/// A DAG cut's camera (`crate::dag::cut`), a uniform. Keep in sync with `CutParams` in
/// shaders/dag/dag_cut.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct CutParams {
    /// The eye (w unused).
    pub eye: [f32; 4],
    /// The view frustum's planes, inside where `n·p + w >= 0`.
    pub planes: [[f32; 4]; 6],
    /// Pixels per unit of error at unit distance, over the threshold in pixels.
    pub scale: f32,
    pub clusters: u32,
    /// 1: clusters outside the frustum are not drawn.
    pub cull: u32,
    /// 1: each draw's first instance is its cluster, its level in the top 8 bits (when the
    /// device reads indirect first instances); 0 otherwise.
    pub number: u32,
}

/// A DAG's cluster as the cut reads it: its spheres and errors, its group's, its triangles.
/// Keep in sync with `CutCluster` in shaders/dag/dag_cut.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Pod, Zeroable)]
pub struct CutCluster {
    pub lod_sphere: [f32; 4],
    pub bounds: [f32; 4],
    /// The sphere of the group that simplifies it (unused for a root).
    pub group_sphere: [f32; 4],
    pub error: f32,
    pub group_error: f32,
    pub first_triangle: u32,
    pub triangle_count: u32,
    /// 1 for a root.
    pub root: u32,
    pub depth: u32,
    pub _pad: [u32; 2],
}

/// A non-indexed indirect draw over the corners of `vertex_count / 3` triangles from corner
/// `first_vertex` (wgpu's `DrawIndirectArgs`; the viewer's vertex shader pulls each corner's
/// vertex). Keep in sync with `CornerDraw` in shaders/dag/dag_cut.wgsl.
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct CornerDraw {
    pub vertex_count: u32,
    pub instance_count: u32,
    pub first_vertex: u32,
    pub first_instance: u32,
}
