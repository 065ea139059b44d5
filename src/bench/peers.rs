//! The peers the `cpu` backend is held against: meshoptimizer's `simplify` and
//! `simplifySloppy`, on our meshes.

use crate::mesh::Mesh;

/// Simplifies with meshoptimizer's `meshopt_simplify` (edge collapse with quadrics, not the
/// sloppy clustering) to `target_faces`, the baseline the `cpu` backend is held against.
///
/// The target error is 1.0 (the whole mesh extent) so that the face count alone stops it, and
/// no flag is set: the border is free to move, as in our default options. meshoptimizer
/// works on positions only; attributes are carried along for the vertices it keeps, per-face
/// materials and groups are dropped. The output is compacted to the vertices it uses.
pub fn meshopt_simplify(mesh: &Mesh, target_faces: usize) -> Mesh {
    with_meshopt(mesh, |indices, vertices| {
        meshopt::simplify(
            indices,
            vertices,
            target_faces * 3,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        )
    })
}

/// Simplifies with meshoptimizer's `meshopt_simplifyWithAttributes`: the edge collapse with
/// the vertex colours (RGB) and UVs the mesh has in its quadrics, each weighted by `weight`
/// (meshoptimizer's own scale: positions are normalized by the mesh's extent). It keeps input
/// vertices and their attributes. Without colours and UVs this is [`meshopt_simplify`].
pub fn meshopt_simplify_with_attributes(mesh: &Mesh, target_faces: usize, weight: f32) -> Mesh {
    let n = mesh.positions.len();
    let mut stride = 0;
    if mesh.colors.is_some() {
        stride += 3;
    }
    if mesh.uvs.is_some() {
        stride += 2;
    }
    if stride == 0 {
        return meshopt_simplify(mesh, target_faces);
    }
    let mut attrs = Vec::with_capacity(n * stride);
    for v in 0..n {
        if let Some(c) = &mesh.colors {
            attrs.extend_from_slice(&c[v][..3]);
        }
        if let Some(t) = &mesh.uvs {
            attrs.extend_from_slice(&t[v]);
        }
    }
    let weights = vec![weight; stride];
    let locks = vec![false; n];
    with_meshopt(mesh, |indices, vertices| {
        meshopt::simplify_with_attributes_and_locks(
            indices,
            vertices,
            &attrs,
            &weights,
            stride * std::mem::size_of::<f32>(),
            &locks,
            target_faces * 3,
            1.0,
            meshopt::SimplifyOptions::None,
            None,
        )
    })
}

/// Simplifies with meshoptimizer's `meshopt_simplifySloppy` (vertex clustering on a grid, no
/// topology kept) to about `target_faces`: the throughput end of the scale. The target error
/// is 1.0 so that the face count alone stops it. Positions only, as [`meshopt_simplify`]; the
/// output is compacted to the vertices it uses.
pub fn meshopt_simplify_sloppy(mesh: &Mesh, target_faces: usize) -> Mesh {
    with_meshopt(mesh, |indices, vertices| {
        meshopt::simplify_sloppy(indices, vertices, target_faces * 3, 1.0, None)
    })
}

/// Runs a meshoptimizer index-buffer simplifier on `mesh`'s positions and turns its output
/// back into a mesh, attributes carried along, compacted to the vertices it uses.
fn with_meshopt(
    mesh: &Mesh,
    simplify: impl FnOnce(&[u32], &meshopt::VertexDataAdapter) -> Vec<u32>,
) -> Mesh {
    let indices: &[u32] = bytemuck::cast_slice(&mesh.triangles);
    let vertices = meshopt::VertexDataAdapter::new(
        bytemuck::cast_slice(&mesh.positions),
        std::mem::size_of::<[f32; 3]>(),
        0,
    )
    .expect("a [f32; 3] slice is a valid vertex buffer");
    let out = simplify(indices, &vertices);
    let mut m = Mesh {
        positions: mesh.positions.clone(),
        triangles: bytemuck::cast_slice(&out).to_vec(),
        normals: mesh.normals.clone(),
        uvs: mesh.uvs.clone(),
        uv_origin: mesh.uv_origin,
        colors: mesh.colors.clone(),
        ..Default::default()
    };
    m.remove_unused_vertices();
    m
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh;

    #[test]
    fn meshopt_reaches_the_face_target_on_a_sphere() {
        let sphere = mesh::icosphere(4); // 5120 faces
        let out = meshopt_simplify(&sphere, 512);
        assert!(out.face_count() <= 512, "{} faces", out.face_count());
        assert!(out.face_count() >= 400, "{} faces", out.face_count());
        out.validate().unwrap();
        assert!(out.vertex_count() < sphere.vertex_count());
    }

    #[test]
    fn sloppy_reaches_about_the_face_target() {
        let sphere = mesh::icosphere(4); // 5120 faces
        let out = meshopt_simplify_sloppy(&sphere, 512);
        assert!(out.face_count() <= 512, "{} faces", out.face_count());
        assert!(out.face_count() >= 300, "{} faces", out.face_count());
        out.validate().unwrap();
    }
}
