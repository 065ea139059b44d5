//! The QEM rounds, one family in one folder: their schedule ([`schedule`]: every stage and the
//! order they run in), the appearance they carry ([`attributes`]), and the backends that run the
//! stages — [`gpu`] (the WGSL passes, shaders/rounds/) and [`cpu`] (`cpu-parallel`: each
//! stage's CPU twin, the same bytes). This file is the round driver both share: what is
//! uploaded, how many collapses each round aims for, when it trims to land on the target, why
//! it stops, and how the result becomes a [`Mesh`] again. The backends only run the stages
//! ([`RoundRunner`]).

pub mod attributes;
// The CPU twins: internals, public (and hidden from the docs) only so that the integration
// tests can diff the GPU's buffers stage by stage.
#[doc(hidden)]
pub mod cpu;
pub mod gpu;
mod grouped;
pub mod prepare;
pub mod schedule;

pub use attributes::RoundAttributes;
pub use grouped::{UploadGroups, simplify_grouped};

use crate::compute::types::{Counters, FaceExtra, Params, flag};
use crate::error::Result;
use crate::mesh::prepare::Surface;
use crate::mesh::{Mesh, first_use};
pub use crate::options::{RoundsReport, StageTimes};
use crate::options::{SimplifyOptions, SimplifyReport, StopReason};
use cpu::plan_round;

/// Selection passes per round. One pass removes ~5% of the faces per round, three ~15%
/// (ARCHITECTURE.md's prototype); more passes add little once most candidates are blocked.
pub const SELECTION_PASSES: u32 = 4;
/// The cost ceiling lets this many times the collapses still needed compete: fewer keeps the
/// order closer to greedy, more needs fewer rounds.
pub const CEILING_FACTOR: u32 = 2;
/// ...but never fewer candidates than this share of the faces: near the target, a ceiling sized
/// to the few collapses still needed let each round remove only a fraction of them (a long tail
/// of small rounds); trimming lands the face count on the target instead.
pub const CEILING_MIN_SHARE: f64 = 0.25;
/// A round trims its winners once the faces still to remove fall below this share of the
/// faces: a round never removes more than about a third of them.
pub const TRIM_SHARE: f64 = 0.4;
/// Safety net: a run that has not converged after this many rounds stops.
pub const MAX_ROUNDS: usize = 400;
/// Rounds a batch runs between two waits for the host, each planned on the device from the last
/// one's counters (`plan_round`): the 1M scan to 1% takes about 30 rounds, so four or five
/// waits; rounds past a batch's stop dispatch nothing, so a longer batch costs only their
/// empty passes.
pub const BATCH_ROUNDS: usize = 8;

/// How many selection passes a round runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Selection {
    /// The runner's fixed count ([`SELECTION_PASSES`]).
    Ordinary,
    /// Passes until one picks no tentative winner. A candidate that fails `validate` (the link
    /// condition, say) blocks its neighbours for the pass it wins; on a small mesh most edges
    /// fail so, and four passes can all go to them (bunny at 0.1% stopped at 144 faces where
    /// the greedy reaches 69). Each pass settles every tentative winner, so this ends, and the
    /// best valid candidate of the whole mesh always wins: a round removes nothing only when no
    /// valid collapse is left.
    Exhaustive,
}

/// One backend's stage runner: the same rounds on GPU buffers or CPU slices.
pub trait RoundRunner {
    /// Runs one round with `params` (the first also computes face planes, flags and quadrics)
    /// and returns its counters.
    fn round(&mut self, params: &Params, first: bool, selection: Selection) -> Result<Counters>;
    /// Ordinary rounds from `params` on, at most `most`, each after the first planned by the
    /// runner from the last one's counters (`cpu::plan_round`) until one removes nothing, grows
    /// the mesh or reaches the target: each round's parameters and counters, in order.
    fn rounds(
        &mut self,
        params: &Params,
        first: bool,
        most: usize,
    ) -> Result<Vec<(Params, Counters)>> {
        let _ = most;
        Ok(vec![(
            *params,
            self.round(params, first, Selection::Ordinary)?,
        )])
    }
    /// How many rounds [`RoundRunner::rounds`] runs at most between two looks of the driver.
    fn batch(&self) -> usize {
        1
    }
    /// The current mesh, read back; the rounds can go on afterwards.
    fn download(&mut self) -> Result<Download>;
    fn stage_times(&self) -> &StageTimes;
}

