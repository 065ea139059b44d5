//! The preparation on the device, described once as the rounds are in [`super::schedule`]: the
//! exact weld (a hash table of positions), the position classes numbered along a Morton curve
//! (a radix sort of the codes), the faces with three distinct classes in the order of their
//! lowest class (a radix sort of those), the used classes numbered densely (a prefix sum) and
//! their positions in the normalized frame: the arrays [`super::Upload`] makes on the host from
//! [`crate::mesh::prepare::Surface`], made where the rounds run, from the arrays the host parsed.
//! The GPU runner is [`super::gpu::prepare`]; the twins, of the same names, are in
//! [`super::cpu::prepare`].
//!
//! It prepares plain meshes (no normals, UVs or colours: one attribute vertex per position, so
//! no seams), which is what a scan is; [`eligible`] says which.

use crate::compute::types::{PrepParams, SORT_BLOCK};
use crate::mesh::Mesh;

/// A buffer of the preparation. The sort's keys and values come in two halves, as the
/// clustering's do: the plain names are the half a pass reads (after a sort, the sorted
/// result), the `*Out` ones the half it writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PBuf {
    /// [`PrepParams`] (uniform).
    Prep,
    /// The pass's [`crate::compute::types::RadixParams`] (uniform, one buffer per pass).
    Radix,
    /// A prefix sum's count (uniform `ScanParams`); which one is the step's.
    ScanCount,
    /// The values a prefix sum scans in place.
    ScanData,
    BlockSums,
    /// The input as parsed: positions (three f32 a vertex) and corners (three u32 a face).
    InPositions,
    InIndices,
    /// Per slot of the weld's hash table: the lowest vertex at its position + 1 (0: empty).
    WeldTable,
    /// Per input vertex: its slot, then the lowest vertex at its position.
    WeldSlot,
    WeldFirst,
    /// Per input vertex, scanned: its welded vertex's number where it is the first (+ 1 for
    /// the count).
    WeldedId,
    /// Per welded vertex: its first input vertex.
    WeldedInput,
    SortKeys,
    SortVals,
    SortKeysOut,
    SortValsOut,
    DigitCounts,
    /// Per welded vertex: its class; per class: its welded vertex.
    ClassOf,
    ClassWelded,
    /// Per class: 1 if a kept face uses it, then scanned into the dense numbers (+ 1).
    ClassUsed,
    /// [`crate::compute::types::PrepCounts`].
    PrepCounts,
    /// The rounds' first half, as [`super::Upload`] carries it.
    Positions,
    Flags,
    VertexAttr,
    Indices,
    FaceExtra,
    // The shared stages' buffers that the preparation never binds (`shared_stages!` names them).
    Params,
    Offsets,
    Cursor,
    VertexFaces,
    FaceNormals,
}

/// A count a stage or a prefix sum runs over.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PCount {
    /// Input vertices.
    Vertices,
    /// Input faces.
    Faces,
    /// 256 digit counts per sort block of the Morton sort (over the input vertices)...
    VertexDigits,
    /// ...and of the faces' sort.
    FaceDigits,
}

/// What a stage's invocations run over.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PGrid {
    Each(PCount),
    /// One workgroup per block of `SORT_BLOCK` keys of the sort under way.
    SortBlocks,
    ScanBlocks,
    One,
}

/// A stage of the preparation.
pub type PStage = crate::compute::schedule::Stage<PBuf, PGrid>;

use PCount::{Faces, Vertices};
use PGrid::{Each, SortBlocks};

// The prefix sum (and the shared stages the preparation does not run), on these buffers.
crate::compute::schedule::shared_stages!(PStage, PStep, PBuf, PGrid, PCount);

pub static WELD_INSERT: PStage = crate::stage!(PBuf; weld_insert in "rounds/weld_insert" over Each(Vertices);
    prep: Uniform Prep, in_positions: Read InPositions, weld_table: ReadWrite WeldTable,
    weld_slot: ReadWrite WeldSlot);
pub static WELD_RESOLVE: PStage = crate::stage!(PBuf; weld_resolve in "rounds/weld_resolve" over Each(Vertices);
    prep: Uniform Prep, weld_table: Read WeldTable, weld_slot: Read WeldSlot,
    weld_first: ReadWrite WeldFirst, welded_id: ReadWrite WeldedId);
