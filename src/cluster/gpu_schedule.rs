//! The clustering build on the GPU, described once as the rounds are in
//! `crate::rounds::schedule`: every stage's entry point, its bindings by WGSL variable name in
//! binding order, the buffer each takes and the grid it runs over; and the parts of a build in
//! order. The runner (`gpu.rs`) binds and dispatches from these, the CPU twins
//! (tests/cluster_twins) are named after them, and `compute::tests` checks every description
//! against its WGSL through naga. It is written in the compute core's vocabulary ([`crate::compute::schedule`]) on its
//! own buffers; the prefix sum, adjacency and face-plane stages are the core's, expanded here.
//!
//! The floating cells (`fc_*`, Low & Tan 1997) reuse the build's parts: the radix sort orders
//! the vertices by rank once per mesh, then per build into the cells of a hash grid (by cell,
//! then rank) and, after the rounds, by cluster; the cells part finds the ranges each time, and
//! the faces part is the uniform grid's.

/// A buffer of the build. The sort's keys and values come in two halves: the plain names are
/// the half a pass reads (and, after the sort, the sorted result), the `*Out` ones the half it
/// writes; the runner swaps them after each pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum ClusterBuf {
    /// [`crate::compute::types::ClusterParams`] (uniform).
    Cluster,
    /// The rounds' `Params` (uniform) with the vertex and face counts, for the adjacency stages.
    Params,
    /// The pass's [`crate::compute::types::RadixParams`] (uniform, one buffer per pass).
    Radix,
    /// A prefix sum's count (uniform `ScanParams`); which one is the [`ClusterStep::PrefixSum`]'s.
    ScanCount,
    /// The values a prefix sum scans in place.
    ScanData,
    BlockSums,
    Positions,
    Indices,
    Locked,
    SortKeys,
    SortVals,
    SortKeysOut,
    SortValsOut,
    DigitCounts,
    CellHead,
    CellStart,
    VertexCell,
    CellKey,
    Offsets,
    Cursor,
    VertexFaces,
    FaceNormals,
    ClusterPlaced,
    ClusterQuadric,
    FaceKey,
    FaceKeep,
    BucketOffsets,
    BucketCursor,
    BucketFaces,
    ClusterFaces,
    FaceOrigin,
    /// The clusters' vertices as a renderer's vertex buffer ([`crate::rounds::gpu::GpuMesh`]).
    MeshPositions,
    /// [`crate::compute::types::FloatParams`] (uniform, one buffer per round slot).
    Floating,
    FcGrade,
    FcRank,
    /// The vertices by rank, highest first: the sorted values of the rank sort, kept.
    FcOrder,
    FcCentre,
    FcDecided,
    /// 1 per centre, then scanned: the centres' numbers.
    FcHead,
    /// Per round slot of a batch: the unclaimed vertices at the round's start.
    FcLive,
}

/// A count a stage or a prefix sum runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClusterCount {
    Vertices,
    Faces,
    /// 256 digit counts per sort block.
    Digits,
}

/// What a stage's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClusterGrid {
    Each(ClusterCount),
    /// One workgroup per block of `SORT_BLOCK` keys.
    SortBlocks,
    /// One workgroup per `SCAN_BLOCK` elements of the prefix sum's count.
    ScanBlocks,
    One,
}

/// A stage of the clustering build: entry point `entry` in `shaders/<shader>.wgsl`.
pub type ClusterStage = crate::compute::schedule::Stage<ClusterBuf, ClusterGrid>;

use crate::cluster::grid::{CellGrid, SINGLETON};
use crate::compute::types::{ClusterParams, FloatParams, RadixParams, SORT_BLOCK};
use ClusterCount::{Faces, Vertices};
use ClusterGrid::{Each, SortBlocks};

// The prefix sum, the vertex→face lists and the face planes: the core's, on these buffers.
crate::compute::schedule::shared_stages!(
    ClusterStage,
    ClusterStep,
    ClusterBuf,
    ClusterGrid,
    ClusterCount
);

