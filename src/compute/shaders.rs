//! The WGSL stages of every family: `shaders/<family>/<stage>.wgsl` (`core/` for the stages every
//! family runs, `rounds/`, `cluster/`), each compiled after the includes it names here — the
//! `*.inc.wgsl` files: `common.inc` and `mesh.inc` at the top for every family, the others in
//! their family's folder — in the order given. Tests parse and validate every stage with naga —
//! no GPU needed — and compare the WGSL structs with their Rust twins.

/// Shared structs, constants and quadric math of every stage.
pub const COMMON: &str = include_str!("../../shaders/common.inc.wgsl");
/// Face and CSR list accessors, for the stages that bind `indices` and `vertex_faces`.
pub const MESH: &str = include_str!("../../shaders/mesh.inc.wgsl");
/// Corner attribute accessors, for the rounds' stages that also bind `face_extra`.
pub const SEAMS: &str = include_str!("../../shaders/rounds/seams.inc.wgsl");
/// The rounds' appearance channels: their layout, sums and values, for the stages that bind
/// `attr_values` and `attr_sums`.
pub const ATTRIBUTES: &str = include_str!("../../shaders/rounds/attributes.inc.wgsl");
/// The preparation on the device's uniform (f64: only its stages include it).
pub const PREPARE: &str = include_str!("../../shaders/rounds/prepare.inc.wgsl");
/// The clustering stages' structs and constants, for the stages that bind `ClusterParams` or
/// `RadixParams`.
pub const CLUSTER: &str = include_str!("../../shaders/cluster/cluster.inc.wgsl");
/// The floating cells' uniform and helpers, for the stages that bind `FloatParams`.
pub const FLOATING: &str = include_str!("../../shaders/cluster/floating.inc.wgsl");
/// The floating cells' hash-grid search, for those of them that also bind `cell_key`.
pub const FLOATING_CELLS: &str = include_str!("../../shaders/cluster/floating_cells.inc.wgsl");
/// A cluster's gather and placement, for the stages that place clusters.
pub const PLACE: &str = include_str!("../../shaders/cluster/place.inc.wgsl");

/// The includes, by file (for the test that every file under shaders/ is accounted for).
#[cfg(test)]
const INCLUDES: &[(&str, &str)] = &[
    ("common.inc", COMMON),
    ("mesh.inc", MESH),
    ("rounds/seams.inc", SEAMS),
    ("rounds/attributes.inc", ATTRIBUTES),
    ("rounds/prepare.inc", PREPARE),
    ("cluster/cluster.inc", CLUSTER),
    ("cluster/floating.inc", FLOATING),
    ("cluster/floating_cells.inc", FLOATING_CELLS),
    ("cluster/place.inc", PLACE),
];

/// A stage's shader: its path under `shaders/` without `.wgsl` (a stage description's `shader`),
/// the includes it is compiled after, in order, and its own source.
pub struct Shader {
    pub path: &'static str,
    pub includes: &'static [&'static str],
    pub body: &'static str,
}

impl Shader {
    /// The source as compiled: the includes, then the stage.
    pub fn source(&self) -> String {
        let mut src = String::new();
        for inc in self.includes {
            src.push_str(inc);
            src.push('\n');
        }
        src + self.body
    }
}

macro_rules! stage {
    ($path:literal, [$($inc:ident),*]) => {
        Shader {
            path: $path,
            includes: &[$($inc),*],
            body: include_str!(concat!("../../shaders/", $path, ".wgsl")),
        }
    };
}