pub static MORTON_KEYS: PStage = crate::stage!(PBuf; morton_keys in "rounds/morton_keys" over Each(Vertices);
    prep: Uniform Prep, in_positions: Read InPositions, weld_first: Read WeldFirst,
    welded_id: Read WeldedId, welded_input: ReadWrite WeldedInput,
    sort_keys: ReadWrite SortKeys, sort_vals: ReadWrite SortVals);
pub static RADIX_COUNT: PStage = crate::stage!(PBuf; radix_count in "cluster/radix_count" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, digit_counts: ReadWrite DigitCounts);
pub static RADIX_SCATTER: PStage = crate::stage!(PBuf; radix_scatter in "cluster/radix_scatter" over SortBlocks;
    radix: Uniform Radix, keys: Read SortKeys, vals: Read SortVals,
    digit_counts: Read DigitCounts, keys_out: ReadWrite SortKeysOut,
    vals_out: ReadWrite SortValsOut);
pub static CLASS_RANK: PStage = crate::stage!(PBuf; class_rank in "rounds/class_rank" over Each(Vertices);
    prep: Uniform Prep, welded_id: Read WeldedId, sort_vals: Read SortVals,
    class_of: ReadWrite ClassOf, class_welded: ReadWrite ClassWelded);
pub static FACE_KEYS: PStage = crate::stage!(PBuf; face_keys in "rounds/face_keys" over Each(Faces);
    prep: Uniform Prep, in_indices: Read InIndices, weld_first: Read WeldFirst,
    welded_id: Read WeldedId, class_of: Read ClassOf, sort_keys: ReadWrite SortKeys,
    sort_vals: ReadWrite SortVals, class_used: ReadWrite ClassUsed,
    prep_counts: ReadWrite PrepCounts);
pub static PREP_FACES: PStage = crate::stage!(PBuf; prep_faces in "rounds/prep_faces" over Each(Faces);
    in_indices: Read InIndices, weld_first: Read WeldFirst,
    welded_id: Read WeldedId, class_of: Read ClassOf, class_used: Read ClassUsed,
    sort_vals: Read SortVals, prep_counts: Read PrepCounts, indices: ReadWrite Indices,
    face_extra: ReadWrite FaceExtra);
pub static PREP_VERTICES: PStage = crate::stage!(PBuf; prep_vertices in "rounds/prep_vertices" over Each(Vertices);
    prep: Uniform Prep, in_positions: Read InPositions, welded_id: Read WeldedId,
    welded_input: Read WeldedInput, class_welded: Read ClassWelded, class_used: Read ClassUsed,
    positions: ReadWrite Positions, flags: ReadWrite Flags, vertex_attr: ReadWrite VertexAttr);

/// The stages the preparation runs, each once: the runner makes one pipeline per entry.
pub const STAGES: &[&[&PStage]] = &[
    &[&PREFIX_SUM_REDUCE, &PREFIX_SUM_SPINE, &PREFIX_SUM_APPLY],
    OWN_STAGES,
];
const OWN_STAGES: &[&PStage] = &[
    &WELD_INSERT,
    &WELD_RESOLVE,
    &MORTON_KEYS,
    &RADIX_COUNT,
    &RADIX_SCATTER,
    &CLASS_RANK,
    &FACE_KEYS,
    &PREP_FACES,
    &PREP_VERTICES,
];

/// One step of the preparation; it has no steps of its own.
pub type PStep = crate::compute::schedule::Step<PBuf, PGrid, PCount, std::convert::Infallible>;

use crate::compute::schedule::Step::{Clear, PrefixSum, Run};

