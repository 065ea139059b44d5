//! Grouped rounds ([`crate::compute::types::Params::groups`]): every group of faces
//! simplified in one run, each to its own target — a level of the cluster DAG (`crate::dag`),
//! the vertices groups share pinned. The stages are `group_flags`, `group_errors`,
//! `group_faces` and `group_open` (their twins are the files of those names in `cpu`).

use super::{SELECTION_PASSES, Upload, cpu, drive, gpu};
use crate::error::Result;
use crate::mesh::Mesh;
use crate::options::SimplifyOptions;

/// Grouped rounds' input: the cluster DAG simplifies every group of a level in one run, each
/// to its own target, the vertices the groups share pinned.
#[derive(Debug, Clone)]
pub struct UploadGroups {
    /// Per input face: its group.
    pub face_group: Vec<u32>,
    /// Per group: the faces it keeps at most.
    pub targets: Vec<u32>,
    /// Per group: 1 when its kept faces are already at or under its target.
    pub closed: Vec<u32>,
    /// Groups over their target, the faces they are over it and all their faces, before the
    /// first round.
    pub open: u32,
    pub excess: u32,
    pub open_faces: u32,
}

impl Upload {
    /// This upload with every input face in a group of its own target: `face_group[f]` is
    /// input face `f`'s group, below `targets.len()`. Every group's free vertices must have
    /// faces of that group only (pin the vertices groups share): a free vertex's first face
    /// names its group on the device. The options' target should be the targets' sum.
    pub fn grouped(mut self, face_group: Vec<u32>, targets: Vec<u32>) -> Result<Upload> {
        let bad = |m: String| Err(crate::error::Error::InvalidOption(m));
        if face_group.len() != self.welded.triangles.len() {
            return bad(format!(
                "{} face groups for {} faces",
                face_group.len(),
                self.welded.triangles.len()
            ));
        }
        if targets.is_empty() || u32::try_from(targets.len()).is_err() {
            return bad(format!("{} groups: 1 to 2^32 - 1 wanted", targets.len()));
        }
        if let Some(g) = face_group.iter().find(|&&g| g as usize >= targets.len()) {
            return bad(format!("face group {g} of {} groups", targets.len()));
        }
        let mut count = vec![0u32; targets.len()];
        for x in &self.face_extra {
            count[face_group[x.origin as usize] as usize] += 1;
        }
        // The first round's open groups as `group_open` finds them after a round.
        let params = crate::compute::types::Params {
            groups: targets.len() as u32,
            ..Default::default()
        };
        let mut closed = vec![0u32; targets.len()];
        let mut counters = [0u32; 16];
        cpu::group_open::group_open(
            &params,
            &targets,
            &mut count,
            &mut closed,
            cpu::atomics(&mut counters),
        );
        let c: crate::compute::types::Counters = bytemuck::cast(counters);
        let (open, excess, open_faces) = (c.open_groups, c.open_excess, c.open_faces);
        self.groups = Some(UploadGroups {
            face_group,
            targets,
            closed,
            open,
            excess,
            open_faces,
        });
        Ok(self)
    }
}

/// Grouped rounds on `backend` (`cpu-parallel` or `gpu`): every group of `mesh`'s faces
/// (`mesh.face_groups`, below `targets.len()`) simplified in one run to at most its target, or
/// as near as its collapses allow, the input vertices `opts.pin` kept (pin every vertex two
/// groups share: see [`Upload::grouped`]). The run never trims, so a group's last round may
/// take it under its target. The result keeps each face's group in `face_groups`; beside it,
/// each group's largest collapse error in mesh units (0 where nothing collapsed).
pub fn simplify_grouped(
    mesh: &Mesh,
    targets: Vec<u32>,
    backend: crate::options::Backend,
    opts: &SimplifyOptions,
) -> Result<(Mesh, Vec<f64>)> {
    use crate::options::Backend;
    mesh.validate()?;
    let face_group = mesh.face_groups.clone().ok_or_else(|| {
        crate::error::Error::InvalidOption("grouped rounds need the faces' groups".into())
    })?;
    let sum: u64 = targets.iter().map(|&t| t as u64).sum();
    let opts = SimplifyOptions {
        backend,
        target_faces: sum.min(u32::MAX as u64) as usize,
        ..opts.clone()
    };
    let up = Upload::pinned(mesh, &opts.pin)
        .attributes(&opts.attributes)
        .grouped(face_group, targets)?;
    let down = match backend {
        Backend::CpuParallel => {
            let mut runner = cpu::CpuRounds::new(&up, SELECTION_PASSES);
            drive(&mut runner, &up, &opts, &mut |_| {})?;
            crate::rounds::RoundRunner::download(&mut runner)?
        }
        Backend::Gpu => {
            let (_, sim) = gpu::shared()?;
            let mut runner = gpu::GpuRounds::new(sim, &up, SELECTION_PASSES)?;
            drive(&mut runner, &up, &opts, &mut |_| {})?;
            crate::rounds::RoundRunner::download(&mut runner)?
        }
        b => {
            return Err(crate::error::Error::Internal(format!(
                "grouped rounds run on cpu-parallel or gpu, not {}",
                b.name()
            )));
        }
    };
    let out = up.build_output(&down, mesh.normals.is_some());
    let errors = down
        .group_err
        .iter()
        .map(|&b| (f32::from_bits(b) as f64).sqrt() / up.scale)
        .collect();
    Ok((out, errors))
}
