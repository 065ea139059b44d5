//! A cluster DAG on screen: every level's triangles uploaded once, and per frame the cut
//! ([`crate::dag::gpu::GpuCut`]) chosen on the device for the camera, which the renderer draws
//! from with no read-back — the clusters whose error projects under the threshold, in view
//! (Karis et al. 2021). The frame-timing loop `view --frames` runs is here too, for a DAG and
//! a plain mesh alike.

use super::camera::Camera;
use super::render::{Extras, Renderer, SceneMesh, Style, Target, vertex_normals};
use crate::compute::gpu::Pipelines;
use crate::compute::types::CutParams;
use crate::dag::gpu::GpuCut;
use crate::dag::{CameraCut, Dag};
use crate::error::Result;
use crate::rounds::gpu::GpuMesh;
use glam::{Mat4, Vec3};
use std::time::Instant;

/// A DAG ready to draw: its triangles as one mesh, in the normalized frame of its input
/// (`center`, `scale`), and its cut on the same device.
pub struct DagScene {
    pub scene: SceneMesh,
    pub cut: GpuCut,
    /// The clusters as the cut reads them, kept for the host's counts.
    clusters: Vec<crate::compute::types::CutCluster>,
    /// The device reads indirect first instances: the cut numbers each cluster's draw.
    pub numbered: bool,
    /// Per cluster, the largest heatmap distance of its vertices (empty without distances).
    cluster_error: Vec<f32>,
    center: [f64; 3],
    scale: f64,
    /// The last host cut and the parameters it was taken with: the panel's counts and the
    /// heatmap's top ask for the same cut in a frame, and the camera is mostly still.
    last_cut: std::cell::RefCell<Option<HostCut>>,
}

/// A cut taken on the host: its parameters, each cluster's draw and the counts.
type HostCut = (
    crate::compute::types::CutParams,
    Vec<crate::compute::types::CornerDraw>,
    [u32; 4],
);

impl DagScene {
    /// `dag` uploaded on the device of `pipelines`, in the normalized frame (`center`,
    /// `scale`) of its input, the first level, as its model draws it
    /// ([`super::scene::Model::leaves_of`]); `error` is each vertex's distance to that level
    /// for the heatmap ([`super::scene::Model::dag_errors`]; empty draws it all blue).
    pub fn new(
        pipelines: &Pipelines,
        queue: &wgpu::Queue,
        dag: &Dag,
        (center, scale): ([f64; 3], f64),
        error: Vec<f32>,
    ) -> Result<DagScene> {
        let device = pipelines.device();
        let positions: Vec<[f32; 4]> = dag
            .mesh
            .positions
            .iter()
            .map(|&p| {
                let n = crate::mesh::prepare::normalize(p, center, scale);
                [n[0] as f32, n[1] as f32, n[2] as f32, 1.0]
            })
            .collect();
        let indices: &[u32] = dag.mesh.triangles.as_flattened();
        let gpu = GpuMesh::from_arrays(device, &positions, indices, center, scale)?;
        let cluster_error: Vec<f32> = match error.is_empty() {
            true => Vec::new(),
            false => dag
                .clusters
                .iter()
                .map(|c| {
                    let tris = dag.triangles(c).iter().flatten();
                    tris.fold(0f32, |m, &v| m.max(error[v as usize]))
                })
                .collect(),
        };
        let extras = Extras {
            error,
            // Every level's faces around a vertex: they approximate one surface.
            normals: vertex_normals(&positions, indices),
            // Per corner, as a mesh's: the DAG's vertices carry the input's UVs and colours.
            uvs: super::corners::corner_uvs(&dag.mesh, indices),
            colors: super::corners::corner_colors(&dag.mesh, indices.iter().copied()),
        };
        let mut scene = SceneMesh::new(
            device,
            gpu,
            positions.len(),
            dag.mesh.triangles.len(),
            &extras,
        )?;
        let clusters = dag.cut_clusters();
        let cut = GpuCut::new(pipelines, queue, &clusters)?;
        scene.cluster_draws = Some((cut.draws.clone(), cut.clusters()));
        scene.levels = dag.levels() as u32;
        Ok(DagScene {
            scene,
            cut,
            clusters,
            numbered: device
                .features()
                .contains(wgpu::Features::INDIRECT_FIRST_INSTANCE),
            cluster_error,
            center,
            scale,
            last_cut: std::cell::RefCell::new(None),
        })
    }

