//! The DAG's cut on the GPU, described as every family's stages are
//! ([`crate::compute::schedule`]): one stage, `dag_cut`, run once per frame over the clusters,
//! writing each cluster's indirect draw; its CPU twin is [`super::cut::dag_cut`], and
//! `compute::tests` checks the description against its WGSL through naga.

/// A buffer of the cut.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum DagBuf {
    /// The camera's [`crate::compute::types::CutParams`] (uniform).
    Cut,
    /// Per cluster: [`crate::compute::types::CutCluster`].
    Clusters,
    /// Per cluster: its [`crate::compute::types::CornerDraw`], a renderer's indirect draws.
    Draws,
    /// Clusters in the cut, clusters drawn, triangles drawn, and a spare word.
    CutCounts,
}

/// What the cut's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DagGrid {
    /// One invocation per cluster.
    EachCluster,
}

/// A stage of the cut: a WGSL entry point in `shaders/<shader>.wgsl`, the twin of the CPU
/// function of the same name in `src/dag/`.
pub type Stage = crate::compute::schedule::Stage<DagBuf, DagGrid>;
/// A step of the cut (it scans nothing and has no steps of its own).
pub type Step = crate::compute::schedule::Step<DagBuf, DagGrid, (), ()>;

pub static DAG_CUT: Stage = crate::stage!(DagBuf; dag_cut in "dag/dag_cut" over DagGrid::EachCluster;
    cut: Uniform Cut, clusters: Read Clusters, draws: ReadWrite Draws,
    cut_counts: ReadWrite CutCounts);

/// Every stage, each once.
pub const STAGES: &[&[&Stage]] = &[&[&DAG_CUT]];

/// A frame's cut: the counts zeroed, then every cluster tested.
pub const CUT: &[Step] = &[
    crate::compute::schedule::Step::Clear(DagBuf::CutCounts),
    crate::compute::schedule::Step::Run(&DAG_CUT),
];

/// The cut's schedule against its WGSL, with the checks every family passes
/// (`compute::tests`); it has no prefix sum, which its runner relies on.
#[cfg(test)]
pub(crate) fn check_schedule() {
    crate::compute::schedule::check::family("dag cut", STAGES, &[], &[CUT]);
    assert!(
        CUT.iter()
            .all(|s| !matches!(s, crate::compute::schedule::Step::PrefixSum { .. })),
        "the cut's runner has no prefix sum"
    );
}
