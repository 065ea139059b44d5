//! Method `decimate`: vertex decimation (Schroeder, Zarge & Lorensen, "Decimation of Triangle
//! Meshes", SIGGRAPH 1992; the half-edge collapse of Schroeder, "A Topology Modifying
//! Progressive Decimation Algorithm", 1997, without its topology changes). The result keeps a
//! subset of the input's vertices, where they were, and its topology.
//!
//! Each vertex is classified from its fan ([`VertexClass`]); simple, boundary and interior-edge
//! vertices may go, corners and complex vertices stay. A removal leaves a hole that loop
//! splitting or a half-edge collapse fills ([`Removal`]); the new faces must not flip against
//! the fan's average plane, degenerate, or duplicate an edge or face outside the hole, so the
//! Euler characteristic, the borders and manifoldness are kept.
//!
//! The criterion is Schroeder's distance (to the fan's average plane for a simple vertex, to the
//! line through its two feature or border neighbours otherwise), measured against the planes of
//! every original face the vertex stands for: each vertex carries the quadric of its own faces
//! (and border and seam constraint planes, as the QEM methods have), and a removed vertex hands
//! its quadric to the loop vertices nearest where it was, so a later removal near it is charged
//! for how far the surface has gone from the original there, not only from the current mesh.
//! The queue is ordered by that quadric error (lazily: see [`Decimator::run`]).
//!
//! [`Decimator`] is the engine as a library: remove vertices in a given order and learn which
//! removals were refused and what each one cost (the Pareto levels of detail decode their
//! candidates with it), or run it greedily to a target.

mod engine;
mod fan;
mod triangulate;

pub use crate::options::{DecimateReport, Removal};
pub use engine::Refusal;
pub use fan::VertexClass;
pub use triangulate::{MIN_SPLIT_ASPECT, fan_from, split_loop};

use crate::error::Result;
use crate::greedy::output::{OutputNormals, build_output};
use crate::greedy::prepare::Prepared;
use crate::greedy::queue::Queue;
use crate::mesh::Mesh;
use crate::options::{SimplifyOptions, SimplifyReport, StopReason};
use engine::{Engine, Params, key};

/// What [`Decimator::run`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct RunResult {
    /// The removed vertices in order, with their errors.
    pub order: Vec<(u32, f64)>,
    pub stop: StopReason,
    /// Removals the queue offered and the checks refused.
    pub refused: usize,
    /// The live vertices by class before the run, indexed by `VertexClass as usize`.
    pub census: [usize; 5],
}

/// One removal asked of [`Decimator::remove`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Outcome {
    /// Removed; its error as a distance relative to the bounding-box diagonal.
    Removed {
        error: f64,
    },
    Refused(Refusal),
}

/// The vertex decimation engine on one mesh. A clone goes on independently (the Pareto
/// search decodes each candidate on a clone of one prepared engine).
#[derive(Clone)]
pub struct Decimator {
    e: Engine,
    normals: bool,
    input_faces: usize,
    input_vertices: usize,
}

impl Decimator {
    /// Prepares `mesh` (welded, vertices in Morton order, quadrics) under `opts`: its
    /// `feature_angle_deg`, `removal`, `lock_border`, `min_quality`, `max_normal_angle_deg`,
    /// `max_error`, `border_weight` and `pin` apply.
    pub fn new(mesh: &Mesh, opts: &SimplifyOptions) -> Decimator {
        let p = Prepared::new(mesh, opts);
        let params = Params {
            removal: opts.removal,
            feature_cos: opts.feature_angle_deg.to_radians().cos(),
            lock_border: opts.lock_border,
            min_quality: opts.min_quality,
            normal_cos: opts.max_normal_angle_deg.to_radians().cos().max(0.0),
            max_error: opts.max_error,
        };
        Decimator {
            e: Engine::new(p, params),
            normals: mesh.normals.is_some(),
            input_faces: mesh.triangles.len(),
            input_vertices: mesh.positions.len(),
        }
    }

    /// Vertices of the engine (positions after welding, in Morton order); ids below are these.
    pub fn vertex_count(&self) -> usize {
        self.e.alive.len()
    }

    /// Live vertices and faces.
    pub fn live_vertices(&self) -> usize {
        self.e.alive.iter().filter(|&&a| a).count()
    }
    pub fn face_count(&self) -> usize {
        self.e.faces
    }

    /// The position of engine vertex `v`, as in the input.
    pub fn position(&self, v: u32) -> [f32; 3] {
        let p = &self.e.p;
        p.mesh.positions[p.first_attr[v as usize] as usize]
    }

    /// The class of `v` in the mesh as it is now.
    pub fn classify(&mut self, v: u32) -> VertexClass {
        self.e.classify(v)
    }

    /// Removes `v` if its class and the checks allow it.
    pub fn remove(&mut self, v: u32) -> Outcome {
        if v as usize >= self.e.alive.len() {
            return Outcome::Refused(Refusal::Gone);
        }
        match self.e.evaluate(v, Some(u32::MAX)) {
            Ok(plan) => {
                debug_assert!(plan.filled);
                self.e.apply(v, &plan);
                Outcome::Removed { error: plan.error }
            }
            Err(r) => Outcome::Refused(r),
        }
    }