/// The surface as the rounds see it: position classes (a seam's vertices share one), Morton
/// ordered, normalized into the unit-diagonal box centred on the origin.
#[derive(Clone)]
pub struct Upload {
    /// The input after exact welding: its vertices are the attribute vertices written out.
    pub welded: Mesh,
    /// Per class: position (w = 1).
    pub positions: Vec<[f32; 4]>,
    /// Per face × 3: class ids.
    pub indices: Vec<u32>,
    /// Per class: SEAM for seams (more than one attribute vertex used).
    pub flags: Vec<u32>,
    /// Per class: one attribute vertex the faces use.
    pub vertex_attr: Vec<u32>,
    pub face_extra: Vec<FaceExtra>,
    pub center: [f64; 3],
    pub scale: f64,
    pub dropped_degenerate: usize,
    /// Seam vertices.
    pub seams: usize,
    /// Per class: the quadric carried in (the hybrid method's clusters), relative to the
    /// vertex; `None` computes them in the first round.
    pub quadrics: Option<Vec<crate::compute::types::Quadric>>,
    /// Per face: the first round's plane (unit normal, area), carried in with the quadrics: the
    /// face's own, or with [`Upload::reference_normals`] the normal of the input face it came
    /// from, which the flip test measures turning from.
    pub face_planes: Option<Vec<[f32; 4]>>,
    /// The appearance channels carried ([`Upload::attributes`]); `None`: none, and the rounds
    /// run as without.
    pub attrs: Option<RoundAttributes>,
    /// Targets per group of faces ([`Upload::grouped`]); `None`: one target for the mesh.
    pub groups: Option<UploadGroups>,
    /// Prepared on the device ([`Upload::on_device`]): the rounds' vertices and faces, whose
    /// arrays are there alone (the ones here stay empty).
    pub device_counts: Option<(u32, u32)>,
}

/// The attribute vertex (of the welded input) of every corner of the rounds' faces: a seam
/// corner's own, which the collapses keep current, any other corner's its vertex's.
pub fn corner_attributes(
    flags: &[u32],
    vertex_attr: &[u32],
    indices: &[u32],
    face_extra: &[FaceExtra],
) -> Vec<u32> {
    indices
        .iter()
        .enumerate()
        .map(|(c, &v)| {
            let v = v as usize;
            if flags[v] & flag::SEAM != 0 {
                face_extra[c / 3].attr[c % 3]
            } else {
                vertex_attr[v]
            }
        })
        .collect()
}

/// The rounds' buffers read back at the end.
#[derive(Debug, Clone, Default)]
pub struct Download {
    pub positions: Vec<[f32; 4]>,
    pub flags: Vec<u32>,
    pub vertex_attr: Vec<u32>,
    pub indices: Vec<u32>,
    /// Per face; empty when the output needs none ([`Upload::output_needs_face_extra`]).
    pub face_extra: Vec<FaceExtra>,
    /// Per attribute vertex: the weighted appearance values (empty without).
    pub attr_values: Vec<f32>,
    /// Grouped rounds: per group, the largest squared error of its collapses, as f32 bits
    /// (empty without groups).
    pub group_err: Vec<u32>,
}

impl Upload {
    /// This upload carrying the welded input's appearance channels that `w` weighs above zero.
    pub fn attributes(mut self, w: &crate::options::AttributeWeights) -> Upload {
        self.attrs = RoundAttributes::new(&self.welded, w);
        self
    }

    /// The carried face planes with each face's normal replaced by `normals[f]` for the face
    /// `f` of the input it came from (the hybrid: the original's face under a cluster face),
    /// so that the rounds' flip test measures turning from there; a face whose plane has no
    /// area, or whose given normal is zero, keeps its own.
    pub fn reference_normals(mut self, normals: &[[f32; 3]]) -> Upload {
        if let Some(planes) = &mut self.face_planes {
            for (pl, x) in planes.iter_mut().zip(&self.face_extra) {
                match normals.get(x.origin as usize) {
                    Some(&n) if pl[3] > 0.0 && n != [0.0; 3] => *pl = [n[0], n[1], n[2], pl[3]],
                    _ => {}
                }
            }
        }
        self
    }