/// Every stage's shader; the families' schedules name each stage's.
pub const SOURCES: &[Shader] = &[
    stage!("core/prefix_sum", [COMMON]),
    stage!("core/adjacency_count", [COMMON]),
    stage!("core/adjacency_fill", [COMMON, MESH]),
    stage!("core/adjacency_sort", [COMMON]),
    stage!("core/face_planes", [COMMON]),
    stage!("rounds/vertex_flags", [COMMON, MESH]),
    stage!("rounds/vertex_quadrics", [COMMON, MESH, SEAMS]),
    stage!(
        "rounds/vertex_attributes",
        [COMMON, MESH, SEAMS, ATTRIBUTES]
    ),
    stage!("rounds/edges_count", [COMMON, MESH]),
    stage!("rounds/edges_fill", [COMMON]),
    stage!("rounds/edge_errors", [COMMON, MESH, SEAMS, ATTRIBUTES]),
    stage!("rounds/live_list", [COMMON]),
    stage!("rounds/edge_costs", [COMMON, MESH]),
    stage!("rounds/cost_ceiling", [COMMON]),
    stage!("rounds/select_cost", [COMMON]),
    stage!("rounds/select_id", [COMMON]),
    stage!("rounds/select_win", [COMMON]),
    stage!("rounds/validate", [COMMON, MESH]),
    stage!("rounds/trim_histogram", [COMMON]),
    stage!("rounds/trim_ceiling", [COMMON]),
    stage!("rounds/trim_mark", [COMMON]),
    stage!("rounds/trim_apply", [COMMON]),
    stage!("rounds/collapse", [COMMON, MESH, SEAMS, ATTRIBUTES]),
    stage!("rounds/compact_mark", [COMMON]),
    stage!("rounds/compact_vertices", [COMMON]),
    stage!("rounds/compact_faces", [COMMON]),
    stage!("rounds/dispatch_args", [COMMON]),
    stage!("rounds/draw_args", [COMMON]),
    stage!("rounds/plan_round", [COMMON]),
    stage!("rounds/group_flags", [COMMON]),
    stage!("rounds/group_errors", [COMMON]),
    stage!("rounds/group_faces", [COMMON]),
    stage!("rounds/group_open", [COMMON]),
    stage!("rounds/weld_insert", [COMMON, PREPARE]),
    stage!("rounds/weld_resolve", [COMMON, PREPARE]),
    stage!("rounds/morton_keys", [COMMON, PREPARE]),
    stage!("rounds/class_rank", [COMMON, PREPARE]),
    stage!("rounds/face_keys", [COMMON, PREPARE]),
    stage!("rounds/prep_faces", [COMMON, PREPARE]),
    stage!("rounds/prep_vertices", [COMMON, PREPARE]),
    stage!("dag/dag_cut", [COMMON]),
    stage!("cluster/cell_keys", [COMMON, CLUSTER]),
    stage!("cluster/radix_count", [COMMON, CLUSTER]),
    stage!("cluster/radix_scatter", [COMMON, CLUSTER]),
    stage!("cluster/cell_heads", [COMMON, CLUSTER]),
    stage!("cluster/cell_ranges", [COMMON, CLUSTER]),
    stage!("cluster/cluster_quadrics", [COMMON, CLUSTER, MESH, PLACE]),
    stage!("cluster/cluster_faces_mark", [COMMON, CLUSTER]),
    stage!("cluster/cluster_faces_fill", [COMMON, CLUSTER]),
    stage!("cluster/cluster_faces_dedupe", [COMMON, CLUSTER]),
    stage!("cluster/cluster_faces_compact", [COMMON, CLUSTER]),
    stage!("cluster/cluster_mesh", [COMMON, CLUSTER]),
    stage!("cluster/fc_grades", [COMMON, MESH]),
    stage!("cluster/fc_ranks", [COMMON]),
    stage!("cluster/fc_keys", [COMMON, CLUSTER]),
    stage!("cluster/fc_init", [COMMON, CLUSTER]),
    stage!(
        "cluster/fc_decide",
        [COMMON, CLUSTER, FLOATING, FLOATING_CELLS]
    ),
    stage!(
        "cluster/fc_claim",
        [COMMON, CLUSTER, FLOATING, FLOATING_CELLS]
    ),
    stage!("cluster/fc_cluster_keys", [COMMON, CLUSTER]),
    stage!(
        "cluster/fc_quadrics",
        [COMMON, CLUSTER, FLOATING, MESH, PLACE]
    ),
];

/// The shader at `path` (`rounds/collapse`).
pub fn shader(path: &str) -> Option<&'static Shader> {
    SOURCES.iter().find(|s| s.path == path)
}

/// The full source of the stage shader at `path`, includes first.
pub fn stage_source(path: &str) -> Option<String> {
    shader(path).map(Shader::source)
}

