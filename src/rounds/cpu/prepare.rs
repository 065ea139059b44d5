//! The preparation on the CPU: [`prepare`] runs its stages' twins (weld_insert.rs,
//! weld_resolve.rs, morton_keys.rs, class_rank.rs, face_keys.rs, prep_faces.rs, prep_vertices.rs;
//! the stages are `crate::rounds::prepare`'s), invocation by invocation in index order, in the
//! schedule's order: what the GPU's buffers are checked against, and, through it, what is checked
//! against the host's own preparation.

use super::class_rank::class_rank;
use super::face_keys::face_keys;
use super::morton_keys::morton_keys;
use super::prefix_sum::prefix_sum;
use super::prep_faces::prep_faces;
use super::prep_vertices::prep_vertices;
use super::weld_insert::weld_insert;
use super::weld_resolve::weld_resolve;
use crate::compute::types::{FaceExtra, PrepCounts, PrepParams};

/// The radix sort's result (`radix_count` and `radix_scatter` have their pass-for-pass twins
/// in tests/cluster_twins): the first `n` pairs stably by key.
fn sort_pairs(n: usize, keys: &mut [u32], vals: &mut [u32]) {
    let (sorted, order) = crate::mesh::sort::radix_sort(keys[..n].to_vec());
    let moved: Vec<u32> = order.iter().map(|&i| vals[i as usize]).collect();
    keys[..n].copy_from_slice(&sorted);
    vals[..n].copy_from_slice(&moved);
}

/// What the preparation leaves: the rounds' first half and its counts.
#[derive(Debug, Clone, PartialEq)]
pub struct Prepared {
    pub positions: Vec<[f32; 4]>,
    pub flags: Vec<u32>,
    pub vertex_attr: Vec<u32>,
    pub indices: Vec<u32>,
    pub face_extra: Vec<FaceExtra>,
    /// Welded vertices (position classes).
    pub welded: u32,
    /// Used classes (the rounds' vertices) and kept faces.
    pub vertices: u32,
    pub faces: u32,
}

