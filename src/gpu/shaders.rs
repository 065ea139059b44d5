//! The WGSL stages: each file in shaders/ is one stage (prefix_sum has its three steps), compiled
//! as shaders/common.wgsl (and shaders/mesh.wgsl for stages reading the faces' CSR lists, then
//! shaders/seams.wgsl for those reading the corners' attribute vertices) followed by the stage's
//! own source. Tests parse and validate every
//! stage with naga — no GPU needed — and compare the WGSL structs with their Rust twins.

/// (file stem, source) of every stage's shader; [`crate::parallel::schedule::STAGES`] names
/// each stage's file.
pub const SOURCES: &[(&str, &str)] = &[
    ("prefix_sum", include_str!("../../shaders/prefix_sum.wgsl")),
    (
        "adjacency_count",
        include_str!("../../shaders/adjacency_count.wgsl"),
    ),
    (
        "adjacency_fill",
        include_str!("../../shaders/adjacency_fill.wgsl"),
    ),
    (
        "adjacency_sort",
        include_str!("../../shaders/adjacency_sort.wgsl"),
    ),
    (
        "face_planes",
        include_str!("../../shaders/face_planes.wgsl"),
    ),
    (
        "vertex_flags",
        include_str!("../../shaders/vertex_flags.wgsl"),
    ),
    (
        "vertex_quadrics",
        include_str!("../../shaders/vertex_quadrics.wgsl"),
    ),
    (
        "edges_count",
        include_str!("../../shaders/edges_count.wgsl"),
    ),
    ("edges_fill", include_str!("../../shaders/edges_fill.wgsl")),
    (
        "edge_errors",
        include_str!("../../shaders/edge_errors.wgsl"),
    ),
    ("live_list", include_str!("../../shaders/live_list.wgsl")),
    ("edge_costs", include_str!("../../shaders/edge_costs.wgsl")),
    (
        "cost_ceiling",
        include_str!("../../shaders/cost_ceiling.wgsl"),
    ),
    (
        "select_cost",
        include_str!("../../shaders/select_cost.wgsl"),
    ),
    ("select_id", include_str!("../../shaders/select_id.wgsl")),
    ("select_win", include_str!("../../shaders/select_win.wgsl")),
    ("validate", include_str!("../../shaders/validate.wgsl")),
    (
        "trim_histogram",
        include_str!("../../shaders/trim_histogram.wgsl"),
    ),
    (
        "trim_ceiling",
        include_str!("../../shaders/trim_ceiling.wgsl"),
    ),
    ("trim_mark", include_str!("../../shaders/trim_mark.wgsl")),
    ("trim_apply", include_str!("../../shaders/trim_apply.wgsl")),
    ("collapse", include_str!("../../shaders/collapse.wgsl")),
    (
        "compact_mark",
        include_str!("../../shaders/compact_mark.wgsl"),
    ),
    (
        "compact_vertices",
        include_str!("../../shaders/compact_vertices.wgsl"),
    ),
    (
        "compact_faces",
        include_str!("../../shaders/compact_faces.wgsl"),
    ),
    (
        "dispatch_args",
        include_str!("../../shaders/dispatch_args.wgsl"),
    ),
    ("draw_args", include_str!("../../shaders/draw_args.wgsl")),
    // The clustering build (src/cluster/gpu_schedule.rs describes these stages).
    ("cell_keys", include_str!("../../shaders/cell_keys.wgsl")),
    (
        "radix_count",
        include_str!("../../shaders/radix_count.wgsl"),
    ),
    (
        "radix_scatter",
        include_str!("../../shaders/radix_scatter.wgsl"),
    ),
    ("cell_heads", include_str!("../../shaders/cell_heads.wgsl")),
    (
        "cell_ranges",
        include_str!("../../shaders/cell_ranges.wgsl"),
    ),
    (
        "cluster_quadrics",
        include_str!("../../shaders/cluster_quadrics.wgsl"),
    ),
    (
        "cluster_faces_mark",
        include_str!("../../shaders/cluster_faces_mark.wgsl"),
    ),
    (
        "cluster_faces_fill",
        include_str!("../../shaders/cluster_faces_fill.wgsl"),
    ),
    (
        "cluster_faces_dedupe",
        include_str!("../../shaders/cluster_faces_dedupe.wgsl"),
    ),
    (
        "cluster_faces_compact",
        include_str!("../../shaders/cluster_faces_compact.wgsl"),
    ),
    (
        "cluster_mesh",
        include_str!("../../shaders/cluster_mesh.wgsl"),
    ),
    // The floating cells' build (also described in src/cluster/gpu_schedule.rs).
    ("fc_grades", include_str!("../../shaders/fc_grades.wgsl")),
    ("fc_ranks", include_str!("../../shaders/fc_ranks.wgsl")),
    ("fc_keys", include_str!("../../shaders/fc_keys.wgsl")),
    ("fc_init", include_str!("../../shaders/fc_init.wgsl")),
    ("fc_decide", include_str!("../../shaders/fc_decide.wgsl")),
    ("fc_claim", include_str!("../../shaders/fc_claim.wgsl")),
    (
        "fc_cluster_keys",
        include_str!("../../shaders/fc_cluster_keys.wgsl"),
    ),
    (
        "fc_quadrics",
        include_str!("../../shaders/fc_quadrics.wgsl"),
    ),
];

