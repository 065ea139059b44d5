//! Backend `gpu`: the rounds as WGSL compute passes run by wgpu.

pub mod types;

use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::simplify::{SimplifyOptions, SimplifyReport};

pub fn simplify_gpu(
    _mesh: &Mesh,
    _opts: &SimplifyOptions,
    _progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    Err(Error::Gpu("not yet built".into()))
}
