//! The vocabulary every family's schedule is written in: a stage (a WGSL entry point, its
//! bindings by WGSL variable name in binding order, the buffer each takes, the grid it runs
//! over) and the steps a family's parts are lists of. A family brings its own buffer, count and
//! grid enums and its own extra steps; the stages every family runs (the prefix sum, the
//! vertex→face lists, the face planes) are written once, in [`shared_stages!`], and expanded in
//! each family's schedule on that family's buffers.

/// How a shader declares a binding.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Access {
    Uniform,
    Read,
    ReadWrite,
}

/// One binding: the WGSL variable, how it is declared, and the buffer of the family `B` bound to
/// it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Binding<B> {
    pub var: &'static str,
    pub access: Access,
    pub buf: B,
}

/// A compute stage: entry point `entry` in `shaders/<shader>.wgsl`, the twin of the CPU function
/// of the same name; its bindings on the family's buffers `B` and the grid `G` it runs over.
#[derive(Debug, PartialEq, Eq)]
pub struct Stage<B: 'static, G> {
    pub entry: &'static str,
    /// The shader's path under `shaders/` without `.wgsl` (`rounds/collapse`).
    pub shader: &'static str,
    pub bindings: &'static [Binding<B>],
    pub grid: G,
}

impl<B, G> Stage<B, G> {
    /// Storage buffers the stage binds (the device must allow as many per stage).
    pub fn storage_buffers(&self) -> usize {
        self.bindings
            .iter()
            .filter(|b| b.access != Access::Uniform)
            .count()
    }
}

