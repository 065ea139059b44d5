//! The clustering build on the GPU, described once as the rounds are in
//! `crate::parallel::schedule`: every stage's entry point, its bindings by WGSL variable name in
//! binding order, the buffer each takes and the grid it runs over; and the parts of a build in
//! order. The runner (`gpu.rs`) binds and dispatches from these, the CPU twins (`twins.rs`) are
//! named after them, and a test checks every description against its WGSL through naga. The
//! rounds' `Buf` has no room for the sort's halves and the clusters' buffers, hence this
//! schedule of its own, with the prefix sum and adjacency stages described again on its buffers.
//!
//! The floating cells (`fc_*`, Low & Tan 1997) reuse the build's parts: the radix sort orders
//! the vertices by rank once per mesh, then per build into the cells of a hash grid (by cell,
//! then rank) and, after the rounds, by cluster; the cells part finds the ranges each time, and
//! the faces part is the uniform grid's.

use crate::parallel::schedule::Access;

/// A buffer of the build. The sort's keys and values come in two halves: the plain names are
/// the half a pass reads (and, after the sort, the sorted result), the `*Out` ones the half it
/// writes; the runner swaps them after each pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CBuf {
    /// [`crate::gpu::types::ClusterParams`] (uniform).
    Cluster,
    /// The rounds' `Params` (uniform) with the vertex and face counts, for the adjacency stages.
    Params,
    /// The pass's [`crate::gpu::types::RadixParams`] (uniform, one buffer per pass).
    Radix,
    /// A prefix sum's count (uniform `ScanParams`); which one is the [`CStep::PrefixSum`]'s.
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
    /// The clusters' vertices as a renderer's vertex buffer ([`crate::gpu::GpuMesh`]).
    MeshPositions,
    /// [`crate::gpu::types::FloatParams`] (uniform, one buffer per round slot).
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

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct CBinding {
    pub var: &'static str,
    pub access: Access,
    pub buf: CBuf,
}

/// A count a stage or a prefix sum runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CCount {
    Vertices,
    Faces,
    /// 256 digit counts per sort block.
    Digits,
}

/// What a stage's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CGrid {
    Each(CCount),
    /// One workgroup per block of `SORT_BLOCK` keys.
    SortBlocks,
    /// One workgroup per `SCAN_BLOCK` elements of the prefix sum's count.
    ScanBlocks,
    One,
}

/// A compute stage: entry point `entry` in `shaders/<shader>.wgsl`.
#[derive(Debug, PartialEq, Eq)]
pub struct CStage {
    pub entry: &'static str,
    pub shader: &'static str,
    pub bindings: &'static [CBinding],
    pub grid: CGrid,
}

/// `stage!(entry in "shader" over grid; var: access Buf, ...)`, as the rounds' schedule writes it.
macro_rules! stage {
    ($entry:ident in $shader:literal over $grid:expr; $($var:ident: $access:ident $buf:ident),* $(,)?) => {
        CStage {
            entry: stringify!($entry),
            shader: $shader,
            bindings: &[$(CBinding { var: stringify!($var), access: Access::$access, buf: CBuf::$buf }),*],
            grid: $grid,
        }
    };
}

use CCount::{Faces, Vertices};
use CGrid::{Each, One, ScanBlocks, SortBlocks};

