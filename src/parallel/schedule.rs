//! The round, described once: every stage's entry point, its bindings by their WGSL variable
//! names in binding order (uniform params first, then read-only, then read_write buffers), the
//! buffer each binding takes and the grid it runs over; and the order the stages run in
//! ([`ROUND`]). The GPU runner ([`crate::gpu::GpuRounds`]) binds and dispatches from these
//! descriptions and the CPU twin ([`crate::cpu::CpuRounds`]) steps through the same list, so the
//! two cannot drift apart; a test reads every shader with naga and checks each description's
//! bindings (names, order, access) against the WGSL, so two swapped buffers fail `cargo test`.

use crate::gpu::types::Params;

/// A buffer of the rounds. Per-vertex and per-face buffers come in two halves that swap each
/// round: the plain names are the half the round reads, the `*Out` ones the half compaction
/// writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Buf {
    /// The round's [`Params`] (uniform).
    Params,
    /// A prefix sum's count (uniform `ScanParams`); which one is the [`Step::PrefixSum`]'s.
    ScanCount,
    /// The values a prefix sum scans in place; which buffer is the [`Step::PrefixSum`]'s.
    ScanData,
    BlockSums,
    Positions,
    Quadrics,
    Flags,
    VertexAttr,
    Indices,
    FaceNormals,
    FaceExtra,
    PositionsOut,
    QuadricsOut,
    FlagsOut,
    VertexAttrOut,
    IndicesOut,
    FaceNormalsOut,
    FaceExtraOut,
    Offsets,
    Cursor,
    VertexFaces,
    EdgeOffsets,
    Neighbours,
    Remap,
    Edges,
    Candidates,
    EdgeState,
    Histogram,
    Live,
    VertexLock,
    FaceBest,
    FaceId,
    Tentative,
    TrimHistogram,
    Marks,
    VertexKeep,
    FaceKeep,
    Counters,
    Dispatch,
    DrawArgs,
}

/// How a shader declares a binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    Uniform,
    Read,
    ReadWrite,
}

/// One binding: the WGSL variable, how it is declared, and the buffer bound to it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Binding {
    pub var: &'static str,
    pub access: Access,
    pub buf: Buf,
}

/// A count a prefix sum runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Count {
    Vertices,
    Faces,
    /// `Params::edge_capacity`: one slot per possible edge.
    EdgeSlots,
}

impl Count {
    pub fn of(self, p: &Params) -> u32 {
        match self {
            Count::Vertices => p.vertex_count,
            Count::Faces => p.face_count,
            Count::EdgeSlots => p.edge_capacity,
        }
    }
}

/// What a stage's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Grid {
    /// One invocation per element of a count.
    Each(Count),
    /// One per vertex or per face, whichever is more.
    VerticesOrFaces,
    /// One per `SCAN_BLOCK` elements of the prefix sum's count.
    ScanBlocks,
    /// A single workgroup.
    One,
    /// From the `dispatch` buffer `dispatch_args` writes: one per edge...
    PerEdge,
    /// ...one per tentative winner of the selection pass...
    PerTentative,
    /// ...one per candidate on the live list.
    PerLive,
}

impl Grid {
    /// Byte offset of an indirect grid in the `dispatch` buffer (three `(x, y, z, _)` grids).
    pub fn indirect_offset(self) -> Option<u64> {
        match self {
            Grid::PerEdge => Some(0),
            Grid::PerTentative => Some(16),
            Grid::PerLive => Some(32),
            _ => None,
        }
    }
}

/// A compute stage: a WGSL entry point in `shaders/<shader>.wgsl`, the twin of the CPU function
/// of the same name in `src/cpu/`.
#[derive(Debug, PartialEq, Eq)]
pub struct Stage {
    pub entry: &'static str,
    /// File stem in `shaders/`.
    pub shader: &'static str,
    pub bindings: &'static [Binding],
    pub grid: Grid,
}

/// `stage!(entry in "shader" over grid; var: access Buf, ...)`: a stage with its bindings in
/// binding order. A binding's name is the WGSL variable's, its buffer the one the runners bind.
macro_rules! stage {
    ($entry:ident in $shader:literal over $grid:expr; $($var:ident: $access:ident $buf:ident),* $(,)?) => {
        Stage {
            entry: stringify!($entry),
            shader: $shader,
            bindings: &[$(Binding { var: stringify!($var), access: Access::$access, buf: Buf::$buf }),*],
            grid: $grid,
        }
    };
}