    /// Whether this upload carries the channels `w` asks for (a copy with
    /// [`Upload::attributes`] otherwise).
    pub fn carries(&self, w: &crate::options::AttributeWeights) -> bool {
        let wanted = crate::quadric::attributes::Layout::new(&self.welded, w);
        wanted.as_ref() == self.attrs.as_ref().map(|a| &a.layout)
    }

    /// The welded input's colours and UVs as the rounds left them (`d`'s solved values in place
    /// of the input's), without geometry: what a renderer draws a result's corners with.
    pub fn solved_appearance(&self, d: &Download) -> Mesh {
        let mut m = self.welded.clone_without_geometry();
        m.colors = self.welded.colors.clone();
        m.uvs = self.welded.uvs.clone();
        if let Some(a) = &self.attrs {
            a.write(&d.attr_values, &mut m);
        }
        m
    }

    /// The first round's values of the attribute vertices (empty without channels).
    pub fn attr_values(&self) -> Vec<f32> {
        self.attrs.as_ref().map_or(Vec::new(), |a| a.values.clone())
    }

    /// Numbers of the attribute sums (0 without channels).
    pub fn attr_sums_len(&self) -> usize {
        self.attrs.as_ref().map_or(0, |a| a.sums_len())
    }

    pub fn new(input: &Mesh) -> Upload {
        Upload::pinned(input, &[])
    }

    /// As [`Upload::new`], with the input vertices `pin` flagged PINNED, which `vertex_flags`
    /// keeps (`SimplifyOptions::pin`: a tile's border).
    pub fn pinned(input: &Mesh, pin: &[u32]) -> Upload {
        Upload::from_surface(Surface::new(input), None, pin)
    }

    /// The upload of `input` in the frame `(center, scale)`, with each input vertex's quadric
    /// (relative to it, in that frame) carried in; vertices welded together sum theirs.
    pub fn with_quadrics(
        input: &Mesh,
        frame: ([f64; 3], f64),
        quadrics: &[crate::compute::types::Quadric],
    ) -> Upload {
        let surface = Surface::in_frame(input, Some(frame));
        let carried = quadrics
            .iter()
            .zip(&surface.weld_remap)
            .map(|(q, &w)| (surface.class[w as usize], q))
            .collect::<Vec<_>>();
        Upload::from_surface(surface, Some(carried), &[])
    }

    /// `carried`: (class, quadric) pairs to sum per class; `pin`: input vertices to pin.
    fn from_surface(
        surface: Surface,
        carried: Option<Vec<(u32, &crate::compute::types::Quadric)>>,
        pin: &[u32],
    ) -> Upload {
        let s = &surface;
        // Classes the faces use, renumbered densely (still in Morton order).
        let mut dense = vec![u32::MAX; s.class_count()];
        let mut n = 0u32;
        for (c, d) in dense.iter_mut().enumerate() {
            if s.attr_count[c] > 0 {
                *d = n;
                n += 1;
            }
        }
        let mut positions = vec![[0.0f32; 4]; n as usize];
        let mut flags = vec![0u32; n as usize];
        let mut vertex_attr = vec![0u32; n as usize];
        for (c, &d) in dense.iter().enumerate() {
            if d != u32::MAX {
                let d = d as usize;
                let a = s.representative[c];
                let q = s
                    .normalize(s.welded.positions[a as usize])
                    .map(|x| x as f32);
                positions[d] = [q[0], q[1], q[2], 1.0];
                vertex_attr[d] = a;
                if s.is_seam(c) {
                    flags[d] = flag::SEAM;
                }
            }
        }
        let indices: Vec<u32> = s
            .faces
            .iter()
            .flat_map(|t| t.map(|v| dense[s.class[v as usize] as usize]))
            .collect();
        let face_extra = s
            .faces
            .iter()
            .zip(&s.face_origin)
            .map(|(&attr, &origin)| FaceExtra { attr, origin })
            .collect();
        let seams = flags.iter().filter(|&&f| f != 0).count();
        for &v in pin {
            let d = dense[s.class[s.weld_remap[v as usize] as usize] as usize];
            if d != u32::MAX {
                flags[d as usize] |= flag::PINNED;
            }
        }
        let quadrics = carried.map(|pairs| {
            let mut q = vec![crate::compute::types::Quadric::default(); n as usize];
            for (c, x) in pairs {
                let d = dense[c as usize];
                if d != u32::MAX {
                    q[d as usize] = crate::compute::common::quadric_add(&q[d as usize], x);
                }
            }
            q
        });
        let face_planes = quadrics.as_ref().map(|_| {
            let p = Params {
                face_count: s.faces.len() as u32,
                ..Default::default()
            };
            let mut planes = vec![[0.0f32; 4]; s.faces.len()];
            crate::rounds::cpu::face_planes::face_planes(&p, &positions, &indices, &mut planes);
            planes
        });
        let Surface {
            welded,
            center,
            scale,
            dropped_degenerate,
            ..
        } = surface;
        Upload {
            positions,
            indices,
            flags,
            vertex_attr,
            face_extra,
            welded,
            center,
            scale,
            dropped_degenerate,
            seams,
            quadrics,
            face_planes,
            attrs: None,
            groups: None,
            device_counts: None,
        }
    }