pub const PREFIX_SUM_REDUCE: CStage = stage!(prefix_sum_reduce in "prefix_sum" over ScanBlocks;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
pub const PREFIX_SUM_SPINE: CStage = stage!(prefix_sum_spine in "prefix_sum" over One;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
pub const PREFIX_SUM_APPLY: CStage = stage!(prefix_sum_apply in "prefix_sum" over ScanBlocks;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);

pub const ADJACENCY_COUNT: CStage = stage!(adjacency_count in "adjacency_count" over Each(Faces);
    params: Uniform Params, indices: Read Indices, counts: ReadWrite Offsets);
pub const ADJACENCY_FILL: CStage = stage!(adjacency_fill in "adjacency_fill" over Each(Faces);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    cursor: ReadWrite Cursor, vertex_faces: ReadWrite VertexFaces);
pub const ADJACENCY_SORT: CStage = stage!(adjacency_sort in "adjacency_sort" over Each(Vertices);
    params: Uniform Params, offsets: Read Offsets, vertex_faces: ReadWrite VertexFaces);
pub const FACE_PLANES: CStage = stage!(face_planes in "face_planes" over Each(Faces);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    face_normals: ReadWrite FaceNormals);

pub const CELL_KEYS: CStage = stage!(cell_keys in "cell_keys" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, locked: Read Locked,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub const RADIX_COUNT: CStage = stage!(radix_count in "radix_count" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, digit_counts: ReadWrite DigitCounts);
pub const RADIX_SCATTER: CStage = stage!(radix_scatter in "radix_scatter" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, vals: Read SortVals,
    digit_counts: Read DigitCounts, keys_out: ReadWrite SortKeysOut,
    vals_out: ReadWrite SortValsOut);
pub const CELL_HEADS: CStage = stage!(cell_heads in "cell_heads" over Each(Vertices);
    cluster: Uniform Cluster, sort_keys: Read SortKeys, cell_head: ReadWrite CellHead);
pub const CELL_RANGES: CStage = stage!(cell_ranges in "cell_ranges" over Each(Vertices);
    cluster: Uniform Cluster, cell_head: Read CellHead, sort_keys: Read SortKeys,
    sort_vals: Read SortVals, cell_start: ReadWrite CellStart,
    vertex_cell: ReadWrite VertexCell, cell_key: ReadWrite CellKey);
pub const CLUSTER_QUADRICS: CStage = stage!(cluster_quadrics in "cluster_quadrics" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cell_key: Read CellKey, cluster_placed: ReadWrite ClusterPlaced,
    cluster_quadric: ReadWrite ClusterQuadric);
pub const CLUSTER_FACES_MARK: CStage = stage!(cluster_faces_mark in "cluster_faces_mark" over Each(Faces);
    cluster: Uniform Cluster, indices: Read Indices, vertex_cell: Read VertexCell,
    face_key: ReadWrite FaceKey, face_keep: ReadWrite FaceKeep,
    bucket_counts: ReadWrite BucketOffsets);
pub const CLUSTER_FACES_FILL: CStage = stage!(cluster_faces_fill in "cluster_faces_fill" over Each(Faces);
    cluster: Uniform Cluster, face_key: Read FaceKey, face_keep: Read FaceKeep,
    bucket_offsets: Read BucketOffsets, bucket_cursor: ReadWrite BucketCursor,
    bucket_faces: ReadWrite BucketFaces);
pub const CLUSTER_FACES_DEDUPE: CStage = stage!(cluster_faces_dedupe in "cluster_faces_dedupe" over Each(Vertices);
    cluster: Uniform Cluster, face_key: Read FaceKey, bucket_offsets: Read BucketOffsets,
    bucket_faces: ReadWrite BucketFaces, face_keep: ReadWrite FaceKeep);
pub const CLUSTER_FACES_COMPACT: CStage = stage!(cluster_faces_compact in "cluster_faces_compact" over Each(Faces);
    cluster: Uniform Cluster, face_key: Read FaceKey, face_keep: Read FaceKeep,
    cluster_faces: ReadWrite ClusterFaces, face_origin: ReadWrite FaceOrigin);

pub const CLUSTER_MESH: CStage = stage!(cluster_mesh in "cluster_mesh" over Each(Vertices);
    cluster: Uniform Cluster, cell_head: Read CellHead, cluster_placed: Read ClusterPlaced,
    mesh_positions: ReadWrite MeshPositions);
pub const FC_GRADES: CStage = stage!(fc_grades in "fc_grades" over Each(Vertices);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, fc_grade: ReadWrite FcGrade);
pub const FC_RANKS: CStage = stage!(fc_ranks in "fc_ranks" over Each(Vertices);
    params: Uniform Params, fc_grade: Read FcGrade, fc_rank: ReadWrite FcRank,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub const FC_KEYS: CStage = stage!(fc_keys in "fc_keys" over Each(Vertices);
    cluster: Uniform Cluster, positions: Read Positions, fc_order: Read FcOrder,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub const FC_INIT: CStage = stage!(fc_init in "fc_init" over Each(Vertices);
    cluster: Uniform Cluster, locked: Read Locked, fc_centre: ReadWrite FcCentre,
    fc_head: ReadWrite FcHead);
pub const FC_DECIDE: CStage = stage!(fc_decide in "fc_decide" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    fc_rank: Read FcRank, sort_vals: Read SortVals, cell_head: Read CellHead,
    cell_start: Read CellStart, cell_key: Read CellKey, fc_centre: Read FcCentre,
    fc_decided: ReadWrite FcDecided, fc_live: ReadWrite FcLive);
pub const FC_CLAIM: CStage = stage!(fc_claim in "fc_claim" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cell_key: Read CellKey, fc_decided: Read FcDecided, fc_centre: ReadWrite FcCentre,
    fc_head: ReadWrite FcHead);
pub const FC_CLUSTER_KEYS: CStage = stage!(fc_cluster_keys in "fc_cluster_keys" over Each(Vertices);
    cluster: Uniform Cluster, fc_centre: Read FcCentre, fc_head: Read FcHead,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub const FC_QUADRICS: CStage = stage!(fc_quadrics in "fc_quadrics" over Each(Vertices);
    cluster: Uniform Cluster, floating: Uniform Floating, positions: Read Positions,
    indices: Read Indices, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    face_normals: Read FaceNormals, locked: Read Locked, fc_centre: Read FcCentre,
    sort_vals: Read SortVals, cell_head: Read CellHead, cell_start: Read CellStart,
    cluster_placed: ReadWrite ClusterPlaced, cluster_quadric: ReadWrite ClusterQuadric);

/// Every stage, each once: the runner makes one pipeline per entry.
pub const STAGES: &[&CStage] = &[
    &PREFIX_SUM_REDUCE,
    &PREFIX_SUM_SPINE,
    &PREFIX_SUM_APPLY,
    &ADJACENCY_COUNT,
    &ADJACENCY_FILL,
    &ADJACENCY_SORT,
    &FACE_PLANES,
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

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CStep {
    Clear(CBuf),
    Run(&'static CStage),
    /// Exclusive prefix sum of `data` over `count` values, the total at index `count`.
    PrefixSum {
        count: CCount,
        data: CBuf,
    },
    /// The whole of one buffer into another of the same size.
    CopyBuffer(CBuf, CBuf),
}

use CStep::{Clear, CopyBuffer, PrefixSum, Run};

/// Once per mesh (the grid does not change them): the vertex→face lists and face planes.
pub const MESH: &[CStep] = &[
    Clear(CBuf::Offsets),
    Clear(CBuf::Cursor),
    Run(&ADJACENCY_COUNT),
    PrefixSum {
        count: Vertices,
        data: CBuf::Offsets,
    },
    Run(&ADJACENCY_FILL),
    Run(&ADJACENCY_SORT),
    Run(&FACE_PLANES),
];
/// Per build: each vertex's cell key.
pub const KEYS: &[CStep] = &[Run(&CELL_KEYS)];
/// One radix pass (as many as the largest key needs); the halves swap after it.
pub const SORT_PASS: &[CStep] = &[
    Run(&RADIX_COUNT),
    PrefixSum {
        count: CCount::Digits,
        data: CBuf::DigitCounts,
    },
    Run(&RADIX_SCATTER),
];
/// The cells of the sorted keys.
pub const CELLS: &[CStep] = &[
    Run(&CELL_HEADS),
    PrefixSum {
        count: Vertices,
        data: CBuf::CellHead,
    },
    Run(&CELL_RANGES),
];
/// One cluster per cell: its quadric and vertex.
pub const QUADRICS: &[CStep] = &[Run(&CLUSTER_QUADRICS)];
/// The faces between three clusters, repeats dropped, compacted in face order.
pub const FACES: &[CStep] = &[
    Clear(CBuf::BucketOffsets),
    Clear(CBuf::BucketCursor),
    Run(&CLUSTER_FACES_MARK),
    PrefixSum {
        count: Vertices,
        data: CBuf::BucketOffsets,
    },
    Run(&CLUSTER_FACES_FILL),
    Run(&CLUSTER_FACES_DEDUPE),
    PrefixSum {
        count: Faces,
        data: CBuf::FaceKeep,
    },
    Run(&CLUSTER_FACES_COMPACT),
];
/// After a build, for a renderer: the clusters' vertices beside the compacted faces.
pub const DRAWABLE: &[CStep] = &[Run(&CLUSTER_MESH)];

/// Floating cells, once per mesh: each vertex's grade and rank, and the rank sort's keys; then
/// four [`SORT_PASS`]es (32-bit keys) and [`FLOATING_ORDER`].
pub const FLOATING_RANKS: &[CStep] = &[Run(&FC_GRADES), Run(&FC_RANKS)];
/// The vertices by rank, kept from the rank sort (the halves are the builds' again after it).
pub const FLOATING_ORDER: &[CStep] = &[CopyBuffer(CBuf::SortVals, CBuf::FcOrder)];
/// Per build: the hash grid's keys in rank order and every vertex unclaimed (a locked one its
/// own centre); then the [`SORT_PASS`]es and [`CELLS`].
pub const FLOATING_KEYS: &[CStep] = &[Run(&FC_KEYS), Run(&FC_INIT)];
/// The start of a batch of rounds: the slots' counters cleared.
pub const FLOATING_BATCH: &[CStep] = &[Clear(CBuf::FcLive)];
/// One round: the new centres, then their claims.
pub const FLOATING_ROUND: &[CStep] = &[Run(&FC_DECIDE), Run(&FC_CLAIM)];
/// After the rounds: centres numbered in vertex order, every vertex keyed by its cluster; then
/// the [`SORT_PASS`]es, [`CELLS`] (a cell per cluster, its members in vertex order),
/// [`FLOATING_QUADRICS`] and [`FACES`].
pub const FLOATING_CLUSTERS: &[CStep] = &[
    PrefixSum {
        count: Vertices,
        data: CBuf::FcHead,
    },
    Run(&FC_CLUSTER_KEYS),
];
/// One vertex per floating cell.
pub const FLOATING_QUADRICS: &[CStep] = &[Run(&FC_QUADRICS)];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::parallel::schedule::check::{in_house_order, snake_case};

    const PARTS: &[&[CStep]] = &[
        MESH,
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

    /// Every stage's described bindings against its shader as naga reads it (names, order,
    /// access), in the house order: uniforms, then read-only, then read_write.
    #[test]
    fn every_cluster_stage_binds_what_its_shader_declares() {
        for stage in STAGES {
            let declared = crate::gpu::shaders::shader_bindings(stage.shader)
                .unwrap_or_else(|e| panic!("{}: {e}", stage.entry));
            let described: Vec<(String, Access)> = stage
                .bindings
                .iter()
                .map(|b| (b.var.to_string(), b.access))
                .collect();
            assert_eq!(
                described, declared,
                "{}: the cluster schedule's bindings against shaders/{}.wgsl",
                stage.entry, stage.shader
            );
            assert!(
                in_house_order(&described),
                "{}: bindings out of the house order: {described:?}",
                stage.entry
            );
        }
    }

    /// A binding's variable names its buffer, but for the roles listed here.
    #[test]
    fn every_cluster_binding_names_its_buffer() {
        const ROLES: &[(&str, CBuf)] = &[
            ("counts", CBuf::Offsets),
            ("bucket_counts", CBuf::BucketOffsets),
            ("keys", CBuf::SortKeys),
            ("vals", CBuf::SortVals),
            ("keys_out", CBuf::SortKeysOut),
            ("vals_out", CBuf::SortValsOut),
            ("scan", CBuf::ScanCount),
            ("data", CBuf::ScanData),
        ];

        for s in STAGES {
            for b in s.bindings {
                assert!(
                    b.var == snake_case(b.buf) || ROLES.contains(&(b.var, b.buf)),
                    "{}: binding `{}` takes {:?}",
                    s.entry,
                    b.var,
                    b.buf
                );
            }
        }
    }

    #[test]
    fn every_cluster_stage_is_listed_once_runs_and_binds_each_buffer_once() {
        for (i, s) in STAGES.iter().enumerate() {
            assert!(
                STAGES[..i].iter().all(|t| t.entry != s.entry),
                "{} listed twice",
                s.entry
            );
            let runs = PARTS.iter().any(|steps| {
                steps.iter().any(|step| match step {
                    Run(t) => t.entry == s.entry,
                    PrefixSum { .. } => s.shader == "prefix_sum",
                    Clear(_) | CopyBuffer(..) => false,
                })
            });
            assert!(runs, "{} never runs", s.entry);
            for (j, b) in s.bindings.iter().enumerate() {
                assert!(
                    s.bindings[..j].iter().all(|c| c.buf != b.buf),
                    "{} binds {:?} twice",
                    s.entry,
                    b.buf
                );
            }
        }
    }
}