use Count::{EdgeSlots, Faces, Vertices};
use Grid::{Each, One, PerEdge, PerLive, PerTentative, ScanBlocks, VerticesOrFaces};

pub const PREFIX_SUM_REDUCE: Stage = stage!(prefix_sum_reduce in "prefix_sum" over ScanBlocks;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
pub const PREFIX_SUM_SPINE: Stage = stage!(prefix_sum_spine in "prefix_sum" over One;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
pub const PREFIX_SUM_APPLY: Stage = stage!(prefix_sum_apply in "prefix_sum" over ScanBlocks;
    scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);

pub const ADJACENCY_COUNT: Stage = stage!(adjacency_count in "adjacency_count" over Each(Faces);
    params: Uniform Params, indices: Read Indices, counts: ReadWrite Offsets);
pub const ADJACENCY_FILL: Stage = stage!(adjacency_fill in "adjacency_fill" over Each(Faces);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    cursor: ReadWrite Cursor, vertex_faces: ReadWrite VertexFaces);
pub const ADJACENCY_SORT: Stage = stage!(adjacency_sort in "adjacency_sort" over Each(Vertices);
    params: Uniform Params, offsets: Read Offsets, vertex_faces: ReadWrite VertexFaces);

pub const FACE_PLANES: Stage = stage!(face_planes in "face_planes" over Each(Faces);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    face_normals: ReadWrite FaceNormals);
pub const VERTEX_FLAGS: Stage = stage!(vertex_flags in "vertex_flags" over Each(Vertices);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, flags: ReadWrite Flags);
pub const VERTEX_QUADRICS: Stage = stage!(vertex_quadrics in "vertex_quadrics" over Each(Vertices);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    face_extra: Read FaceExtra, quadrics: ReadWrite Quadrics);

pub const EDGES_COUNT: Stage = stage!(edges_count in "edges_count" over Each(Vertices);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, edge_counts: ReadWrite EdgeOffsets, remap: ReadWrite Remap,
    neighbours: ReadWrite Neighbours);
pub const EDGES_FILL: Stage = stage!(edges_fill in "edges_fill" over Each(Vertices);
    params: Uniform Params, offsets: Read Offsets, neighbours: Read Neighbours,
    edge_offsets: Read EdgeOffsets, edges: ReadWrite Edges);
pub const DISPATCH_ARGS: Stage = stage!(dispatch_args in "dispatch_args" over One;
    params: Uniform Params, edge_offsets: Read EdgeOffsets, counters: Read Counters,
    args: ReadWrite Dispatch);

pub const EDGE_ERRORS: Stage = stage!(edge_errors in "edge_errors" over PerEdge;
    params: Uniform Params, positions: Read Positions, quadrics: Read Quadrics, flags: Read Flags,
    indices: Read Indices, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    edges: Read Edges, edge_offsets: Read EdgeOffsets, face_extra: Read FaceExtra,
    candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    histogram: ReadWrite Histogram, counters: ReadWrite Counters);
pub const COST_CEILING: Stage = stage!(cost_ceiling in "cost_ceiling" over One;
    params: Uniform Params, histogram: Read Histogram, counters: ReadWrite Counters);
pub const LIVE_LIST: Stage = stage!(live_list in "live_list" over PerEdge;
    params: Uniform Params, edge_offsets: Read EdgeOffsets, candidates: Read Candidates,
    edge_state: ReadWrite EdgeState, counters: ReadWrite Counters, live: ReadWrite Live);
pub const EDGE_COSTS: Stage = stage!(edge_costs in "edge_costs" over PerLive;
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    live: Read Live, candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    counters: ReadWrite Counters);

pub const SELECT_COST: Stage = stage!(select_cost in "select_cost" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    candidates: Read Candidates, vertex_lock: Read VertexLock, counters: Read Counters,
    edge_state: ReadWrite EdgeState, face_best: ReadWrite FaceBest);
pub const SELECT_ID: Stage = stage!(select_id in "select_id" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    candidates: Read Candidates, face_best: Read FaceBest, counters: Read Counters,
    edge_state: ReadWrite EdgeState, face_id: ReadWrite FaceId);
pub const SELECT_WIN: Stage = stage!(select_win in "select_win" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    face_id: Read FaceId, edge_state: ReadWrite EdgeState, tentative: ReadWrite Tentative,
    counters: ReadWrite Counters);
pub const VALIDATE: Stage = stage!(validate in "validate" over PerTentative;
    params: Uniform Params, flags: Read Flags, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, edges: Read Edges, tentative: Read Tentative,
    candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    vertex_lock: ReadWrite VertexLock, counters: ReadWrite Counters);

pub const TRIM_HISTOGRAM: Stage = stage!(trim_histogram in "trim_histogram" over PerEdge;
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, histogram: ReadWrite TrimHistogram);
pub const TRIM_CEILING: Stage = stage!(trim_ceiling in "trim_ceiling" over One;
    params: Uniform Params, histogram: Read TrimHistogram, counters: ReadWrite Counters);
pub const TRIM_MARK: Stage = stage!(trim_mark in "trim_mark" over Each(EdgeSlots);
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, counters: Read Counters, marks: ReadWrite Marks);
pub const TRIM_APPLY: Stage = stage!(trim_apply in "trim_apply" over PerEdge;
    params: Uniform Params, candidates: Read Candidates, marks: Read Marks,
    counters: Read Counters, edge_offsets: Read EdgeOffsets, edge_state: ReadWrite EdgeState);

pub const COLLAPSE: Stage = stage!(collapse in "collapse" over PerEdge;
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, positions: ReadWrite Positions,
    quadrics: ReadWrite Quadrics, flags: ReadWrite Flags, remap: ReadWrite Remap,
    face_extra: ReadWrite FaceExtra);
pub const COMPACT_MARK: Stage = stage!(compact_mark in "compact_mark" over VerticesOrFaces;
    params: Uniform Params, indices: Read Indices, remap: Read Remap,
    vertex_keep: ReadWrite VertexKeep, face_keep: ReadWrite FaceKeep);
pub const COMPACT_VERTICES: Stage = stage!(compact_vertices in "compact_vertices" over Each(Vertices);
    params: Uniform Params, vertex_keep: Read VertexKeep, positions: Read Positions,
    quadrics: Read Quadrics, flags: Read Flags, vertex_attr: Read VertexAttr,
    positions_out: ReadWrite PositionsOut, quadrics_out: ReadWrite QuadricsOut,
    flags_out: ReadWrite FlagsOut, vertex_attr_out: ReadWrite VertexAttrOut);
pub const COMPACT_FACES: Stage = stage!(compact_faces in "compact_faces" over Each(Faces);
    params: Uniform Params, indices: Read Indices, face_normals: Read FaceNormals,
    face_extra: Read FaceExtra, remap: Read Remap, vertex_keep: Read VertexKeep,
    face_keep: Read FaceKeep, indices_out: ReadWrite IndicesOut,
    face_normals_out: ReadWrite FaceNormalsOut, face_extra_out: ReadWrite FaceExtraOut);
pub const DRAW_ARGS: Stage = stage!(draw_args in "draw_args" over One;
    params: Uniform Params, vertex_keep: Read VertexKeep, face_keep: Read FaceKeep,
    counters: ReadWrite Counters, draw: ReadWrite DrawArgs);

/// Every stage, each once: the GPU makes one pipeline per entry, the test checks each against
/// its shader.
pub const STAGES: &[&Stage] = &[
    &PREFIX_SUM_REDUCE,
    &PREFIX_SUM_SPINE,
    &PREFIX_SUM_APPLY,
    &ADJACENCY_COUNT,
    &ADJACENCY_FILL,
    &ADJACENCY_SORT,
    &FACE_PLANES,
    &VERTEX_FLAGS,
    &VERTEX_QUADRICS,
    &EDGES_COUNT,
    &EDGES_FILL,
    &DISPATCH_ARGS,
    &EDGE_ERRORS,
    &COST_CEILING,
    &LIVE_LIST,
    &EDGE_COSTS,
    &SELECT_COST,
    &SELECT_ID,
    &SELECT_WIN,
    &VALIDATE,
    &TRIM_HISTOGRAM,
    &TRIM_CEILING,
    &TRIM_MARK,
    &TRIM_APPLY,
    &COLLAPSE,
    &COMPACT_MARK,
    &COMPACT_VERTICES,
    &COMPACT_FACES,
    &DRAW_ARGS,
];

/// One step of a round.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// Zero a buffer (the CPU also sizes it for the round).
    Clear(Buf),
    /// Zero `Counters::tentative`: the list `select_win` fills is per selection pass.
    ClearTentative,
    Run(&'static Stage),
    /// Exclusive prefix sum of `data` over `count` values, the total at index `count`: the three
    /// `prefix_sum_*` stages with [`Buf::ScanCount`] and [`Buf::ScanData`] bound to these.
    PrefixSum {
        count: Count,
        data: Buf,
    },
    /// The CPU twin's check that no two winners reach one face, before `collapse` writes through
    /// unsynchronised slices on that promise (`cpu::select::shared_face`); nothing on the GPU.
    CheckWinners,
}

/// When a part of the round runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum When {
    Always,
    /// The first round only: face planes and flags of the input.
    FirstRound,
    /// The first round, unless the quadrics were carried in (the hybrid method's clustering
    /// hands over each cluster's quadric of the original surface).
    FirstRoundQuadrics,
    /// Repeated as the round's [`crate::parallel::Selection`] says.
    EachSelectionPass,
    /// When the round trims its winners to land on the target (`Params::trim`).
    Trimming,
}

use Step::{Clear, PrefixSum, Run};

/// Vertex→face lists of the current faces (CSR: counts, prefix sum, fill, sort).
pub const ADJACENCY: &[Step] = &[
    Clear(Buf::Offsets),
    Clear(Buf::Cursor),
    Run(&ADJACENCY_COUNT),
    PrefixSum {
        count: Vertices,
        data: Buf::Offsets,
    },
    Run(&ADJACENCY_FILL),
    Run(&ADJACENCY_SORT),
];
/// The first round's set-up.
pub const SETUP: &[Step] = &[Run(&FACE_PLANES), Run(&VERTEX_FLAGS)];
/// The input's vertex quadrics.
pub const SETUP_QUADRICS: &[Step] = &[Run(&VERTEX_QUADRICS)];
/// Unique edges, and the indirect grids over them.
pub const EDGES: &[Step] = &[
    Run(&EDGES_COUNT),
    PrefixSum {
        count: Vertices,
        data: Buf::EdgeOffsets,
    },
    Run(&EDGES_FILL),
    Run(&DISPATCH_ARGS),
];
/// Placements, errors and their histogram.
pub const ERRORS: &[Step] = &[Clear(Buf::Histogram), Run(&EDGE_ERRORS)];
/// The round's cost ceiling from the histogram.
pub const CEILING: &[Step] = &[Run(&COST_CEILING)];
/// The edges under the ceiling and their costs.
pub const LISTED_COSTS: &[Step] = &[Run(&LIVE_LIST), Run(&DISPATCH_ARGS), Run(&EDGE_COSTS)];
/// Before the selection passes.
pub const UNLOCK: &[Step] = &[Clear(Buf::VertexLock)];
/// One pass of the independent-set selection.
pub const SELECTION_PASS: &[Step] = &[
    Clear(Buf::FaceBest),
    Clear(Buf::FaceId),
    Step::ClearTentative,
    Run(&SELECT_COST),
    Run(&SELECT_ID),
    Run(&SELECT_WIN),
    Run(&DISPATCH_ARGS),
    Run(&VALIDATE),
];
pub const CHECK: &[Step] = &[Step::CheckWinners];
/// Winners beyond the round's budget lose, so the round lands on its target.
pub const TRIM: &[Step] = &[
    Clear(Buf::TrimHistogram),
    Run(&TRIM_HISTOGRAM),
    Run(&TRIM_CEILING),
    Run(&TRIM_MARK),
    PrefixSum {
        count: EdgeSlots,
        data: Buf::Marks,
    },
    Run(&TRIM_APPLY),
];
/// The collapses, then compaction into the other half.
pub const APPLY: &[Step] = &[
    Run(&COLLAPSE),
    Run(&COMPACT_MARK),
    PrefixSum {
        count: Vertices,
        data: Buf::VertexKeep,
    },
    PrefixSum {
        count: Faces,
        data: Buf::FaceKeep,
    },
    Run(&COMPACT_VERTICES),
    Run(&COMPACT_FACES),
    Run(&DRAW_ARGS),
];

/// A round, in order (after the counters are zeroed); the halves swap after it.
pub const ROUND: &[(When, &[Step])] = &[
    (When::Always, ADJACENCY),
    (When::FirstRound, SETUP),
    (When::FirstRoundQuadrics, SETUP_QUADRICS),
    (When::Always, EDGES),
    (When::Always, ERRORS),
    (When::Always, CEILING),
    (When::Always, LISTED_COSTS),
    (When::Always, UNLOCK),
    (When::EachSelectionPass, SELECTION_PASS),
    (When::Always, CHECK),
    (When::Trimming, TRIM),
    (When::Always, APPLY),
];

/// Test helpers both schedules' binding tests share (the rounds' here, the clustering's in
/// `cluster::gpu_schedule`).
#[cfg(test)]
pub(crate) mod check {
    use super::Access;

    /// Whether bindings come in the house order: uniform params, then read-only, then
    /// read_write.
    pub fn in_house_order(bindings: &[(String, Access)]) -> bool {
        let rank = |a: Access| match a {
            Access::Uniform => 0,
            Access::Read => 1,
            Access::ReadWrite => 2,
        };
        bindings.windows(2).all(|w| rank(w[0].1) <= rank(w[1].1))
    }

    /// A buffer enum's variant as the variable that binds it: `EdgeState` is `edge_state`.
    pub fn snake_case(variant: impl std::fmt::Debug) -> String {
        let mut out = String::new();
        for (i, c) in format!("{variant:?}").chars().enumerate() {
            if c.is_ascii_uppercase() && i > 0 {
                out.push('_');
            }
            out.push(c.to_ascii_lowercase());
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::check::{in_house_order, snake_case};
    use super::*;

    /// Every stage's declared bindings against its shader, as naga reads it: the same variables
    /// in the same binding order with the same access; and in the house order (uniform params,
    /// then read-only, then read_write), so a reader finds a stage's outputs at its end.
    #[test]
    fn every_stage_binds_what_its_shader_declares() {
        for stage in STAGES {
            let declared = crate::gpu::shaders::declared_bindings(stage)
                .unwrap_or_else(|e| panic!("{}: {e}", stage.entry));
            let described: Vec<(String, Access)> = stage
                .bindings
                .iter()
                .map(|b| (b.var.to_string(), b.access))
                .collect();
            assert_eq!(
                described, declared,
                "{}: the schedule's bindings against shaders/{}.wgsl",
                stage.entry, stage.shader
            );
            assert!(
                in_house_order(&described),
                "{}: bindings not in the order params, read-only, read_write: {described:?}",
                stage.entry
            );
        }
    }

    /// A binding's variable names its buffer (`Buf::EdgeState` is `edge_state`) but for the
    /// few a stage calls by its own role, listed here: so `edges: Read Live` in a description,
    /// the right name on the wrong buffer, fails too.
    #[test]
    fn every_binding_names_its_buffer() {
        const ROLES: &[(&str, Buf)] = &[
            ("counts", Buf::Offsets),
            ("edge_counts", Buf::EdgeOffsets),
            ("args", Buf::Dispatch),
            ("draw", Buf::DrawArgs),
            ("histogram", Buf::TrimHistogram),
            ("scan", Buf::ScanCount),
            ("data", Buf::ScanData),
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
    fn every_stage_is_listed_once_and_runs_in_the_round() {
        for (i, s) in STAGES.iter().enumerate() {
            assert!(
                STAGES[..i].iter().all(|t| t.entry != s.entry),
                "{} listed twice",
                s.entry
            );
            let runs = ROUND.iter().any(|(_, steps)| {
                steps.iter().any(|step| match step {
                    Step::Run(t) => t.entry == s.entry,
                    Step::PrefixSum { .. } => s.shader == "prefix_sum",
                    _ => false,
                })
            });
            assert!(runs, "{} never runs in ROUND", s.entry);
        }
    }

    /// A buffer may go by a stage's own name (`offsets` is `counts` in adjacency_count), but no
    /// stage binds one buffer twice: WGSL would alias a read_write binding.
    #[test]
    fn no_stage_binds_a_buffer_twice() {
        for s in STAGES {
            for (i, b) in s.bindings.iter().enumerate() {
                assert!(
                    s.bindings[..i].iter().all(|c| c.buf != b.buf),
                    "{} binds {:?} twice",
                    s.entry,
                    b.buf
                );
            }
        }
    }
}