pub static CELL_KEYS: ClusterStage = crate::stage!(ClusterBuf; cell_keys in "cluster/cell_keys" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, locked: Read Locked,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub static RADIX_COUNT: ClusterStage = crate::stage!(ClusterBuf; radix_count in "cluster/radix_count" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, digit_counts: ReadWrite DigitCounts);
pub static RADIX_SCATTER: ClusterStage = crate::stage!(ClusterBuf; radix_scatter in "cluster/radix_scatter" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, vals: Read SortVals,
    digit_counts: Read DigitCounts, keys_out: ReadWrite SortKeysOut,
    vals_out: ReadWrite SortValsOut);
pub static CELL_HEADS: ClusterStage = crate::stage!(ClusterBuf; cell_heads in "cluster/cell_heads" over Each(Vertices);
    cluster: Uniform Cluster, sort_keys: Read SortKeys, cell_head: ReadWrite CellHead);
pub static CELL_RANGES: ClusterStage = crate::stage!(ClusterBuf; cell_ranges in "cluster/cell_ranges" over Each(Vertices);
    cluster: Uniform Cluster, cell_head: Read CellHead, sort_keys: Read SortKeys,
    sort_vals: Read SortVals, cell_start: ReadWrite CellStart,
    vertex_cell: ReadWrite VertexCell, cell_key: ReadWrite CellKey);
pub static CLUSTER_QUADRICS: ClusterStage = crate::stage!(ClusterBuf; cluster_quadrics in "cluster/cluster_quadrics" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cell_key: Read CellKey, cluster_placed: ReadWrite ClusterPlaced,
    cluster_quadric: ReadWrite ClusterQuadric);
pub static CLUSTER_FACES_MARK: ClusterStage = crate::stage!(ClusterBuf; cluster_faces_mark in "cluster/cluster_faces_mark" over Each(Faces);
    cluster: Uniform Cluster, indices: Read Indices, vertex_cell: Read VertexCell,
    face_key: ReadWrite FaceKey, face_keep: ReadWrite FaceKeep,
    bucket_counts: ReadWrite BucketOffsets);
pub static CLUSTER_FACES_FILL: ClusterStage = crate::stage!(ClusterBuf; cluster_faces_fill in "cluster/cluster_faces_fill" over Each(Faces);
    cluster: Uniform Cluster, face_key: Read FaceKey, face_keep: Read FaceKeep,
    bucket_offsets: Read BucketOffsets, bucket_cursor: ReadWrite BucketCursor,
    bucket_faces: ReadWrite BucketFaces);
pub static CLUSTER_FACES_DEDUPE: ClusterStage = crate::stage!(ClusterBuf; cluster_faces_dedupe in "cluster/cluster_faces_dedupe" over Each(Vertices);
    cluster: Uniform Cluster, face_key: Read FaceKey, bucket_offsets: Read BucketOffsets,
    bucket_faces: ReadWrite BucketFaces, face_keep: ReadWrite FaceKeep);
pub static CLUSTER_FACES_COMPACT: ClusterStage = crate::stage!(ClusterBuf; cluster_faces_compact in "cluster/cluster_faces_compact" over Each(Faces);
    cluster: Uniform Cluster, face_key: Read FaceKey, face_keep: Read FaceKeep,
    cluster_faces: ReadWrite ClusterFaces, face_origin: ReadWrite FaceOrigin);

pub static CLUSTER_MESH: ClusterStage = crate::stage!(ClusterBuf; cluster_mesh in "cluster/cluster_mesh" over Each(Vertices);
    cluster: Uniform Cluster, cell_head: Read CellHead, cluster_placed: Read ClusterPlaced,
    mesh_positions: ReadWrite MeshPositions);
pub static FC_GRADES: ClusterStage = crate::stage!(ClusterBuf; fc_grades in "cluster/fc_grades" over Each(Vertices);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, fc_grade: ReadWrite FcGrade);
pub static FC_RANKS: ClusterStage = crate::stage!(ClusterBuf; fc_ranks in "cluster/fc_ranks" over Each(Vertices);
    params: Uniform Params, fc_grade: Read FcGrade, fc_rank: ReadWrite FcRank,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub static FC_KEYS: ClusterStage = crate::stage!(ClusterBuf; fc_keys in "cluster/fc_keys" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, fc_order: Read FcOrder,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub static FC_INIT: ClusterStage = crate::stage!(ClusterBuf; fc_init in "cluster/fc_init" over Each(Vertices);
    cluster: Uniform Cluster, locked: Read Locked, fc_centre: ReadWrite FcCentre,
    fc_head: ReadWrite FcHead);
pub static FC_DECIDE: ClusterStage = crate::stage!(ClusterBuf; fc_decide in "cluster/fc_decide" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    fc_rank: Read FcRank, sort_vals: Read SortVals, cell_head: Read CellHead,
    cell_start: Read CellStart, cell_key: Read CellKey, fc_centre: Read FcCentre,
    fc_decided: ReadWrite FcDecided, fc_live: ReadWrite FcLive);
pub static FC_CLAIM: ClusterStage = crate::stage!(ClusterBuf; fc_claim in "cluster/fc_claim" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cell_key: Read CellKey, fc_decided: Read FcDecided, fc_centre: ReadWrite FcCentre,
    fc_head: ReadWrite FcHead);
pub static FC_CLUSTER_KEYS: ClusterStage = crate::stage!(ClusterBuf; fc_cluster_keys in "cluster/fc_cluster_keys" over Each(Vertices);
    cluster: Uniform Cluster, fc_centre: Read FcCentre, fc_head: Read FcHead,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub static FC_QUADRICS: ClusterStage = crate::stage!(ClusterBuf; fc_quadrics in "cluster/fc_quadrics" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    indices: Read Indices, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    face_normals: Read FaceNormals, locked: Read Locked, fc_centre: Read FcCentre,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cluster_placed: ReadWrite ClusterPlaced, cluster_quadric: ReadWrite ClusterQuadric);

/// Every stage, each once: the runner makes one pipeline per entry.
pub const STAGES: &[&[&ClusterStage]] = &[SHARED_STAGES, OWN_STAGES];
/// The family's own stages.
const OWN_STAGES: &[&ClusterStage] = &[
    &CELL_KEYS,
    &RADIX_COUNT,
    &RADIX_SCATTER,
    &CELL_HEADS,
    &CELL_RANGES,
    &CLUSTER_QUADRICS,
    &CLUSTER_FACES_MARK,
    &CLUSTER_FACES_FILL,
    &CLUSTER_FACES_DEDUPE,
    &CLUSTER_FACES_COMPACT,
    &CLUSTER_MESH,
    &FC_GRADES,
    &FC_RANKS,
    &FC_KEYS,
    &FC_INIT,
    &FC_DECIDE,
    &FC_CLAIM,
    &FC_CLUSTER_KEYS,
    &FC_QUADRICS,
];

/// One step of a build; the clustering has no steps of its own.
pub type ClusterStep =
    crate::compute::schedule::Step<ClusterBuf, ClusterGrid, ClusterCount, std::convert::Infallible>;

use crate::compute::schedule::Step::{Clear, CopyBuffer, PrefixSum, Run};

/// The face planes, once per mesh after [`ADJACENCY`] (the grid changes neither).
pub const PLANES: &[ClusterStep] = &[Run(&FACE_PLANES)];
/// Per build: each vertex's cell key.
pub const KEYS: &[ClusterStep] = &[Run(&CELL_KEYS)];
/// One radix pass (as many as the largest key needs); the halves swap after it.
pub const SORT_PASS: &[ClusterStep] = &[
    Run(&RADIX_COUNT),
    PrefixSum {
        count: ClusterCount::Digits,
        data: ClusterBuf::DigitCounts,
    },
    Run(&RADIX_SCATTER),
];
/// The cells of the sorted keys.
pub const CELLS: &[ClusterStep] = &[
    Run(&CELL_HEADS),
    PrefixSum {
        count: Vertices,
        data: ClusterBuf::CellHead,
    },
    Run(&CELL_RANGES),
];
/// One cluster per cell: its quadric and vertex.
pub const QUADRICS: &[ClusterStep] = &[Run(&CLUSTER_QUADRICS)];
/// The faces between three clusters, repeats dropped, compacted in face order.
pub const FACES: &[ClusterStep] = &[
    Clear(ClusterBuf::BucketOffsets),
    Clear(ClusterBuf::BucketCursor),
    Run(&CLUSTER_FACES_MARK),
    PrefixSum {
        count: Vertices,
        data: ClusterBuf::BucketOffsets,
    },
    Run(&CLUSTER_FACES_FILL),
    Run(&CLUSTER_FACES_DEDUPE),
    PrefixSum {
        count: Faces,
        data: ClusterBuf::FaceKeep,
    },
    Run(&CLUSTER_FACES_COMPACT),
];
/// After a build, for a renderer: the clusters' vertices beside the compacted faces.
pub const DRAWABLE: &[ClusterStep] = &[Run(&CLUSTER_MESH)];

/// Floating cells, once per mesh: each vertex's grade and rank, and the rank sort's keys; then
/// four [`SORT_PASS`]es (32-bit keys) and [`FLOATING_ORDER`].
pub const FLOATING_RANKS: &[ClusterStep] = &[Run(&FC_GRADES), Run(&FC_RANKS)];
/// The vertices by rank, kept from the rank sort (the halves are the builds' again after it).
pub const FLOATING_ORDER: &[ClusterStep] = &[CopyBuffer(ClusterBuf::SortVals, ClusterBuf::FcOrder)];
/// Per build: the hash grid's keys in rank order and every vertex unclaimed (a locked one its
/// own centre); then the [`SORT_PASS`]es and [`CELLS`].
pub const FLOATING_KEYS: &[ClusterStep] = &[Run(&FC_KEYS), Run(&FC_INIT)];
/// The start of a batch of rounds: the slots' counters cleared.
pub const FLOATING_BATCH: &[ClusterStep] = &[Clear(ClusterBuf::FcLive)];
/// One round: the new centres, then their claims.
pub const FLOATING_ROUND: &[ClusterStep] = &[Run(&FC_DECIDE), Run(&FC_CLAIM)];
/// After the rounds: centres numbered in vertex order, every vertex keyed by its cluster; then
/// the [`SORT_PASS`]es, [`CELLS`] (a cell per cluster, its members in vertex order),
/// [`FLOATING_QUADRICS`] and [`FACES`].
pub const FLOATING_CLUSTERS: &[ClusterStep] = &[
    PrefixSum {
        count: Vertices,
        data: ClusterBuf::FcHead,
    },
    Run(&FC_CLUSTER_KEYS),
];
/// One vertex per floating cell.
pub const FLOATING_QUADRICS: &[ClusterStep] = &[Run(&FC_QUADRICS)];

/// Every part of a build, for the schedule's test.
#[cfg(test)]
const PARTS: &[&[ClusterStep]] = &[
    ADJACENCY,
    PLANES,
    KEYS,
    SORT_PASS,
    CELLS,
    QUADRICS,
    FACES,
    DRAWABLE,
    FLOATING_RANKS,
    FLOATING_ORDER,
    FLOATING_KEYS,
    FLOATING_BATCH,
    FLOATING_ROUND,
    FLOATING_CLUSTERS,
    FLOATING_QUADRICS,
];

// The uniforms the runner writes (and the twins in tests/cluster_twins take).

/// The uniform of a build at `grid`.
pub fn cluster_params(grid: &CellGrid, vertices: usize, faces: usize) -> ClusterParams {
    ClusterParams {
        lo_h: [grid.lo[0], grid.lo[1], grid.lo[2], grid.h],
        dims: [grid.dims[0], grid.dims[1], grid.dims[2], 0],
        vertex_count: vertices as u32,
        face_count: faces as u32,
        inv_h: grid.inv_h,
        _pad: 0,
    }
}

/// Radix passes of 8 bits the largest possible key needs: the far corner's Morton key (Morton
/// order grows with each coordinate), or SINGLETON when a vertex is locked.
pub fn radix_passes(c: &ClusterParams, any_locked: bool) -> u32 {
    let max = if any_locked {
        SINGLETON
    } else {
        crate::mesh::morton::morton3(c.dims[0] - 1, c.dims[1] - 1, c.dims[2] - 1)
    };
    (32 - max.leading_zeros()).div_ceil(8)
}

/// The uniform of radix pass `pass` over `n` keys.
pub fn radix_params(n: usize, pass: u32) -> RadixParams {
    RadixParams {
        n: n as u32,
        blocks: (n as u32).div_ceil(SORT_BLOCK),
        shift: 8 * pass,
        _pad: 0,
    }
}

/// Rounds recorded in one batch (`FloatParams::slot` < this): the host reads back one counter
/// per round once per batch, and at most this many rounds less one run idle at the end. Horse
/// (97k faces) takes 23 rounds at 10%, so three batches, three waits for the device.
pub const ROUND_SLOTS: usize = 8;

/// The uniform of round slot `slot` at nominal radius `r`.
pub fn float_params(r: f32, slot: u32) -> FloatParams {
    FloatParams {
        r,
        slot,
        _pad: [0; 2],
    }
}

/// Radix passes of the rank sort: 32-bit rank words.
pub const RANK_PASSES: u32 = 4;

/// Radix passes of the sort by cluster: the largest cluster number is below the vertex count.
pub fn cluster_passes(vertices: usize) -> u32 {
    (32 - (vertices.max(1) as u32 - 1).leading_zeros()).div_ceil(8)
}

/// The build's schedule against its WGSL, with the checks every family passes
/// (`compute::tests`); a binding's variable names its buffer but for the roles listed here.
#[cfg(test)]
pub(crate) fn check_schedule() {
    const ROLES: &[(&str, ClusterBuf)] = &[
        ("counts", ClusterBuf::Offsets),
        ("bucket_counts", ClusterBuf::BucketOffsets),
        ("keys", ClusterBuf::SortKeys),
        ("vals", ClusterBuf::SortVals),
        ("keys_out", ClusterBuf::SortKeysOut),
        ("vals_out", ClusterBuf::SortValsOut),
        ("scan", ClusterBuf::ScanCount),
        ("data", ClusterBuf::ScanData),
    ];
    crate::compute::schedule::check::family("clustering", STAGES, ROLES, PARTS);
}