/// The preparation's stages in the schedule's order (`WELD`, the Morton sort, `CLASSES`, the
/// faces' sort, `OUTPUT`) on the input's arrays.
pub fn prepare(p: &PrepParams, in_positions: &[f32], in_indices: &[u32]) -> Prepared {
    let (n, m) = (p.vertex_count as usize, p.face_count as usize);
    let mut block_sums = Vec::new();
    let mut weld_table = vec![0u32; p.table_mask as usize + 1];
    let mut weld_slot = vec![0u32; n];
    weld_insert(p, in_positions, &mut weld_table, &mut weld_slot);
    let mut first = vec![0u32; n];
    let mut welded_id = vec![0u32; n + 1];
    weld_resolve(p, &weld_table, &weld_slot, &mut first, &mut welded_id);
    let welded = prefix_sum(n as u32, &mut welded_id, &mut block_sums);
    let mut welded_input = vec![0u32; n];
    let (mut keys, mut vals) = (vec![0u32; n.max(m)], vec![0u32; n.max(m)]);
    morton_keys(
        p,
        in_positions,
        &first,
        &welded_id,
        &mut welded_input,
        &mut keys,
        &mut vals,
    );
    sort_pairs(n, &mut keys, &mut vals);
    let (mut class_of, mut class_welded) = (vec![0u32; n], vec![0u32; n]);
    class_rank(p, &welded_id, &vals, &mut class_of, &mut class_welded);
    let mut class_used = vec![0u32; n + 1];
    let mut counts = PrepCounts::default();
    face_keys(
        p,
        in_indices,
        &first,
        &welded_id,
        &class_of,
        &mut keys,
        &mut vals,
        &mut class_used,
        &mut counts,
    );
    sort_pairs(m, &mut keys, &mut vals);
    let vertices = prefix_sum(n as u32, &mut class_used, &mut block_sums);
    let faces = counts.kept;
    let mut indices = vec![0u32; 3 * faces as usize];
    let mut face_extra = vec![FaceExtra::default(); faces as usize];
    prep_faces(
        in_indices,
        &first,
        &welded_id,
        &class_of,
        &class_used,
        &vals,
        &counts,
        &mut indices,
        &mut face_extra,
    );
    let mut positions = vec![[0.0f32; 4]; vertices as usize];
    let mut flags = vec![0u32; vertices as usize];
    let mut vertex_attr = vec![0u32; vertices as usize];
    prep_vertices(
        p,
        in_positions,
        &welded_id,
        &welded_input,
        &class_welded,
        &class_used,
        &mut positions,
        &mut flags,
        &mut vertex_attr,
    );
    Prepared {
        positions,
        flags,
        vertex_attr,
        indices,
        face_extra,
        welded,
        vertices,
        faces,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;
    use crate::rounds::Upload;

    /// The input's arrays as the device takes them.
    fn arrays(m: &Mesh) -> (Vec<f32>, Vec<u32>) {
        (
            bytemuck::cast_slice(&m.positions).to_vec(),
            bytemuck::cast_slice(&m.triangles).to_vec(),
        )
    }

    /// A mesh with what the weld and the face filter must handle: every vertex written twice
    /// (once as -0.0 where it is 0.0), faces that collapse to a segment once welded, and an
    /// unused vertex.
    fn awkward() -> Mesh {
        // The grid moved so that x = 0 runs through its middle (a -0.0 on a box's side would
        // leave the mesh to the host's preparation).
        let mut base = crate::mesh::grid(12);
        for p in &mut base.positions {
            *p = [p[0] - 0.5, p[1] - 0.5, 0.3 * p[0] + 0.2];
        }
        let n = base.positions.len() as u32;
        let mut positions = base.positions.clone();
        positions.extend(
            base.positions
                .iter()
                .map(|p| p.map(|x| if x == 0.0 { -0.0 } else { x })),
        );
        positions.push([5.0, 5.0, 5.0]);
        let mut triangles: Vec<[u32; 3]> = base
            .triangles
            .iter()
            .enumerate()
            .map(|(f, t)| if f % 3 == 0 { t.map(|v| v + n) } else { *t })
            .collect();
        triangles.push([0, n, 1]);
        triangles.push([2, 2, 3]);
        Mesh {
            positions,
            triangles,
            ..base.clone_without_geometry()
        }
    }

    /// The twins, run in order, give the host's upload: the same positions, flags, indices and
    /// face origins, and as vertex and corner attributes the first input vertex of each welded
    /// vertex the host names.
    #[test]
    fn the_twins_prepare_what_the_host_does() {
        for mesh in [
            crate::mesh::grid(40),
            awkward(),
            crate::mesh::noisy_sphere(3, 0.01, 7),
        ] {
            let p = super::super::super::prepare::eligible(&mesh).expect("a plain mesh");
            let (pos, idx) = arrays(&mesh);
            let got = prepare(&p, &pos, &idx);
            let up = Upload::new(&mesh);
            // Each welded vertex's first input vertex: the lowest one the weld maps to it.
            let remap = crate::mesh::weld(&mesh).remap;
            let mut first_input = vec![u32::MAX; up.welded.positions.len()];
            for (v, &w) in remap.iter().enumerate().rev() {
                first_input[w as usize] = v as u32;
            }
            let named = |w: u32| first_input[w as usize];
            assert_eq!(got.positions, up.positions);
            assert_eq!(got.flags, up.flags);
            assert_eq!(got.indices, up.indices);
            assert_eq!(
                got.vertex_attr,
                up.vertex_attr.iter().map(|&w| named(w)).collect::<Vec<_>>()
            );
            let want: Vec<FaceExtra> = up
                .face_extra
                .iter()
                .map(|x| FaceExtra {
                    attr: x.attr.map(named),
                    origin: x.origin,
                })
                .collect();
            assert_eq!(got.face_extra, want);
            assert_eq!(got.welded as usize, up.welded.positions.len());
            assert_eq!(
                mesh.triangles.len() - got.faces as usize,
                up.dropped_degenerate
            );
        }
    }
}
