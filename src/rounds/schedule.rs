//! The round, described once: every stage's entry point, its bindings by their WGSL variable names
//! in binding order (uniform params first, then read-only, then read_write buffers), the buffer
//! each binding takes and the grid it runs over; and the order the stages run in ([`ROUND`]). The
//! GPU runner ([`crate::rounds::gpu::GpuRounds`]) binds and dispatches from these descriptions and
//! the CPU twin ([`crate::rounds::cpu::CpuRounds`]) steps through the same list, so the two cannot
//! drift apart; a test reads every shader with naga and checks each description's bindings (names,
//! order, access) against the WGSL, so two swapped buffers fail `cargo test`.

use crate::compute::types::Params;

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
    /// Per attribute vertex of the welded input: its weighted appearance values
    /// ([`crate::compute::types::attr_layout`]); never compacted, the faces' corners index it.
    AttrValues,
    /// Per attribute vertex: its attribute sums `G`, `D`, `W` relative to its vertex.
    AttrSums,
    /// The planner's state between the rounds of a batch ([`crate::compute::types::PlanState`]).
    Plan,
    /// The next round as the planner wrote it ([`crate::compute::types::Planned`]): copied
    /// into `Params` and the scans' counts, and the indirect grids of a planned round.
    Planned,
    /// Grouped rounds ([`Params::groups`]), a word each when there are none (bound, never
    /// read). Per input face (`FaceExtra::origin`): its group; never compacted.
    FaceGroup,
    /// Per group: the faces it is to keep at most.
    GroupTarget,
    /// Per group: its faces after the round (`group_faces`), zero again once `group_open`
    /// has read them.
    GroupCount,
    /// Per group: 1 once it has reached its target.
    GroupClosed,
    /// Per group: the largest squared error of its collapses, as f32 bits.
    GroupErr,
}

/// A count a prefix sum runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
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
    /// A single workgroup in every round, also past a batch's stop: the planner's.
    Planner,
    /// From the `dispatch` buffer `dispatch_args` writes: one per edge...
    PerEdge,
    /// ...one per tentative winner of the selection pass...
    PerTentative,
    /// ...one per candidate on the live list...
    PerLive,
    /// ...and one per edge when the round trims, none otherwise.
    PerEdgeTrim,
}

impl Grid {
    /// Byte offset of an indirect grid in the `dispatch` buffer (four `(x, y, z, _)` grids).
    pub fn indirect_offset(self) -> Option<u64> {
        match self {
            Grid::PerEdge => Some(0),
            Grid::PerTentative => Some(16),
            Grid::PerLive => Some(32),
            Grid::PerEdgeTrim => Some(48),
            _ => None,
        }
    }
}

/// A stage of the rounds: a WGSL entry point in `shaders/<shader>.wgsl`, the twin of the CPU
/// function of the same name in `src/rounds/cpu/`.
pub type Stage = crate::compute::schedule::Stage<Buf, Grid>;
pub use crate::compute::schedule::{Access, Binding};

use Count::{EdgeSlots, Faces, Vertices};
use Grid::{Each, One, PerEdge, PerEdgeTrim, PerLive, PerTentative, VerticesOrFaces};

// The prefix sum, the vertex→face lists and the face planes: written once for every family.
crate::compute::schedule::shared_stages!(Stage, Step, Buf, Grid, Count);

pub static VERTEX_FLAGS: Stage = crate::stage!(Buf; vertex_flags in "rounds/vertex_flags" over Each(Vertices);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, flags: ReadWrite Flags);
pub static VERTEX_QUADRICS: Stage = crate::stage!(Buf; vertex_quadrics in "rounds/vertex_quadrics" over Each(Vertices);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    face_extra: Read FaceExtra, quadrics: ReadWrite Quadrics);

pub static VERTEX_ATTRIBUTES: Stage = crate::stage!(Buf; vertex_attributes in "rounds/vertex_attributes" over Each(Vertices);
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    face_extra: Read FaceExtra, attr_values: Read AttrValues, quadrics: ReadWrite Quadrics,
    attr_sums: ReadWrite AttrSums);

pub static EDGES_COUNT: Stage = crate::stage!(Buf; edges_count in "rounds/edges_count" over Each(Vertices);
    params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, edge_counts: ReadWrite EdgeOffsets, remap: ReadWrite Remap,
    neighbours: ReadWrite Neighbours);
pub static EDGES_FILL: Stage = crate::stage!(Buf; edges_fill in "rounds/edges_fill" over Each(Vertices);
    params: Uniform Params, offsets: Read Offsets, neighbours: Read Neighbours,
    edge_offsets: Read EdgeOffsets, edges: ReadWrite Edges);