    /// The upload of a plain `mesh` the device prepared ([`crate::rounds::prepare`]) into
    /// `vertices` and `faces`, in the frame `(center, scale)`: the arrays stay on the device,
    /// and the vertex and corner attributes there name `mesh`'s own vertices (the first input
    /// vertex of each welded one), so the output is built from `mesh`
    /// ([`Upload::output_base`]).
    pub fn on_device(
        mesh: &Mesh,
        vertices: u32,
        faces: u32,
        (center, scale): ([f64; 3], f64),
    ) -> Upload {
        Upload {
            welded: mesh.clone_without_geometry(),
            positions: Vec::new(),
            indices: Vec::new(),
            flags: Vec::new(),
            vertex_attr: Vec::new(),
            face_extra: Vec::new(),
            center,
            scale,
            dropped_degenerate: mesh.triangles.len() - faces as usize,
            seams: 0,
            quadrics: None,
            face_planes: None,
            attrs: None,
            groups: None,
            device_counts: Some((vertices, faces)),
        }
    }

    /// The mesh the output's vertices come from: the welded input, or for an upload the device
    /// prepared, `input` itself.
    pub fn output_base<'m>(&'m self, input: &'m Mesh) -> &'m Mesh {
        if self.device_counts.is_some() {
            input
        } else {
            &self.welded
        }
    }

    pub fn vertex_count(&self) -> usize {
        self.device_counts
            .map_or(self.positions.len(), |(v, _)| v as usize)
    }

    pub fn face_count(&self) -> usize {
        self.device_counts
            .map_or(self.face_extra.len(), |(_, f)| f as usize)
    }

    /// Whether the output needs the faces' extras read back: a seam corner's attribute vertex,
    /// or the input face a face came from for its material or group. Without either, a
    /// download may leave [`Download::face_extra`] empty.
    pub fn output_needs_face_extra(&self) -> bool {
        self.seams > 0 || self.welded.face_materials.is_some() || self.welded.face_groups.is_some()
    }

    /// The round parameters common to every round.
    pub fn base_params(&self, opts: &SimplifyOptions) -> Params {
        let (attributes, color_weight) = self.attrs.as_ref().map_or((0, 0.0), |a| a.params());
        Params {
            attributes,
            color_weight,
            vertex_count: self.vertex_count() as u32,
            face_count: self.face_count() as u32,
            edge_capacity: 3 * self.face_count() as u32,
            target_faces: opts.target_faces as u32,
            lock_border: opts.lock_border as u32,
            cos_max_angle: opts.max_normal_angle_deg.to_radians().cos() as f32,
            min_quality: opts.min_quality as f32,
            quality_threshold: opts.quality_threshold as f32,
            border_weight: opts.border_weight as f32,
            max_error2: opts.max_error.map_or(f32::MAX, |e| (e * e) as f32),
            groups: self.groups.as_ref().map_or(0, |g| g.targets.len() as u32),
            ..Default::default()
        }
    }

    /// The output mesh: the rounds' faces as attribute vertices of the welded input (a seam
    /// corner keeps its own, any other corner takes its class's), moved vertices taken out of
    /// the normalized frame, materials and groups per face, unused vertices dropped.
    pub fn build_output(&self, d: &Download, normals: bool) -> Mesh {
        self.build_output_on(&self.welded, d, normals)
    }