/// The weld: every vertex's first at its position, the welded vertices numbered.
pub const WELD: &[PStep] = &[
    Clear(PBuf::WeldTable),
    Run(&WELD_INSERT),
    Run(&WELD_RESOLVE),
    PrefixSum {
        count: Vertices,
        data: PBuf::WeldedId,
    },
    Run(&MORTON_KEYS),
];
/// One pass of the Morton codes' radix sort (four: 32-bit keys); the halves swap after it.
pub const VERTEX_SORT_PASS: &[PStep] = &[
    Run(&RADIX_COUNT),
    PrefixSum {
        count: PCount::VertexDigits,
        data: PBuf::DigitCounts,
    },
    Run(&RADIX_SCATTER),
];
/// The classes in code order, then each face's key.
pub const CLASSES: &[PStep] = &[
    Run(&CLASS_RANK),
    Clear(PBuf::ClassUsed),
    Clear(PBuf::PrepCounts),
    Run(&FACE_KEYS),
];
/// One pass of the faces' radix sort ([`face_sort_passes`] of them).
pub const FACE_SORT_PASS: &[PStep] = &[
    Run(&RADIX_COUNT),
    PrefixSum {
        count: PCount::FaceDigits,
        data: PBuf::DigitCounts,
    },
    Run(&RADIX_SCATTER),
];
/// The rounds' first half: the used classes numbered, the faces and vertices written.
pub const OUTPUT: &[PStep] = &[
    PrefixSum {
        count: Vertices,
        data: PBuf::ClassUsed,
    },
    Run(&PREP_FACES),
    Run(&PREP_VERTICES),
];

/// Passes of the Morton sort: its keys use all 32 bits (the pad sorts last).
pub const VERTEX_SORT_PASSES: u32 = 4;

/// Passes of 8 bits the faces' sort needs: a kept face's key is its lowest class (below the
/// vertex count); a dropped face's, all ones, is above every class in those bits too.
pub fn face_sort_passes(vertices: usize) -> u32 {
    let bits = u32::BITS - (vertices as u32).leading_zeros();
    bits.div_ceil(8).max(1)
}

/// Sort blocks over `n` keys.
pub fn sort_blocks(n: usize) -> u32 {
    (n as u32).div_ceil(SORT_BLOCK)
}

/// The uniform of the preparation of `mesh`, when it is one the device prepares: a plain mesh
/// (no normals, UVs or colours), with vertices, whose box the host's frame would see the same
/// way. A box that touches a coordinate plane in a mesh holding a -0.0 is left to the host: its
/// welded positions (the first of each) might give the box's corner another sign of zero than
/// all the input's do, and the frame's centre would follow.
pub fn eligible(mesh: &Mesh) -> Option<PrepParams> {
    if mesh.normals.is_some() || mesh.uvs.is_some() || mesh.colors.is_some() {
        return None;
    }
    let b = mesh.bounds()?;
    let zero_side = b.min.iter().chain(&b.max).any(|&x| x == 0.0);
    if zero_side
        && mesh
            .positions
            .iter()
            .any(|p| p.iter().any(|x| x.to_bits() == (-0.0f32).to_bits()))
    {
        return None;
    }
    let (center, scale) = crate::mesh::prepare::frame_of_box(Some(b));
    let spread = (0..3)
        .map(|i| b.max[i] - b.min[i])
        .fold(0.0f32, f32::max)
        .max(f32::MIN_POSITIVE);
    let slots = (2 * mesh.positions.len()).next_power_of_two() as u32;
    Some(PrepParams {
        vertex_count: mesh.positions.len() as u32,
        face_count: mesh.triangles.len() as u32,
        table_mask: slots - 1,
        _pad: 0,
        grid: [b.min[0], b.min[1], b.min[2], spread],
        frame: [center[0], center[1], center[2], scale],
    })
}

/// The preparation's schedule against its WGSL, with the checks every family passes
/// (`compute::tests`); a binding's variable names its buffer but for the roles listed here.
#[cfg(test)]
pub(crate) fn check_schedule() {
    const ROLES: &[(&str, PBuf)] = &[
        ("keys", PBuf::SortKeys),
        ("vals", PBuf::SortVals),
        ("keys_out", PBuf::SortKeysOut),
        ("vals_out", PBuf::SortValsOut),
        ("scan", PBuf::ScanCount),
        ("data", PBuf::ScanData),
    ];
    const PARTS: &[&[PStep]] = &[WELD, VERTEX_SORT_PASS, CLASSES, FACE_SORT_PASS, OUTPUT];
    crate::compute::schedule::check::family("preparation", STAGES, ROLES, PARTS);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_faces_sort_looks_at_the_bits_the_largest_class_needs() {
        assert_eq!(face_sort_passes(255), 1);
        assert_eq!(face_sort_passes(256), 2);
        assert_eq!(face_sort_passes(537_000), 3);
        assert_eq!(face_sort_passes(1 << 24), 4);
    }
}