/// One step of a family's part: `B` its buffers, `G` its grids, `C` the counts a prefix sum runs
/// over, `X` the steps only that family has.
#[derive(Debug, PartialEq, Eq)]
pub enum Step<B: 'static, G: 'static, C, X> {
    /// Zero a buffer (the CPU twin also sizes it).
    Clear(B),
    Run(&'static Stage<B, G>),
    /// Exclusive prefix sum of `data` over `count` values, the total at index `count`: the three
    /// `prefix_sum_*` stages with the family's scan buffers bound to these.
    PrefixSum {
        count: C,
        data: B,
    },
    /// The whole of one buffer into another (as much as the smaller holds).
    CopyBuffer(B, B),
    /// A step of the family's own.
    Own(X),
}

// `Step` holds only `Copy` parts; derive would ask it of the stage's grid type through the
// reference too, which the families' grids are anyway.
impl<B: Copy, G, C: Copy, X: Copy> Clone for Step<B, G, C, X> {
    fn clone(&self) -> Self {
        *self
    }
}
impl<B: Copy, G, C: Copy, X: Copy> Copy for Step<B, G, C, X> {}

/// `stage!(Buf; entry in "shader" over grid; var: access Variant, ...)`: a stage whose bindings
/// take the variants of the family's buffer enum `Buf`, in binding order. A binding's name is
/// the WGSL variable's, its buffer the one the runners bind.
#[macro_export]
#[doc(hidden)]
macro_rules! stage {
    ($b:ident; $entry:ident in $shader:literal over $grid:expr;
     $($var:ident: $access:ident $buf:ident),* $(,)?) => {
        $crate::compute::schedule::Stage {
            entry: stringify!($entry),
            shader: $shader,
            bindings: &[$($crate::compute::schedule::Binding {
                var: stringify!($var),
                access: $crate::compute::schedule::Access::$access,
                buf: $b::$buf,
            }),*],
            grid: $grid,
        }
    };
}
pub use crate::stage;

/// The stages every family runs, written once: expanded in a family's schedule with its stage
/// type, buffer enum and grid and count enums, whose variants must include the names used here
/// (`Params`, `ScanCount`, `ScanData`, `BlockSums`, `Positions`, `Indices`, `Offsets`, `Cursor`,
/// `VertexFaces`, `FaceNormals`; grids `Each`, `ScanBlocks`, `One`; counts `Vertices`, `Faces`).
/// It defines the `PREFIX_SUM_*`, `ADJACENCY_*` and `FACE_PLANES` stages, their list
/// `SHARED_STAGES`, and the `ADJACENCY` part (the vertex→face lists: counts, prefix sum, fill,
/// sort).
#[macro_export]
#[doc(hidden)]
macro_rules! shared_stages {
    ($stage:ty, $step:ty, $b:ident, $g:ident, $c:ident) => {
        pub static PREFIX_SUM_REDUCE: $stage = $crate::compute::schedule::stage!($b;
            prefix_sum_reduce in "core/prefix_sum" over $g::ScanBlocks;
            scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
        pub static PREFIX_SUM_SPINE: $stage = $crate::compute::schedule::stage!($b;
            prefix_sum_spine in "core/prefix_sum" over $g::One;
            scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
        pub static PREFIX_SUM_APPLY: $stage = $crate::compute::schedule::stage!($b;
            prefix_sum_apply in "core/prefix_sum" over $g::ScanBlocks;
            scan: Uniform ScanCount, data: ReadWrite ScanData, block_sums: ReadWrite BlockSums);
        /// The stages every family runs, each once (a family's `STAGES` starts with these).
        pub const SHARED_STAGES: &[&$stage] = &[
            &PREFIX_SUM_REDUCE,
            &PREFIX_SUM_SPINE,
            &PREFIX_SUM_APPLY,
            &ADJACENCY_COUNT,
            &ADJACENCY_FILL,
            &ADJACENCY_SORT,
            &FACE_PLANES,
        ];
        /// The three passes of a prefix sum, in order.
        pub const PREFIX_SUM: [&$stage; 3] = [&PREFIX_SUM_REDUCE, &PREFIX_SUM_SPINE, &PREFIX_SUM_APPLY];

        pub static ADJACENCY_COUNT: $stage = $crate::compute::schedule::stage!($b;
            adjacency_count in "core/adjacency_count" over $g::Each($c::Faces);
            params: Uniform Params, indices: Read Indices, counts: ReadWrite Offsets);
        pub static ADJACENCY_FILL: $stage = $crate::compute::schedule::stage!($b;
            adjacency_fill in "core/adjacency_fill" over $g::Each($c::Faces);
            params: Uniform Params, indices: Read Indices, offsets: Read Offsets,
            cursor: ReadWrite Cursor, vertex_faces: ReadWrite VertexFaces);
        pub static ADJACENCY_SORT: $stage = $crate::compute::schedule::stage!($b;
            adjacency_sort in "core/adjacency_sort" over $g::Each($c::Vertices);
            params: Uniform Params, offsets: Read Offsets, vertex_faces: ReadWrite VertexFaces);
        pub static FACE_PLANES: $stage = $crate::compute::schedule::stage!($b;
            face_planes in "core/face_planes" over $g::Each($c::Faces);
            params: Uniform Params, positions: Read Positions, indices: Read Indices,
            face_normals: ReadWrite FaceNormals);

        /// Vertex→face lists of the current faces (CSR: counts, prefix sum, fill, sort).
        pub const ADJACENCY: &[$step] = &[
            $crate::compute::schedule::Step::Clear($b::Offsets),
            $crate::compute::schedule::Step::Clear($b::Cursor),
            $crate::compute::schedule::Step::Run(&ADJACENCY_COUNT),
            $crate::compute::schedule::Step::PrefixSum {
                count: $c::Vertices,
                data: $b::Offsets,
            },
            $crate::compute::schedule::Step::Run(&ADJACENCY_FILL),
            $crate::compute::schedule::Step::Run(&ADJACENCY_SORT),
        ];
    };
}
pub use crate::shared_stages;

/// The checks every family's schedule passes, for the one test that walks them all
/// (`compute::tests`).
#[cfg(test)]
pub(crate) mod check {
    use super::{Access, Stage, Step};

    /// The entry points `shaders/<shader>.wgsl` defines, and the bindings it declares by binding
    /// number (each variable's name and access): what every family's schedule is checked against.
    #[allow(clippy::type_complexity)]
    pub fn shader_module(
        shader: &str,
    ) -> std::result::Result<(Vec<String>, Vec<(String, Access)>), String> {
        let src = crate::compute::shaders::stage_source(shader).ok_or("no such shader file")?;
        let module = naga::front::wgsl::parse_str(&src).map_err(|e| e.message().to_string())?;
        let entries = module.entry_points.iter().map(|e| e.name.clone()).collect();
        let mut vars: Vec<(u32, String, Access)> = Vec::new();
        for (_, v) in module.global_variables.iter() {
            let Some(binding) = &v.binding else { continue };
            if binding.group != 0 {
                return Err(format!(
                    "binding group {} (every family binds group 0)",
                    binding.group
                ));
            }
            let access = match v.space {
                naga::AddressSpace::Uniform => Access::Uniform,
                naga::AddressSpace::Storage { access }
                    if access.contains(naga::StorageAccess::STORE) =>
                {
                    Access::ReadWrite
                }
                naga::AddressSpace::Storage { .. } => Access::Read,
                ref other => return Err(format!("a binding in address space {other:?}")),
            };
            vars.push((binding.binding, v.name.clone().unwrap_or_default(), access));
        }
        vars.sort_by_key(|v| v.0);
        for (i, v) in vars.iter().enumerate() {
            if v.0 != i as u32 {
                return Err(format!(
                    "bindings not numbered 0..{}: {:?}",
                    vars.len(),
                    vars
                ));
            }
        }
        Ok((
            entries,
            vars.into_iter()
                .map(|(_, name, access)| (name, access))
                .collect(),
        ))
    }

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

    /// Every stage of a family against its shader as naga reads it (the same variables in the
    /// same binding order with the same access, in the house order); each binding named after
    /// its buffer but for the `roles` a stage calls by a name of its own; each stage listed once
    /// and binding no buffer twice (WGSL would alias a read_write binding); and each running in
    /// one of the family's `parts`.
    pub fn family<B: Copy + PartialEq + std::fmt::Debug, G, C, X>(
        family: &str,
        lists: &[&[&Stage<B, G>]],
        roles: &[(&str, B)],
        parts: &[&[Step<B, G, C, X>]],
    ) {
        // A stage runs when a part names it, or, for the prefix sum's, when a part scans.
        let runs = |s: &Stage<B, G>| {
            parts.iter().flat_map(|p| p.iter()).any(|step| match step {
                Step::Run(t) => t.entry == s.entry,
                Step::PrefixSum { .. } => s.shader == "core/prefix_sum",
                _ => false,
            })
        };
        let stages: Vec<&Stage<B, G>> = lists.iter().flat_map(|l| l.iter().copied()).collect();
        for (i, stage) in stages.iter().enumerate() {
            let (entries, declared) = shader_module(stage.shader)
                .unwrap_or_else(|e| panic!("{family}: {}: {e}", stage.entry));
            assert!(
                entries.iter().any(|e| e == stage.entry),
                "{family}: shaders/{}.wgsl has no entry point {}",
                stage.shader,
                stage.entry
            );
            let described: Vec<(String, Access)> = stage
                .bindings
                .iter()
                .map(|b| (b.var.to_string(), b.access))
                .collect();
            assert_eq!(
                described, declared,
                "{family}: {}: the schedule's bindings against shaders/{}.wgsl",
                stage.entry, stage.shader
            );
            assert!(
                in_house_order(&described),
                "{family}: {}: bindings not in the order params, read-only, read_write: \
                 {described:?}",
                stage.entry
            );
            for (j, b) in stage.bindings.iter().enumerate() {
                assert!(
                    b.var == snake_case(b.buf)
                        || roles.iter().any(|r| r.0 == b.var && r.1 == b.buf),
                    "{family}: {}: binding `{}` takes {:?}",
                    stage.entry,
                    b.var,
                    b.buf
                );
                assert!(
                    stage.bindings[..j].iter().all(|c| c.buf != b.buf),
                    "{family}: {} binds {:?} twice",
                    stage.entry,
                    b.buf
                );
            }
            assert!(
                stages[..i].iter().all(|t| t.entry != stage.entry),
                "{family}: {} listed twice",
                stage.entry
            );
            assert!(runs(stage), "{family}: {} never runs", stage.entry);
        }
    }
}