/// The most storage buffers a stage binds (edge_errors: 13, and 3 more since the rounds carry
/// appearance channels), counted in every stage by a unit test: a new stage that binds more
/// changes what a device must allow (`Kernels::new` checks each family's widest stage against
/// the device; Vulkan drivers for desktop GPUs and lavapipe allow far more, Metal 31).
#[cfg(test)]
const MAX_STORAGE_BUFFERS: u32 = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compute::types::*;

    /// What a stage may use: f64 in the preparation's stages alone, which run only where the
    /// device has SHADER_F64.
    fn capabilities(stem: &str) -> naga::valid::Capabilities {
        let prep = SOURCES
            .iter()
            .any(|s| s.path == stem && s.includes.contains(&PREPARE));
        if prep {
            naga::valid::Capabilities::FLOAT64
        } else {
            naga::valid::Capabilities::empty()
        }
    }

    fn parse(stem: &str, src: &str) -> naga::Module {
        let module = naga::front::wgsl::parse_str(src)
            .unwrap_or_else(|e| panic!("shaders/{stem}.wgsl: {}", e.emit_to_string(src)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), capabilities(stem))
            .validate(&module)
            .unwrap_or_else(|e| panic!("shaders/{stem}.wgsl does not validate: {e:?}"));
        module
    }

    #[test]
    fn no_stage_binds_more_storage_buffers_than_the_device_check_asks_for() {
        let most = SOURCES
            .iter()
            .map(|s| {
                let module = parse(s.path, &s.source());
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
        for s in SOURCES {
            parse(s.path, &s.source());
        }
    }

    /// Every file under shaders/ (but the viewer's render shaders, validated in src/viewer) is
    /// a stage in SOURCES or an include, and only includes are named `*.inc.wgsl`.
    #[test]
    fn every_shader_file_is_a_stage_or_an_include() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("shaders");
        let mut dirs = vec![root.clone()];
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(dir).unwrap() {
                let path = entry.unwrap().path();
                let rel = path
                    .strip_prefix(&root)
                    .unwrap()
                    .to_string_lossy()
                    .replace('\\', "/");
                if path.is_dir() {
                    if rel != "viewer" {
                        dirs.push(path);
                    }
                    continue;
                }
                let stem = rel.trim_end_matches(".wgsl");
                if stem.ends_with(".inc") {
                    assert!(
                        INCLUDES.iter().any(|i| i.0 == stem),
                        "shaders/{rel} is not listed in INCLUDES"
                    );
                } else {
                    assert!(
                        shader(stem).is_some(),
                        "shaders/{rel} is not listed in SOURCES"
                    );
                }
            }
        }
    }

    /// The initializer of `const name` in `module` (parsed from a stage that includes `file`).
    fn constant<'m>(module: &'m naga::Module, file: &str, name: &str) -> &'m naga::Expression {
        let (_, c) = module
            .constants
            .iter()
            .find(|(_, c)| c.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no const {name} in {file}"));
        &module.global_expressions[c.init]
    }

    /// The value of `const name`, which the twins' tests need to be a u32 literal.
    fn u32_constant(module: &naga::Module, file: &str, name: &str) -> u32 {
        match *constant(module, file, name) {
            naga::Expression::Literal(naga::Literal::U32(v)) => v,
            ref e => panic!("const {name} is not a u32 literal: {e:?}"),
        }
    }

    /// The size in bytes of `struct name`, as naga lays it out for the GPU.
    fn struct_size(module: &naga::Module, file: &str, name: &str) -> usize {
        let (_, ty) = module
            .types
            .iter()
            .find(|(_, t)| t.name.as_deref() == Some(name))
            .unwrap_or_else(|| panic!("no struct {name} in {file}"));
        ty.inner.size(module.to_ctx()) as usize
    }

    /// The constants of shaders/common.inc.wgsl against their Rust twins: a state, flag or counter
    /// index out of step would not fail to compile, only make the backends disagree.
    #[test]
    fn wgsl_constants_match_their_rust_twins() {
        use crate::rounds::cpu::counters::CounterField as C;
        let module = parse("draw_args", &stage_source("rounds/draw_args").unwrap());
        let value = |name: &str| u32_constant(&module, "common.wgsl", name);
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
            ("FLAG_CLOSED", flag::CLOSED),
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
            ("C_OPEN_GROUPS", C::OpenGroups as u32),
            ("C_OPEN_EXCESS", C::OpenExcess as u32),
            ("C_OPEN_FACES", C::OpenFaces as u32),
            ("COUNTERS", (std::mem::size_of::<Counters>() / 4) as u32),
            ("GRID_VERTICES", grid_slot::VERTICES as u32),
            ("GRID_FACES", grid_slot::FACES as u32),
            ("GRID_EDGE_SLOTS", grid_slot::EDGE_SLOTS as u32),
            (
                "GRID_VERTICES_OR_FACES",
                grid_slot::VERTICES_OR_FACES as u32,
            ),
            ("GRID_SCAN_VERTICES", grid_slot::SCAN_VERTICES as u32),
            ("GRID_ONE", grid_slot::ONE as u32),
            ("GRID_TRIM_EDGE_SLOTS", grid_slot::TRIM_EDGE_SLOTS as u32),
            ("GRID_TRIM_SCAN", grid_slot::TRIM_SCAN as u32),
            ("GRID_TRIM_ONE", grid_slot::TRIM_ONE as u32),
            ("GRID_SLOTS", grid_slot::COUNT as u32),
        ];
        for (name, rust) in pairs {
            assert_eq!(value(name), rust, "const {name}: WGSL against Rust");
        }
    }

    #[test]
    fn wgsl_structs_match_their_rust_twins() {
        let module = parse("draw_args", &stage_source("rounds/draw_args").unwrap());
        let size = |name: &str| struct_size(&module, "common.wgsl", name);
        use std::mem::size_of;
        assert_eq!(size("Params"), size_of::<Params>());
        assert_eq!(size("ScanParams"), size_of::<ScanParams>());
        assert_eq!(size("Counters"), size_of::<Counters>());
        assert_eq!(size("Quadric"), size_of::<Quadric>());
        assert_eq!(size("EdgeCandidate"), size_of::<EdgeCandidate>());
        assert_eq!(size("FaceExtra"), size_of::<FaceExtra>());
        assert_eq!(size("DrawArgs"), size_of::<DrawArgs>());
        assert_eq!(size("PlanState"), size_of::<PlanState>());
        assert_eq!(size("Planned"), size_of::<Planned>());
        let module = parse(
            "cluster_quadrics",
            &stage_source("cluster/cluster_quadrics").unwrap(),
        );
        let size = |name: &str| struct_size(&module, "cluster.wgsl", name);
        assert_eq!(size("ClusterParams"), size_of::<ClusterParams>());
        assert_eq!(size("RadixParams"), size_of::<RadixParams>());
        assert_eq!(size("ClusterPlaced"), size_of::<ClusterPlaced>());
        let module = parse(
            "rounds/weld_resolve",
            &stage_source("rounds/weld_resolve").unwrap(),
        );
        assert_eq!(
            struct_size(&module, "prepare.wgsl", "PrepParams"),
            size_of::<PrepParams>()
        );
        let module = parse("fc_quadrics", &stage_source("cluster/fc_quadrics").unwrap());
        assert_eq!(
            struct_size(&module, "floating.wgsl", "FloatParams"),
            size_of::<FloatParams>()
        );
        let module = parse("dag_cut", &stage_source("dag/dag_cut").unwrap());
        let size = |name: &str| struct_size(&module, "dag_cut.wgsl", name);
        assert_eq!(size("CutParams"), size_of::<CutParams>());
        assert_eq!(size("CutCluster"), size_of::<CutCluster>());
        assert_eq!(size("CornerDraw"), size_of::<CornerDraw>());
    }

    /// The floating cells' radius spread (shaders/cluster/floating.inc.wgsl) against its Rust twin: the
    /// radii must be the CPU's to the bit, or a claim at the edge of a ball differs.
    #[test]
    fn floating_constants_match_their_rust_twins() {
        let module = parse("fc_decide", &stage_source("cluster/fc_decide").unwrap());
        match *constant(&module, "floating.wgsl", "JITTER") {
            naga::Expression::Literal(naga::Literal::F32(v)) => {
                assert_eq!(v.to_bits(), crate::cluster::floating::JITTER.to_bits())
            }
            ref e => panic!("const JITTER is not an f32 literal: {e:?}"),
        }
    }

    /// The constants of shaders/cluster/cluster.inc.wgsl against their Rust twins.
    #[test]
    fn cluster_constants_match_their_rust_twins() {
        let module = parse(
            "cluster_quadrics",
            &stage_source("cluster/cluster_quadrics").unwrap(),
        );
        let value = |name: &str| u32_constant(&module, "cluster.wgsl", name);
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
