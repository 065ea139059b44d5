//! What a streaming reader hands over as it reads, element by element: the in-memory readers
//! collect it into a [`Mesh`]; the out-of-core clustering (Lindstrom, "Out-of-Core
//! Simplification of Large Polygonal Models", SIGGRAPH 2000) keeps the positions and consumes
//! the faces as they stream past, so a scan's faces are never all in memory.

use crate::mesh::Mesh;

/// Which attributes the file's vertices carry.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct VertexAttributes {
    pub normals: bool,
    pub colors: bool,
    pub uvs: bool,
}

/// One vertex as read; the attributes the file lacks are zero.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
    pub color: [f32; 4],
    pub uv: [f32; 2],
}

/// The receiver of a streaming read. Indices are checked by the reader before they arrive.
pub trait Sink {
    /// Whether this pass reads the vertices; when not, the reader skips them (it still knows
    /// their count, to check the faces' indices).
    fn wants_vertices(&self) -> bool {
        true
    }
    /// Whether this pass reads the faces; when not, the reader stops after the vertices.
    fn wants_faces(&self) -> bool {
        true
    }
    /// Before the vertices: at most how many to reserve for, and the attributes they carry.
    fn begin_vertices(&mut self, _reserve: usize, _attributes: VertexAttributes) {}
    fn vertex(&mut self, v: &Vertex);
    /// Before a run of faces: at most how many to reserve for.
    fn begin_faces(&mut self, _reserve: usize) {}
    fn triangle(&mut self, t: [u32; 3]);
}

/// Collects everything into a [`Mesh`] (the attributes the file has).
#[derive(Default)]
pub struct MeshSink {
    pub mesh: Mesh,
    attributes: VertexAttributes,
}

impl MeshSink {
    pub fn into_mesh(self) -> Mesh {
        self.mesh
    }
}

impl Sink for MeshSink {
    fn begin_vertices(&mut self, reserve: usize, a: VertexAttributes) {
        let m = &mut self.mesh;
        self.attributes = a;
        m.positions.reserve(reserve);
        m.normals = a.normals.then(|| Vec::with_capacity(reserve));
        m.colors = a.colors.then(|| Vec::with_capacity(reserve));
        m.uvs = a.uvs.then(|| Vec::with_capacity(reserve));
    }

    fn vertex(&mut self, v: &Vertex) {
        let m = &mut self.mesh;
        m.positions.push(v.position);
        if let Some(n) = m.normals.as_mut() {
            n.push(v.normal);
        }
        if let Some(c) = m.colors.as_mut() {
            c.push(v.color);
        }
        if let Some(uv) = m.uvs.as_mut() {
            uv.push(v.uv);
        }
    }

    fn begin_faces(&mut self, reserve: usize) {
        self.mesh.triangles.reserve(reserve);
    }

    fn triangle(&mut self, t: [u32; 3]) {
        self.mesh.triangles.push(t);
    }
}