/// The source of `shaders/<stem>.wgsl`.
pub fn stage_source(stem: &str) -> Option<&'static str> {
    SOURCES.iter().find(|s| s.0 == stem).map(|s| s.1)
}

/// The most storage buffers a stage binds (edge_errors); the device must allow as many per
/// stage. A unit test counts them in every stage.
pub const MAX_STORAGE_BUFFERS: u32 = 13;

pub const COMMON: &str = include_str!("../../shaders/common.wgsl");
/// Face and CSR list accessors, for the stages that bind `indices` and `vertex_faces`.
pub const MESH: &str = include_str!("../../shaders/mesh.wgsl");
/// Corner attribute accessors, for the stages that also bind `face_extra`.
pub const SEAMS: &str = include_str!("../../shaders/seams.wgsl");
/// The clustering stages' structs and constants, for the stages that bind `ClusterParams` or
/// `RadixParams`.
pub const CLUSTER: &str = include_str!("../../shaders/cluster.wgsl");
/// The floating cells' uniform and helpers, for the stages that bind `FloatParams`.
pub const FLOATING: &str = include_str!("../../shaders/floating.wgsl");
/// The floating cells' hash-grid search, for those of them that also bind `cell_key`.
pub const FLOATING_CELLS: &str = include_str!("../../shaders/floating_cells.wgsl");
/// A cluster's gather and placement, for the stages that bind `cluster_placed`.
pub const PLACE: &str = include_str!("../../shaders/place.wgsl");

/// The full source of a stage: the common definitions, the clustering, floating-cell, mesh,
/// seam and placement helpers when the stage binds the buffers they read, then the stage.
pub fn source(stage_source: &str) -> String {
    let binds = |var: &str| {
        ["read", "read_write"]
            .iter()
            .any(|access| stage_source.contains(&format!("var<storage, {access}> {var}:")))
    };
    let mut src = COMMON.to_string();
    if stage_source.contains(": ClusterParams;") || stage_source.contains(": RadixParams;") {
        src = format!("{src}\n{CLUSTER}");
    }
    if stage_source.contains(": FloatParams;") {
        src = format!("{src}\n{FLOATING}");
        if binds("cell_key") {
            src = format!("{src}\n{FLOATING_CELLS}");
        }
    }
    if binds("indices") && binds("vertex_faces") {
        src = format!("{src}\n{MESH}");
        if binds("face_extra") {
            src = format!("{src}\n{SEAMS}");
        }
    }
    // The placement, for the stages that place clusters (not those that only read them).
    if stage_source.contains("var<storage, read_write> cluster_placed:") {
        src = format!("{src}\n{PLACE}");
    }
    format!("{src}\n{stage_source}")
}