    /// Removes the cheapest vertices first until at most `target` faces are left (one below
    /// when the last removal takes two), or no vertex can go. Returns the removed vertices in
    /// order with their errors, and why it stopped.
    ///
    /// The queue is lazy (as the greedy QEM's): a removal re-queues its loop vertices at their
    /// old keys, and a vertex's cost is found again only when it comes to the top; if it grew
    /// (it mostly does: the vertex took a share of the removed one's quadric), it goes back in
    /// at the new cost, else it is removed. Measured on horse at 10%: re-evaluating every loop
    /// vertex at once took 0.37 s, the lazy queue 0.32 s, for the same error.
    pub fn run(
        &mut self,
        target: usize,
        progress: &mut dyn FnMut(usize),
        cancel: &crate::options::Cancel,
    ) -> Result<RunResult> {
        let e = &mut self.e;
        let mut census = [0usize; 5];
        // The greedy QEM's bucket queue: measured on horse at 10%, std's BinaryHeap spent 12%
        // of the run in pop.
        let mut heap = Queue::new();
        let mut keys = vec![0u32; e.alive.len()];
        for v in 0..e.alive.len() as u32 {
            if !e.alive[v as usize] {
                continue;
            }
            let class = match e.evaluate(v, None) {
                Ok(plan) => {
                    keys[v as usize] = key(plan.cost);
                    heap.push(key(plan.cost), v, 0, e.version[v as usize]);
                    e.last_class()
                }
                Err(Refusal::Kept(c)) => c,
                Err(_) => e.last_class(),
            };
            census[class as usize] += 1;
        }
        let mut order = Vec::new();
        let mut ring = Vec::new();
        let mut refused = 0;
        let mut over_error = false;
        while e.faces > target {
            let version = &e.version;
            let Some((k, v, _, stamp)) = heap.pop(|v, _, stamp| version[v as usize] == stamp)
            else {
                break;
            };
            if stamp != e.version[v as usize] || !e.alive[v as usize] {
                continue;
            }
            match e.evaluate(v, Some(k)) {
                Ok(plan) if !plan.filled || key(plan.cost) > k => {
                    // It costs more than its key said: back in the queue at its cost.
                    keys[v as usize] = key(plan.cost);
                    heap.push(key(plan.cost), v, 0, stamp);
                }
                Ok(plan) => {
                    e.apply(v, &plan);
                    order.push((v, plan.error));
                    ring.clear();
                    ring.extend_from_slice(e.loop_vertices());
                    for &x in &ring {
                        heap.push(keys[x as usize], x, 0, e.version[x as usize]);
                    }
                    if order.len() % 4096 == 0 {
                        cancel.check()?;
                        progress(e.faces);
                    }
                }
                Err(Refusal::OverMaxError) => {
                    over_error = true;
                    refused += 1;
                }
                Err(_) => refused += 1,
            }
        }
        cancel.check()?;
        let stop = if e.faces <= target {
            StopReason::TargetReached
        } else if over_error {
            StopReason::MaxError
        } else {
            StopReason::NoValidCollapse
        };
        Ok(RunResult {
            order,
            stop,
            refused,
            census,
        })
    }

    /// The vertex-to-plane error of the mesh as it is now: the area-weighted RMS distance of
    /// the live vertices from the planes of the original faces each one stands for (its own,
    /// and those the removals around it handed on), relative to the bounding-box diagonal.
    /// A removal moves no vertex, so this is what the removed vertices' planes say of the
    /// vertices that took them over: the Pareto search's cheap error.
    pub fn vertex_plane_error(&self) -> f64 {
        let p = &self.e.p;
        let (mut sum, mut weight) = (0.0, 0.0);
        for (v, _) in self.e.alive.iter().enumerate().filter(|a| *a.1) {
            sum += p.quadrics[v].eval(p.pos[v]);
            weight += p.quadrics[v].weight;
        }
        if weight > 0.0 {
            (sum / weight).sqrt()
        } else {
            0.0
        }
    }

    /// The mesh as it is now: the input's vertices that are left, with their attributes.
    pub fn mesh(&self) -> Mesh {
        let normals = if self.normals {
            OutputNormals::Keep
        } else {
            OutputNormals::None
        };
        build_output(&self.e.p, &self.e.face_alive, &self.e.alive, normals)
    }
}

/// `simplify --method decimate`: the greedy run of the engine to the options' target.
pub(crate) fn simplify_decimate(
    input: &Mesh,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Mesh, SimplifyReport)> {
    let mut d = Decimator::new(input, opts);
    let nf = d.face_count();
    let need = nf.saturating_sub(opts.target_faces).max(1) as f32;
    let RunResult {
        order,
        stop,
        refused,
        census,
    } = d.run(
        opts.target_faces,
        &mut |faces| progress((nf - faces) as f32 / need),
        &opts.cancel,
    )?;
    progress(1.0);
    let out = d.mesh();
    let report = SimplifyReport {
        backend: crate::Backend::Cpu,
        auto: None,
        input_faces: d.input_faces,
        target_faces: opts.target_faces,
        output_faces: out.triangles.len(),
        input_vertices: d.input_vertices,
        output_vertices: out.positions.len(),
        collapses: order.len(),
        max_collapse_error: order.iter().map(|o| o.1).fold(0.0, f64::max),
        stop_reason: stop,
        dropped_degenerate_faces: d.e.p.dropped_degenerate,
        pinned_vertices: census[3] + census[4],
        rounds: None,
        blocked: None,
        clustering: None,
        decimation: Some(DecimateReport {
            removal: opts.removal,
            simple: census[0],
            boundary: census[1],
            interior_edge: census[2],
            corner: census[3],
            complex: census[4],
            removed: order.len(),
            refused,
        }),
    };
    Ok((out, report))
}