pub static DISPATCH_ARGS: Stage = crate::stage!(Buf; dispatch_args in "rounds/dispatch_args" over One;
    params: Uniform Params, edge_offsets: Read EdgeOffsets, counters: Read Counters,
    args: ReadWrite Dispatch);

pub static EDGE_ERRORS: Stage = crate::stage!(Buf; edge_errors in "rounds/edge_errors" over PerEdge;
    params: Uniform Params, positions: Read Positions, quadrics: Read Quadrics, flags: Read Flags,
    indices: Read Indices, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    edges: Read Edges, edge_offsets: Read EdgeOffsets, face_extra: Read FaceExtra,
    vertex_attr: Read VertexAttr, attr_values: Read AttrValues, attr_sums: Read AttrSums,
    candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    histogram: ReadWrite Histogram, counters: ReadWrite Counters);
pub static COST_CEILING: Stage = crate::stage!(Buf; cost_ceiling in "rounds/cost_ceiling" over One;
    params: Uniform Params, histogram: Read Histogram, counters: ReadWrite Counters);
pub static LIVE_LIST: Stage = crate::stage!(Buf; live_list in "rounds/live_list" over PerEdge;
    params: Uniform Params, edge_offsets: Read EdgeOffsets, candidates: Read Candidates,
    edge_state: ReadWrite EdgeState, counters: ReadWrite Counters, live: ReadWrite Live);
pub static EDGE_COSTS: Stage = crate::stage!(Buf; edge_costs in "rounds/edge_costs" over PerLive;
    params: Uniform Params, positions: Read Positions, indices: Read Indices,
    offsets: Read Offsets, vertex_faces: Read VertexFaces, face_normals: Read FaceNormals,
    live: Read Live, candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    counters: ReadWrite Counters);

pub static SELECT_COST: Stage = crate::stage!(Buf; select_cost in "rounds/select_cost" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    candidates: Read Candidates, vertex_lock: Read VertexLock, counters: Read Counters,
    edge_state: ReadWrite EdgeState, face_best: ReadWrite FaceBest);
pub static SELECT_ID: Stage = crate::stage!(Buf; select_id in "rounds/select_id" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    candidates: Read Candidates, face_best: Read FaceBest, counters: Read Counters,
    edge_state: ReadWrite EdgeState, face_id: ReadWrite FaceId);
pub static SELECT_WIN: Stage = crate::stage!(Buf; select_win in "rounds/select_win" over PerLive;
    offsets: Read Offsets, vertex_faces: Read VertexFaces, edges: Read Edges, live: Read Live,
    face_id: Read FaceId, edge_state: ReadWrite EdgeState, tentative: ReadWrite Tentative,
    counters: ReadWrite Counters);
pub static VALIDATE: Stage = crate::stage!(Buf; validate in "rounds/validate" over PerTentative;
    params: Uniform Params, flags: Read Flags, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, edges: Read Edges, tentative: Read Tentative,
    candidates: ReadWrite Candidates, edge_state: ReadWrite EdgeState,
    vertex_lock: ReadWrite VertexLock, counters: ReadWrite Counters);

pub static TRIM_HISTOGRAM: Stage = crate::stage!(Buf; trim_histogram in "rounds/trim_histogram" over PerEdgeTrim;
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, histogram: ReadWrite TrimHistogram);
pub static TRIM_CEILING: Stage = crate::stage!(Buf; trim_ceiling in "rounds/trim_ceiling" over One;
    params: Uniform Params, histogram: Read TrimHistogram, counters: ReadWrite Counters);
pub static TRIM_MARK: Stage = crate::stage!(Buf; trim_mark in "rounds/trim_mark" over Each(EdgeSlots);
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, counters: Read Counters, marks: ReadWrite Marks);
pub static TRIM_APPLY: Stage = crate::stage!(Buf; trim_apply in "rounds/trim_apply" over PerEdgeTrim;
    params: Uniform Params, candidates: Read Candidates, marks: Read Marks,
    counters: Read Counters, edge_offsets: Read EdgeOffsets, edge_state: ReadWrite EdgeState);

pub static COLLAPSE: Stage = crate::stage!(Buf; collapse in "rounds/collapse" over PerEdge;
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, indices: Read Indices, offsets: Read Offsets,
    vertex_faces: Read VertexFaces, vertex_attr: Read VertexAttr,
    positions: ReadWrite Positions, quadrics: ReadWrite Quadrics, flags: ReadWrite Flags,
    remap: ReadWrite Remap, face_extra: ReadWrite FaceExtra, attr_values: ReadWrite AttrValues,
    attr_sums: ReadWrite AttrSums);
pub static COMPACT_MARK: Stage = crate::stage!(Buf; compact_mark in "rounds/compact_mark" over VerticesOrFaces;
    params: Uniform Params, indices: Read Indices, remap: Read Remap,
    vertex_keep: ReadWrite VertexKeep, face_keep: ReadWrite FaceKeep);