/// The bindings `shaders/<shader>.wgsl` declares, by binding number: each variable's name and
/// access: what every family's schedule test compares with the stages' descriptions.
#[cfg(test)]
pub(crate) fn shader_bindings(
    shader: &str,
) -> std::result::Result<Vec<(String, crate::compute::schedule::Access)>, String> {
    use crate::compute::schedule::Access;
    let src = stage_source(shader).ok_or("no such shader file")?;
    let module = naga::front::wgsl::parse_str(&source(src)).map_err(|e| e.message().to_string())?;
    let mut vars: Vec<(u32, String, Access)> = Vec::new();
    for (_, v) in module.global_variables.iter() {
        let Some(binding) = &v.binding else { continue };
        if binding.group != 0 {
            return Err(format!(
                "binding group {} (the rounds use group 0)",
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
    Ok(vars
        .into_iter()
        .map(|(_, name, access)| (name, access))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::types::*;

    fn parse(stem: &str, src: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(&source(src))
            .unwrap_or_else(|e| panic!("shaders/{stem}.wgsl: {}", e.emit_to_string(&source(src))));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::empty(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("shaders/{stem}.wgsl does not validate: {e:?}"));
        module
    }

    #[test]
    fn no_stage_binds_more_storage_buffers_than_the_device_check_asks_for() {
        let most = SOURCES
            .iter()
            .map(|(stem, src)| {
                let module = parse(stem, src);
                module
                    .global_variables
                    .iter()
                    .filter(|(_, v)| matches!(v.space, naga::AddressSpace::Storage { .. }))
                    .count() as u32
            })
            .max()
            .unwrap_or(0);
        assert_eq!(most, MAX_STORAGE_BUFFERS);
    }

    #[test]
    fn every_stage_parses_and_validates() {
        for (stem, src) in SOURCES {
            parse(stem, src);
        }
        for stage in crate::parallel::schedule::STAGES {
            let src = stage_source(stage.shader)
                .unwrap_or_else(|| panic!("{}: no shaders/{}.wgsl", stage.entry, stage.shader));
            let module = parse(stage.shader, src);
            assert!(
                module.entry_points.iter().any(|ep| ep.name == stage.entry),
                "shaders/{}.wgsl has no entry point {}",
                stage.shader,
                stage.entry
            );
        }
    }

    #[test]
    fn every_shader_file_is_a_stage() {
        let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        for entry in std::fs::read_dir(dir).unwrap() {
            let entry = entry.unwrap();
            if entry.file_type().unwrap().is_dir() {
                continue; // shaders/viewer: render shaders, validated in src/viewer
            }
            let name = entry.file_name().into_string().unwrap();
            let stem = name.trim_end_matches(".wgsl");
            assert!(
                [
                    "common",
                    "mesh",
                    "seams",
                    "cluster",
                    "floating",
                    "floating_cells",
                    "place"
                ]
                .contains(&stem)
                    || stage_source(stem).is_some(),
                "shaders/{name} is not listed in SOURCES"
            );
        }
    }

    /// The constants of shaders/common.wgsl against their Rust twins: a state, flag or counter
    /// index out of step would not fail to compile, only make the backends disagree.
    #[test]
    fn wgsl_constants_match_their_rust_twins() {
        use crate::cpu::edge_costs::CounterField as C;
        let module = parse("draw_args", stage_source("draw_args").unwrap());
        let value = |name: &str| -> u32 {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no const {name} in common.wgsl"));
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                ref e => panic!("const {name} is not a u32 literal: {e:?}"),
            }
        };
        let pairs = [
            ("WG", WG),
            ("SCAN_BLOCK", SCAN_BLOCK),
            ("HIST_BINS", HIST_BINS),
            ("HIST_SHIFT", HIST_SHIFT),
            ("INVALID_COST", INVALID_COST),
            ("NO_ATTR", NO_ATTR),
            ("FLAG_BORDER", flag::BORDER),
            ("FLAG_PINNED", flag::PINNED),
            ("FLAG_SEAM", flag::SEAM),
            ("FLAG_MOVED", flag::MOVED),
            ("STATE_OUT", state::OUT),
            ("STATE_CANDIDATE", state::CANDIDATE),
            ("STATE_WON", state::WON),
            ("STATE_TENTATIVE", state::TENTATIVE),
            ("STATE_POSTED", state::POSTED),
            ("C_CANDIDATES", C::Candidates as u32),
            ("C_OVER_MAX_ERROR", C::OverMaxError as u32),
            ("C_CEILING", C::Ceiling as u32),
            ("C_WINNERS", C::Winners as u32),
            ("C_REMOVED", C::Removed as u32),
            ("C_MAX_ERR2_BITS", C::MaxErr2Bits as u32),
            ("C_TRIM_BIN", C::TrimBin as u32),
            ("C_TRIM_BUDGET", C::TrimBudget as u32),
            ("C_VERTICES_OUT", C::VerticesOut as u32),
            ("C_FACES_OUT", C::FacesOut as u32),
            ("C_TENTATIVE", C::Tentative as u32),
            ("C_LIVE", C::Live as u32),
            ("COUNTERS", (std::mem::size_of::<Counters>() / 4) as u32),
        ];
        for (name, rust) in pairs {
            assert_eq!(value(name), rust, "const {name}: WGSL against Rust");
        }
    }

    #[test]
    fn wgsl_structs_match_their_rust_twins() {
        let module = parse("draw_args", stage_source("draw_args").unwrap());
        let size = |name: &str| {
            let (_, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no struct {name} in common.wgsl"));
            ty.inner.size(module.to_ctx()) as usize
        };
        use std::mem::size_of;
        assert_eq!(size("Params"), size_of::<Params>());
        assert_eq!(size("ScanParams"), size_of::<ScanParams>());
        assert_eq!(size("Counters"), size_of::<Counters>());
        assert_eq!(size("Quadric"), size_of::<Quadric>());
        assert_eq!(size("EdgeCandidate"), size_of::<EdgeCandidate>());
        assert_eq!(size("FaceExtra"), size_of::<FaceExtra>());
        assert_eq!(size("DrawArgs"), size_of::<DrawArgs>());
        let module = parse(
            "cluster_quadrics",
            stage_source("cluster_quadrics").unwrap(),
        );
        let size = |name: &str| {
            let (_, ty) = module
                .types
                .iter()
                .find(|(_, t)| t.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no struct {name} in cluster.wgsl"));
            ty.inner.size(module.to_ctx()) as usize
        };
        assert_eq!(size("ClusterParams"), size_of::<ClusterParams>());
        assert_eq!(size("RadixParams"), size_of::<RadixParams>());
        assert_eq!(size("ClusterPlaced"), size_of::<ClusterPlaced>());
        let module = parse("fc_quadrics", stage_source("fc_quadrics").unwrap());
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some("FloatParams"))
            .expect("no struct FloatParams in floating.wgsl");
        assert_eq!(
            ty.inner.size(module.to_ctx()) as usize,
            size_of::<FloatParams>()
        );
    }

    /// The floating cells' radius spread (shaders/floating.wgsl) against its Rust twin: the
    /// radii must be the CPU's to the bit, or a claim at the edge of a ball differs.
    #[test]
    fn floating_constants_match_their_rust_twins() {
        let module = parse("fc_decide", stage_source("fc_decide").unwrap());
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some("JITTER"))
            .expect("no const JITTER in floating.wgsl");
        match module.global_expressions[c.init] {
            naga::Expression::Literal(naga::Literal::F32(v)) => {
                assert_eq!(v.to_bits(), crate::cluster::floating::JITTER.to_bits())
            }
            ref e => panic!("const JITTER is not an f32 literal: {e:?}"),
        }
    }

    /// The constants of shaders/cluster.wgsl against their Rust twins.
    #[test]
    fn cluster_constants_match_their_rust_twins() {
        let module = parse(
            "cluster_quadrics",
            stage_source("cluster_quadrics").unwrap(),
        );
        let value = |name: &str| -> u32 {
            let (_, c) = module
                .constants
                .iter()
                .find(|(_, c)| c.name.as_deref() == Some(name))
                .unwrap_or_else(|| panic!("no const {name} in cluster.wgsl"));
            match module.global_expressions[c.init] {
                naga::Expression::Literal(naga::Literal::U32(v)) => v,
                ref e => panic!("const {name} is not a u32 literal: {e:?}"),
            }
        };
        let pairs = [
            ("SINGLETON", crate::cluster::grid::SINGLETON),
            ("UNCLAIMED", crate::cluster::floating::UNCLAIMED),
            ("SORT_BLOCK", SORT_BLOCK),
            ("PLACE_SINGLE", place::SINGLE),
            ("PLACE_SOLVE", place::SOLVE),
            ("PLACE_MEMBER", place::MEMBER),
            ("PLACE_CENTROID", place::CENTROID),
        ];
        for (name, rust) in pairs {
            assert_eq!(value(name), rust, "const {name}: WGSL against Rust");
        }
    }
}
