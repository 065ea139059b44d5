//! Welding: merging vertices that are the same point.
//!
//! `weld` merges vertices whose position *and* attributes are bitwise identical, so attribute seams
//! (same position, different UV, normal or colour) survive as separate vertices. `weld_positions`
//! merges by position alone; the simplifier uses it to see the surface's true topology through seams.

use super::Mesh;
// FxHash: position keys are trusted numbers, not attacker-chosen strings, and SipHash made
// grouping 540k positions a visible share of setup time in profiles.
use rustc_hash::FxHashMap as HashMap;

/// A welded mesh and, for each input vertex, the vertex it became.
#[derive(Debug, Clone)]
pub struct WeldResult {
    pub mesh: Mesh,
    pub remap: Vec<u32>,
}

/// Key of a vertex: bit patterns, so that -0.0 and 0.0 differ only where they really differ
/// (we canonicalise -0.0 to 0.0 so coincident points written either way still weld).
fn bits(x: f32) -> u32 {
    if x == 0.0 { 0 } else { x.to_bits() }
}

fn group_by<K: std::hash::Hash + Eq>(n: usize, key: impl Fn(usize) -> K) -> (Vec<u32>, Vec<u32>) {
    let mut map: HashMap<K, u32> = HashMap::with_capacity_and_hasher(n, Default::default());
    let mut remap = Vec::with_capacity(n);
    let mut firsts = Vec::new();
    for v in 0..n {
        let next = firsts.len() as u32;
        let id = *map.entry(key(v)).or_insert(next);
        if id == next {
            firsts.push(v as u32);
        }
        remap.push(id);
    }
    (remap, firsts)
}

fn apply(mesh: &Mesh, remap: Vec<u32>, firsts: &[u32]) -> WeldResult {
    fn pick<T: Copy>(firsts: &[u32], src: &[T]) -> Vec<T> {
        firsts.iter().map(|&v| src[v as usize]).collect()
    }
    let out = Mesh {
        positions: pick(firsts, &mesh.positions),
        triangles: mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| remap[v as usize]))
            .collect(),
        normals: mesh.normals.as_deref().map(|s| pick(firsts, s)),
        uvs: mesh.uvs.as_deref().map(|s| pick(firsts, s)),
        colors: mesh.colors.as_deref().map(|s| pick(firsts, s)),
        ..mesh.clone_without_geometry()
    };
    WeldResult { mesh: out, remap }
}

/// Merges vertices with identical position and attributes; faces are kept (even ones that become
/// degenerate, which the topology report then counts).
pub fn weld(mesh: &Mesh) -> WeldResult {
    let key = |v: usize| {
        let mut k: Vec<u32> = mesh.positions[v].iter().map(|&x| bits(x)).collect();
        if let Some(n) = &mesh.normals {
            k.extend(n[v].iter().map(|&x| bits(x)));
        }
        if let Some(t) = &mesh.uvs {
            k.extend(t[v].iter().map(|&x| bits(x)));
        }
        if let Some(c) = &mesh.colors {
            k.extend(c[v].iter().map(|&x| bits(x)));
        }
        k
    };
    if mesh.normals.is_none() && mesh.uvs.is_none() && mesh.colors.is_none() {
        return weld_positions(mesh);
    }
    let (remap, firsts) = group_by(mesh.positions.len(), key);
    apply(mesh, remap, &firsts)
}

/// Merges vertices by position only; the attributes of the first vertex at a position win.
pub fn weld_positions(mesh: &Mesh) -> WeldResult {
    let (remap, firsts) = position_classes(&mesh.positions);
    apply(mesh, remap, &firsts)
}

/// For each vertex the id of its position class, and each class's first vertex.
pub(crate) fn position_classes(positions: &[[f32; 3]]) -> (Vec<u32>, Vec<u32>) {
    group_by(positions.len(), |v| positions[v].map(bits))
}

impl Mesh {
    /// A copy of the per-face and material data with empty vertex data, for rebuilding a mesh.
    pub(crate) fn clone_without_geometry(&self) -> Mesh {
        Mesh {
            positions: Vec::new(),
            triangles: Vec::new(),
            normals: None,
            uvs: None,
            uv_origin: self.uv_origin,
            colors: None,
            face_materials: self.face_materials.clone(),
            materials: self.materials.clone(),
            material_libs: self.material_libs.clone(),
            face_groups: self.face_groups.clone(),
            groups: self.groups.clone(),
            textures: self.textures.clone(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weld_merges_duplicates_and_keeps_seams() {
        // Two triangles sharing edge (1,2), stored with the shared corners duplicated; one copy of
        // corner 2 has a different UV, so it is a seam and must stay separate.
        let mut m = Mesh::new(
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [1., 0., 0.],
                [0., 1., 0.],
                [1., 1., 0.],
            ],
            vec![[0, 1, 2], [3, 5, 4]],
        );
        m.uvs = Some(vec![
            [0., 0.],
            [1., 0.],
            [0., 1.],
            [1., 0.],
            [0.5, 1.],
            [1., 1.],
        ]);
        let w = weld(&m);
        assert_eq!(w.mesh.positions.len(), 5);
        assert_eq!(w.remap, vec![0, 1, 2, 1, 3, 4]);
        let p = weld_positions(&m);
        assert_eq!(p.mesh.positions.len(), 4);
        assert_eq!(p.mesh.triangles, vec![[0, 1, 2], [1, 3, 2]]);
    }
}