pub static COMPACT_VERTICES: Stage = crate::stage!(Buf; compact_vertices in "rounds/compact_vertices" over Each(Vertices);
    params: Uniform Params, vertex_keep: Read VertexKeep, positions: Read Positions,
    quadrics: Read Quadrics, flags: Read Flags, vertex_attr: Read VertexAttr,
    positions_out: ReadWrite PositionsOut, quadrics_out: ReadWrite QuadricsOut,
    flags_out: ReadWrite FlagsOut, vertex_attr_out: ReadWrite VertexAttrOut);
pub static COMPACT_FACES: Stage = crate::stage!(Buf; compact_faces in "rounds/compact_faces" over Each(Faces);
    params: Uniform Params, indices: Read Indices, face_normals: Read FaceNormals,
    face_extra: Read FaceExtra, remap: Read Remap, vertex_keep: Read VertexKeep,
    face_keep: Read FaceKeep, indices_out: ReadWrite IndicesOut,
    face_normals_out: ReadWrite FaceNormalsOut, face_extra_out: ReadWrite FaceExtraOut);
pub static PLAN_ROUND: Stage = crate::stage!(Buf; plan_round in "rounds/plan_round" over Grid::Planner;
    params: Uniform Params, counters: Read Counters, plan: ReadWrite Plan,
    planned: ReadWrite Planned, dispatch: ReadWrite Dispatch);
pub static GROUP_FLAGS: Stage = crate::stage!(Buf; group_flags in "rounds/group_flags" over Each(Vertices);
    params: Uniform Params, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    face_extra: Read FaceExtra, face_group: Read FaceGroup, group_closed: Read GroupClosed,
    flags: ReadWrite Flags);
pub static GROUP_ERRORS: Stage = crate::stage!(Buf; group_errors in "rounds/group_errors" over PerEdge;
    params: Uniform Params, candidates: Read Candidates, edge_state: Read EdgeState,
    edge_offsets: Read EdgeOffsets, offsets: Read Offsets, vertex_faces: Read VertexFaces,
    face_extra: Read FaceExtra, face_group: Read FaceGroup, group_err: ReadWrite GroupErr);
pub static GROUP_FACES: Stage = crate::stage!(Buf; group_faces in "rounds/group_faces" over Each(Faces);
    params: Uniform Params, face_keep: Read FaceKeep, face_extra_out: Read FaceExtraOut,
    face_group: Read FaceGroup, group_count: ReadWrite GroupCount);
pub static GROUP_OPEN: Stage = crate::stage!(Buf; group_open in "rounds/group_open" over One;
    params: Uniform Params, group_target: Read GroupTarget, group_count: ReadWrite GroupCount,
    group_closed: ReadWrite GroupClosed, counters: ReadWrite Counters);
pub static DRAW_ARGS: Stage = crate::stage!(Buf; draw_args in "rounds/draw_args" over One;
    params: Uniform Params, vertex_keep: Read VertexKeep, face_keep: Read FaceKeep,
    counters: ReadWrite Counters, draw: ReadWrite DrawArgs);

/// Every stage, each once: the GPU makes one pipeline per entry, the test checks each against
/// its shader.
pub const STAGES: &[&[&Stage]] = &[SHARED_STAGES, OWN_STAGES];
/// The family's own stages.
const OWN_STAGES: &[&Stage] = &[
    &VERTEX_FLAGS,
    &VERTEX_QUADRICS,
    &VERTEX_ATTRIBUTES,
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
    &PLAN_ROUND,
    &GROUP_FLAGS,
    &GROUP_ERRORS,
    &GROUP_FACES,
    &GROUP_OPEN,
];

/// The rounds' own steps, beside the core's ([`crate::compute::schedule::Step`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RoundStep {
    /// Zero `Counters::tentative`: the list `select_win` fills is per selection pass.
    ClearTentative,
    /// The CPU twin's check that no two winners reach one face, before `collapse` writes through
    /// unsynchronised slices on that promise (`cpu::select::shared_face`); nothing on the GPU.
    CheckWinners,
    /// The planner's round into the uniforms the stages bind: `Planned::params` into `Params`,
    /// its scan counts into the prefix sums'.
    ApplyPlan,
}

/// One step of a round.
pub type Step = crate::compute::schedule::Step<Buf, Grid, Count, RoundStep>;