    /// What the cut for `cam` at `pixels` draws, by the twin of the device's stage on the host
    /// (the panel's counts; the device's own are never read back while drawing): clusters in
    /// the cut, clusters drawn, triangles drawn.
    pub fn counts(&self, cam: &Camera, size: (u32, u32), pixels: f64) -> [u32; 4] {
        self.with_host_cut(cam, size, pixels, |_, counts| *counts)
    }

    /// The top of the heatmap for the cut of `cam`: the largest distance of a drawn cluster's
    /// vertices, as a mesh's heatmap tops at its own largest (0 without distances).
    pub fn heat_top(&self, cam: &Camera, size: (u32, u32), pixels: f64) -> f32 {
        if self.cluster_error.is_empty() {
            return 0.0;
        }
        self.with_host_cut(cam, size, pixels, |draws, _| {
            (draws.iter().zip(&self.cluster_error))
                .filter(|(d, _)| d.instance_count > 0)
                .fold(0f32, |m, (_, &e)| m.max(e))
        })
    }

    /// `f` of the cut of `cam` by the stage's twin on the host (each cluster's draw, and the
    /// counts), taken again only when its parameters changed.
    fn with_host_cut<T>(
        &self,
        cam: &Camera,
        size: (u32, u32),
        pixels: f64,
        f: impl FnOnce(&[crate::compute::types::CornerDraw], &[u32; 4]) -> T,
    ) -> T {
        let p = self.cut_params(cam, size, pixels);
        let mut last = self.last_cut.borrow_mut();
        if last.as_ref().is_none_or(|(q, _, _)| *q != p) {
            let mut draws = vec![crate::compute::types::CornerDraw::default(); self.clusters.len()];
            let mut counts = [0; 4];
            crate::dag::cut::dag_cut(&p, &self.clusters, &mut draws, &mut counts);
            *last = Some((p, draws, counts));
        }
        let (_, draws, counts) = last.as_ref().expect("taken just above");
        f(draws, counts)
    }

    /// The cut of `cam` at `pixels` on a `size` view, as `dag cut --camera` takes it: the eye
    /// in the DAG's own units, the vertical field of view and the view's height.
    pub fn camera_cut(&self, cam: &Camera, size: (u32, u32), pixels: f64) -> CameraCut {
        let eye = cam.model.inverse().transform_point3(cam.eye());
        CameraCut {
            eye: [0, 1, 2].map(|i| eye[i] as f64 / self.scale + self.center[i]),
            pixels,
            fov_deg: (cam.fov_y as f64).to_degrees(),
            height: size.1 as f64,
        }
    }

    /// The cut's uniform for `cam` on a `size` view at `pixels`: the error test, and the
    /// frustum of the view.
    pub fn cut_params(&self, cam: &Camera, size: (u32, u32), pixels: f64) -> CutParams {
        let mut p = self
            .camera_cut(cam, size, pixels)
            .params(self.cut.clusters() as usize);
        // The DAG's units into the normalized frame the camera sees, then the view.
        let c = Vec3::from_array(self.center.map(|x| x as f32));
        let to_frame =
            Mat4::from_scale(Vec3::splat(self.scale as f32)) * Mat4::from_translation(-c);
        let aspect = size.0 as f32 / size.1 as f32;
        p.planes = crate::dag::cut::frustum_planes(cam.proj_view(aspect) * cam.model * to_frame);
        p.cull = 1;
        p.number = self.numbered as u32;
        p
    }
}

/// Draws `frames` frames of `scene` into `target` as `view` = (camera, style) sees it, each
/// submitted and waited for (`before` records what a frame needs first: a DAG's cut); the
/// seconds of each.
pub fn time_frames(
    ctx: &crate::compute::context::GpuContext,
    renderer: &mut Renderer,
    target: &Target,
    (cam, style): (&Camera, &Style),
    scene: &SceneMesh,
    frames: usize,
    before: &mut dyn FnMut(&mut wgpu::CommandEncoder),
) -> Result<Vec<f64>> {
    let items = [(scene, cam.model)];
    let mut seconds = Vec::with_capacity(frames);
    for _ in 0..frames {
        let t = Instant::now();
        let mut enc = ctx.device.create_command_encoder(&Default::default());
        before(&mut enc);
        renderer.draw(
            &ctx.device,
            &ctx.queue,
            &mut enc,
            target,
            cam,
            style,
            &items,
        );
        ctx.queue.submit([enc.finish()]);
        ctx.device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| crate::error::Error::Gpu(format!("drawing a frame: {e}")))?;
        seconds.push(t.elapsed().as_secs_f64());
    }
    Ok(seconds)
}