    /// As [`Upload::build_output`], the vertices taken from `base` ([`Upload::output_base`]).
    pub fn build_output_on(&self, base: &Mesh, d: &Download, normals: bool) -> Mesh {
        let mut out = self.welded.clone_without_geometry();
        let to_world =
            |p: &[f32; 4]| [0, 1, 2].map(|i| (p[i] as f64 / self.scale + self.center[i]) as f32);
        let moved =
            || (d.positions.iter().enumerate()).filter(|(v, _)| d.flags[*v] & flag::MOVED != 0);
        let nf = d.indices.len() / 3;
        let attrs = corner_attributes(&d.flags, &d.vertex_attr, &d.indices, &d.face_extra);
        let triangles: Vec<[u32; 3]> = attrs.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        let origin = |f: usize| d.face_extra[f].origin as usize;
        out.face_materials = self
            .welded
            .face_materials
            .as_ref()
            .map(|m| (0..nf).map(|f| m[origin(f)]).collect());
        out.face_groups = self
            .welded
            .face_groups
            .as_ref()
            .map(|g| (0..nf).map(|f| g[origin(f)]).collect());
        let mut normals = normals;
        if let Some(a) = &self.attrs {
            // The solved appearance is written at the input's attribute vertices, so the
            // output starts as the whole input and drops what no face uses.
            out.positions = base.positions.clone();
            out.uvs = base.uvs.clone();
            out.colors = base.colors.clone();
            for (v, p) in moved() {
                out.positions[d.vertex_attr[v] as usize] = to_world(p);
            }
            out.triangles = triangles;
            if a.keeps_normals() {
                out.normals = base.normals.clone();
            }
            a.write(&d.attr_values, &mut out);
            normals &= !a.keeps_normals();
            out.remove_unused_vertices();
        } else {
            // Only the vertices the faces use are copied, in the order of their first use (as
            // remove_unused_vertices numbers them): at 1% that is about 1% of the input's, and
            // copying the whole input first cost the 1M scan 0.010 s of its 0.05 s on the host.
            let (order, place) = first_use(&triangles, base.positions.len(), |t| *t);
            out.triangles = triangles
                .iter()
                .map(|t| t.map(|v| place[v as usize]))
                .collect();
            out.positions = crate::mesh::pick(&order, &base.positions);
            out.uvs = base.uvs.as_deref().map(|s| crate::mesh::pick(&order, s));
            out.colors = base.colors.as_deref().map(|s| crate::mesh::pick(&order, s));
            for (v, p) in moved() {
                let at = place[d.vertex_attr[v] as usize];
                if at != u32::MAX {
                    out.positions[at as usize] = to_world(p);
                }
            }
        }
        if normals {
            out.recompute_normals();
        }
        out
    }
}

/// What [`drive`] did.
pub struct Driven {
    pub stop_reason: StopReason,
    /// Largest error of an applied collapse (relative RMS distance).
    pub max_error: f64,
    /// Faces removed per round.
    pub removed: Vec<usize>,
    pub collapses: usize,
}