/// When a part of the round runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum When {
    Always,
    /// The first round only: face planes and flags of the input.
    FirstRound,
    /// The first round, unless the face planes and quadrics were carried in (the hybrid
    /// method's clustering hands over each cluster's quadric of the original surface, and
    /// each face's normal of the original face under it).
    FirstRoundQuadrics,
    /// The first round, when the rounds carry appearance channels (`Params::attributes`):
    /// after the quadrics, computed or carried in, since it adds to them.
    FirstRoundAttributes,
    /// Repeated as the round's [`crate::rounds::Selection`] says.
    EachSelectionPass,
    /// When the round trims its winners to land on the target (`Params::trim`); in a round
    /// planned on the device, always, over the planner's trim grids (all zero unless it trims).
    Trimming,
    /// Before a round the device planned from the last one's counters: not the first of its
    /// batch. The CPU twin plans between rounds on the host ([`crate::rounds::cpu::CpuRounds`]
    /// runs `plan_round` there).
    Planned,
    /// In every round of grouped rounds ([`Params::groups`] above 0).
    Grouped,
}

use crate::compute::schedule::Step::{Clear, Own, PrefixSum, Run};

/// The round planned from the last one's counters (before they are cleared).
pub const PLAN: &[Step] = &[Run(&PLAN_ROUND), Own(RoundStep::ApplyPlan)];
/// The first round's set-up.
pub const SETUP: &[Step] = &[Run(&VERTEX_FLAGS)];
/// The input's face planes and vertex quadrics.
pub const SETUP_QUADRICS: &[Step] = &[Run(&FACE_PLANES), Run(&VERTEX_QUADRICS)];
/// The input's attribute quadrics (Hoppe 1999) on top of them.
pub const SETUP_ATTRIBUTES: &[Step] = &[Run(&VERTEX_ATTRIBUTES)];
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
    Own(RoundStep::ClearTentative),
    Run(&SELECT_COST),
    Run(&SELECT_ID),
    Run(&SELECT_WIN),
    Run(&DISPATCH_ARGS),
    Run(&VALIDATE),
];
pub const CHECK: &[Step] = &[Own(RoundStep::CheckWinners)];
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
/// Grouped rounds: the free vertices of the groups at their target are closed to collapses.
pub const GROUP_START: &[Step] = &[Run(&GROUP_FLAGS)];
/// Grouped rounds: each group's largest collapse error, before the collapses.
pub const GROUP_ERRORS_PART: &[Step] = &[Run(&GROUP_ERRORS)];
/// Grouped rounds: each group's faces after compaction, which groups are still open and the
/// faces they are over, for the next round's plan.
pub const GROUP_COUNT: &[Step] = &[Run(&GROUP_FACES), Run(&GROUP_OPEN)];
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

impl When {
    /// Whether a part runs once in the round of `p`: the `first` round, quadrics `carried` in.
    /// [`When::EachSelectionPass`] is the runner's to repeat and [`When::Planned`] the
    /// runner's to record in a batch; both say no here.
    pub fn runs_once(self, first: bool, carried: bool, p: &Params) -> bool {
        match self {
            When::Always => true,
            When::FirstRound => first,
            When::FirstRoundQuadrics => first && !carried,
            When::FirstRoundAttributes => first && p.attributes != 0,
            When::Trimming => p.trim != 0,
            When::Grouped => p.groups != 0,
            When::EachSelectionPass | When::Planned => false,
        }
    }
}

/// A round, in order (after the counters are zeroed); the halves swap after it.
pub const ROUND: &[(When, &[Step])] = &[
    (When::Planned, PLAN),
    (When::Always, ADJACENCY),
    (When::FirstRound, SETUP),
    (When::FirstRoundQuadrics, SETUP_QUADRICS),
    (When::FirstRoundAttributes, SETUP_ATTRIBUTES),
    (When::Grouped, GROUP_START),
    (When::Always, EDGES),
    (When::Always, ERRORS),
    (When::Always, CEILING),
    (When::Always, LISTED_COSTS),
    (When::Always, UNLOCK),
    (When::EachSelectionPass, SELECTION_PASS),
    (When::Always, CHECK),
    (When::Trimming, TRIM),
    (When::Grouped, GROUP_ERRORS_PART),
    (When::Always, APPLY),
    (When::Grouped, GROUP_COUNT),
];

/// The rounds' schedule against its WGSL, with the checks every family passes
/// (`compute::tests`); a binding's variable names its buffer (`Buf::EdgeState` is `edge_state`)
/// but for the few a stage calls by its own role, listed here.
#[cfg(test)]
pub(crate) fn check_schedule() {
    const ROLES: &[(&str, Buf)] = &[
        ("counts", Buf::Offsets),
        ("edge_counts", Buf::EdgeOffsets),
        ("args", Buf::Dispatch),
        ("draw", Buf::DrawArgs),
        ("histogram", Buf::TrimHistogram),
        ("scan", Buf::ScanCount),
        ("data", Buf::ScanData),
    ];
    let parts: Vec<&[Step]> = ROUND.iter().map(|(_, steps)| *steps).collect();
    crate::compute::schedule::check::family("rounds", STAGES, ROLES, &parts);
}