/// Runs rounds until the target, the error bound, or no valid collapse.
pub fn drive(
    runner: &mut dyn RoundRunner,
    up: &Upload,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<Driven> {
    let mut d = Driver::new(up, opts);
    let reason = d.run_to(runner, opts.target_faces, progress)?;
    Ok(d.finish(reason))
}

/// The rounds' loop, resumable: [`Driver::run_to`] a target, look at (or copy) the mesh, then
/// run on to a smaller target with the quadrics and history kept — the levels of detail of the
/// viewer's LOD scene are made in one run this way.
pub struct Driver {
    base: Params,
    cancel: crate::options::Cancel,
    pub vertices: usize,
    pub faces: usize,
    first: bool,
    removed: Vec<usize>,
    max_err2: f32,
    collapses: usize,
    /// Grouped rounds: the groups over their target, the faces they are over it, and all
    /// their faces.
    open_groups: u32,
    open_excess: u32,
    open_faces: u32,
}

impl Driver {
    pub fn new(up: &Upload, opts: &SimplifyOptions) -> Driver {
        let base = up.base_params(opts);
        let (open_groups, open_excess, open_faces) = up
            .groups
            .as_ref()
            .map_or((0, 0, 0), |g| (g.open, g.excess, g.open_faces));
        Driver {
            open_groups,
            open_excess,
            open_faces,
            vertices: base.vertex_count as usize,
            faces: base.face_count as usize,
            base,
            cancel: opts.cancel.clone(),
            first: true,
            removed: Vec::new(),
            max_err2: 0.0,
            collapses: 0,
        }
    }

    /// Runs rounds until `target` faces (±1), the error bound, or no valid collapse; `progress`
    /// gets the fraction of the way from where this call started.
    pub fn run_to(
        &mut self,
        runner: &mut dyn RoundRunner,
        target: usize,
        progress: &mut dyn FnMut(f32),
    ) -> Result<StopReason> {
        let target = target.min(u32::MAX as usize) as u32;
        let (mut nv, mut nf) = (self.vertices as u32, self.faces as u32);
        let from = nf;
        let start = nf.saturating_sub(target).max(1) as f32;
        // Rounds a runner ran ahead in its last batch, not yet looked at.
        let mut ahead = std::collections::VecDeque::new();
        let reason = loop {
            // Trimming lands a round on the target or one below it (an interior collapse
            // removes two faces), never above: the target is reached only when it is met.
            let reached = if self.base.groups != 0 {
                self.open_groups == 0
            } else {
                nf <= target
            };
            if reached {
                break StopReason::TargetReached;
            }
            if self.removed.len() >= MAX_ROUNDS {
                break StopReason::NoValidCollapse;
            }
            let mut params = plan_round::next_params(
                &self.base,
                nv,
                nf,
                target,
                self.open_excess,
                self.open_faces,
            );
            let mut c = match ahead.pop_front() {
                Some((planned, c)) => {
                    // The runner planned this round itself: it must be the round planned here.
                    if planned != params {
                        return Err(crate::error::Error::Internal(format!(
                            "round {}: the runner planned {planned:?}, the driver {params:?}",
                            self.removed.len() + 1
                        )));
                    }
                    c
                }
                None => {
                    self.cancel.check()?;
                    let most = runner.batch().clamp(1, MAX_ROUNDS - self.removed.len());
                    let mut batch = runner.rounds(&params, self.first, most)?.into_iter();
                    self.first = false;
                    let (_, c) = batch.next().ok_or_else(|| {
                        crate::error::Error::Internal("a batch of rounds ran none".into())
                    })?;
                    ahead.extend(batch);
                    c
                }
            };
            if c.faces_out == nf {
                // The ceiling is picked from the edges' errors, lower bounds of their priorities
                // that know nothing of flips, and the passes may all have gone to candidates
                // that failed validation: valid edges may wait above the ceiling or behind
                // them. Let every edge compete, through as many passes as it takes, before
                // concluding that none can go (the round changed nothing, so it runs again on
                // the same mesh). A batch stops at such a round, so none ran after it.
                params.ceiling_wanted = u32::MAX;
                c = runner.round(&params, false, Selection::Exhaustive)?;
            }
            if c.faces_out > nf || c.vertices_out > nv {
                return Err(crate::error::Error::Internal(format!(
                    "round {} grew the mesh: {nf} -> {} faces",
                    self.removed.len() + 1,
                    c.faces_out
                )));
            }
            if c.faces_out == nf {
                break if c.over_max_error > 0 && c.candidates == 0 {
                    StopReason::MaxError
                } else {
                    StopReason::NoValidCollapse
                };
            }
            if c.winners > 0 {
                self.max_err2 = self.max_err2.max(f32::from_bits(c.max_err2_bits));
            }
            self.removed.push((nf - c.faces_out) as usize);
            self.open_groups = c.open_groups;
            self.open_excess = c.open_excess;
            self.open_faces = c.open_faces;
            self.collapses += (nv - c.vertices_out) as usize;
            nv = c.vertices_out;
            nf = c.faces_out;
            self.vertices = nv as usize;
            self.faces = nf as usize;
            progress((from - nf) as f32 / start);
        };
        if !ahead.is_empty() {
            return Err(crate::error::Error::Internal(format!(
                "the rounds stopped ({reason:?}) with {} rounds of a batch after the stop",
                ahead.len()
            )));
        }
        Ok(reason)
    }

    /// The largest collapse error so far (relative RMS distance).
    pub fn max_error(&self) -> f64 {
        (self.max_err2 as f64).sqrt()
    }

    pub fn finish(self, stop_reason: StopReason) -> Driven {
        Driven {
            stop_reason,
            max_error: self.max_error(),
            removed: self.removed,
            collapses: self.collapses,
        }
    }
}

/// Runs the rounds on `runner` over `up` and assembles the report.
pub fn simplify_rounds(
    runner: &mut dyn RoundRunner,
    up: &Upload,
    input: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
    mut rounds_report: RoundsReport,
) -> Result<(Mesh, SimplifyReport)> {
    let driven = drive(runner, up, opts, progress)?;
    let down = runner.download()?;
    let out = up.build_output_on(up.output_base(input), &down, input.normals.is_some());
    rounds_report.rounds = driven.removed.len();
    rounds_report.stage_seconds = runner.stage_times().clone();
    rounds_report.faces_removed_per_round = driven.removed;
    let pinned = down
        .flags
        .iter()
        .filter(|&&f| f & flag::PINNED != 0)
        .count();
    let report = SimplifyReport {
        backend: opts.backend,
        auto: None,
        input_faces: input.triangles.len(),
        target_faces: opts.target_faces,
        output_faces: out.triangles.len(),
        input_vertices: input.positions.len(),
        output_vertices: out.positions.len(),
        collapses: driven.collapses,
        max_collapse_error: driven.max_error,
        stop_reason: driven.stop_reason,
        dropped_degenerate_faces: up.dropped_degenerate,
        pinned_vertices: pinned,
        rounds: Some(rounds_report),
        blocked: None,
        clustering: None,
        decimation: None,
    };
    Ok((out, report))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::compute::types::INVALID_COST;
    use crate::mesh::grid;

    /// A runner whose ordinary rounds find nothing (every candidate under the ceiling fails)
    /// and that collapses one interior edge when every edge competes through exhaustive passes.
    struct FailsUnderCeiling {
        /// (ceiling_wanted, first, selection) of each call.
        calls: Vec<(u32, bool, Selection)>,
    }

    impl RoundRunner for FailsUnderCeiling {
        fn round(&mut self, p: &Params, first: bool, selection: Selection) -> Result<Counters> {
            self.calls.push((p.ceiling_wanted, first, selection));
            let all = p.ceiling_wanted == u32::MAX && selection == Selection::Exhaustive;
            Ok(Counters {
                candidates: 10,
                ceiling: if all { INVALID_COST } else { 5 << 20 },
                winners: all as u32,
                vertices_out: p.vertex_count - all as u32,
                faces_out: p.face_count - 2 * all as u32,
                ..Default::default()
            })
        }
        fn download(&mut self) -> Result<Download> {
            unreachable!("the test reads the driver only")
        }
        fn stage_times(&self) -> &StageTimes {
            unreachable!("the test reads the driver only")
        }
    }

    #[test]
    fn a_round_without_winners_under_its_ceiling_runs_again_without_it() {
        let mesh = grid(8);
        let up = Upload::new(&mesh);
        let faces = mesh.triangles.len();
        let opts = SimplifyOptions::with_faces(faces - 4);
        let mut driver = Driver::new(&up, &opts);
        let mut runner = FailsUnderCeiling { calls: Vec::new() };
        let reason = driver.run_to(&mut runner, faces - 4, &mut |_| {}).unwrap();
        assert_eq!(reason, StopReason::TargetReached);
        assert_eq!(driver.faces, faces - 4);
        // Two rounds, each tried under its ceiling first; only the very first call sets up the
        // quadrics (the retry runs on the same buffers).
        let wanted: Vec<bool> = runner.calls.iter().map(|c| c.0 == u32::MAX).collect();
        assert_eq!(wanted, [false, true, false, true]);
        let first: Vec<bool> = runner.calls.iter().map(|c| c.1).collect();
        assert_eq!(first, [true, false, false, false]);
        let exhaustive: Vec<bool> = runner
            .calls
            .iter()
            .map(|c| c.2 == Selection::Exhaustive)
            .collect();
        assert_eq!(exhaustive, [false, true, false, true]);
    }
}
