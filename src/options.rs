//! What a simplification is asked (options, backend, cancel token) and what it reports: below
//! every backend, which read the options and fill the report; `crate::simplify` dispatches.

use crate::error::{Error, Result};
use serde::Serialize;

/// Which implementation simplifies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Backend {
    /// Greedy quadric edge collapse with a priority queue, in f64: the quality reference.
    Cpu,
    /// The GPU's rounds of independent-set parallel collapses, run on the CPU with rayon.
    CpuParallel,
    /// Rounds of parallel collapses as WGSL compute passes through wgpu.
    Gpu,
    /// `Gpu` when a hardware GPU adapter is found, else `CpuParallel` (a software rasterizer
    /// such as lavapipe's llvmpipe counts as none: it is slower than the CPU's cores); a GPU that
    /// fails (a lost device, a mesh too big for its buffers) falls back to `CpuParallel`. The
    /// report names the backend that ran and says why in [`SimplifyReport::auto`].
    Auto,
}

impl Backend {
    pub fn name(self) -> &'static str {
        match self {
            Backend::Cpu => "cpu",
            Backend::CpuParallel => "cpu-parallel",
            Backend::Gpu => "gpu",
            Backend::Auto => "auto",
        }
    }
}

/// Which family of algorithms simplifies.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
#[non_exhaustive]
pub enum Method {
    /// Quadric edge collapse (Garland & Heckbert 1997): the best quality, on every backend.
    #[default]
    Qem,
    /// Uniform-grid vertex clustering (Rossignac & Borrel 1993) with one quadric per cell
    /// (Lindstrom 2000): the fastest, lands within 5% of the target, may change topology.
    Cluster,
    /// Low & Tan's floating cells (1997): clusters centred on the most important vertices, so
    /// creases and corners survive where a uniform grid cuts them; within 5% of the target.
    FloatingCell,
    /// Clustering to an intermediate count, then the QEM rounds to the exact target with the
    /// clusters' quadrics carried over (Garland & Shaffer's multiphase simplification, 2002):
    /// near-QEM quality at clustering speed on large scans.
    Hybrid,
    /// Vertex decimation (Schroeder, Zarge & Lorensen 1992): removes vertices and fills their
    /// holes, so the result keeps a subset of the input's vertices where they were, and its
    /// topology; on the CPU, sequential.
    Decimate,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Qem => "qem",
            Method::Cluster => "cluster",
            Method::FloatingCell => "floating-cell",
            Method::Hybrid => "hybrid",
            Method::Decimate => "decimate",
        }
    }
}

/// How the hole is filled.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Removal {
    /// Remove the vertex and triangulate its loop by recursive splitting along the diagonal
    /// with the best aspect ratio (Schroeder, Zarge & Lorensen 1992).
    LoopSplit,
    /// Collapse the vertex into the allowed neighbour of least error (a half-edge collapse:
    /// the fan of that neighbour fills the hole; Schroeder 1997 took the shortest edge). The
    /// default: on horse at 10% its mean distance was 0.77x loop splitting's.
    #[default]
    HalfEdge,
}

impl Removal {
    pub fn name(self) -> &'static str {
        match self {
            Removal::LoopSplit => "loop-split",
            Removal::HalfEdge => "half-edge",
        }
    }
}

/// How far to simplify. Whichever of the face target and the error bound is met first stops it.
#[derive(Debug, Clone, PartialEq)]
pub struct SimplifyOptions {
    /// Stop at this many faces (reached exactly or one below: an interior collapse removes two).
    pub target_faces: usize,
    /// Stop before a collapse whose error, relative to the bounding-box diagonal, exceeds this.
    pub max_error: Option<f64>,
    /// Keep the border exactly: border vertices never move; a border vertex is removed only
    /// when it lies on the straight line between its two border neighbours, so the outline is
    /// unchanged.
    pub lock_border: bool,
    /// Weight of the border and attribute-seam constraint planes relative to the face planes
    /// (Hoppe's boundary quadrics); larger keeps open borders and seams closer to where they were.
    pub border_weight: f64,
    /// A collapse may turn no surrounding face's normal by more than this many degrees.
    pub max_normal_angle_deg: f64,
    /// A collapse may not create a face of quality below this (quality = |cross| / longest edge²,
    /// 0.866 for an equilateral triangle) unless the face was already that thin.
    pub min_quality: f64,
    /// Faces below this quality make a collapse proportionally more expensive (MeshLab's
    /// `QualityThr`, default 0.3); 0 turns the term off, giving textbook QEM order.
    pub quality_threshold: f64,
    pub backend: Backend,
    /// The algorithm; the clustering methods run on `cpu-parallel` (`cpu` means it too).
    pub method: Method,
    /// `cpu` backend: how many regions large meshes are split into for the parallel first
    /// level (a second level then uses at most 4); `None` picks one per 32,768 faces, 8 to 32,
    /// for meshes of 100,000 faces or more and 1 (purely sequential) below. The result depends
    /// on this number, never on the number of threads.
    pub partitions: Option<usize>,
    /// Input vertex ids (indices into the positions) that keep their position and are never
    /// removed, though a free neighbour may collapse onto them: a tile's border, so that the
    /// neighbouring tile, simplified apart, still meets it there. QEM methods only. The `cpu`
    /// backend also refuses a collapse that joins two pinned vertices by a new edge (the tile
    /// next door may hold it); the rounds (`cpu-parallel`, `gpu`) keep the pins but not that.
    pub pin: Vec<u32>,
    /// `decimate`: faces meeting at a dihedral angle over this many degrees make a feature
    /// edge, which vertices are removed along but not across (Schroeder's feature angle).
    /// 60 by default: the angle is judged on the mesh as it coarsens, where faces meet at
    /// ever larger angles, and at 30 the 1% levels of the scans were mostly "features" (on
    /// horse at 1% the half-edge collapse stopped at 1,114 faces, loop splitting had 3.4x the
    /// greedy QEM's mean distance; at 60: 970 faces, 1.8x and 2.1x).
    pub feature_angle_deg: f64,
    /// `decimate`: how a removed vertex's hole is filled.
    pub removal: Removal,
    /// How much appearance counts beside geometry in the QEM collapse cost (`cpu` backend;
    /// Hoppe 1999): a channel the input has and whose weight is above zero joins the quadric,
    /// and a collapse's survivor takes the solved values.
    pub attributes: AttributeWeights,
    /// Set from another thread to stop a running simplification (the viewer's Cancel button):
    /// it then returns [`Error::Cancelled`] within one round or a few thousand collapses.
    pub cancel: Cancel,
}

/// The weight of each appearance attribute in the collapse cost: a difference of 1 in a value
/// (black to full red; a UV across the whole texture; a normal component) costs like moving the
/// surface by `weight` bounding-box diagonals. 0 leaves the attribute out of the cost: it then
/// rides on the survivor of each collapse, as the nearer endpoint had it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AttributeWeights {
    pub color: f64,
    pub uv: f64,
    pub normal: f64,
}

impl AttributeWeights {
    /// No attribute in the cost.
    pub const OFF: AttributeWeights = AttributeWeights {
        color: 0.0,
        uv: 0.0,
        normal: 0.0,
    };
}

impl Default for AttributeWeights {
    fn default() -> Self {
        // Chosen on the painted scans and spot (docs/PERFORMANCE.md, "Appearance"): colour
        // error a third to three quarters of meshoptimizer's simplifyWithAttributes at weight
        // 0.3, with a lower geometric error. Normals are made again from the output's faces by
        // default, which follows the new surface.
        AttributeWeights {
            color: 0.04,
            uv: 0.3,
            normal: 0.0,
        }
    }
}

/// A shared stop flag; every clone sees the same flag. Options compare equal whatever it holds.
#[derive(Debug, Clone, Default)]
pub struct Cancel(std::sync::Arc<std::sync::atomic::AtomicBool>);

impl Cancel {
    pub fn cancel(&self) {
        self.0.store(true, std::sync::atomic::Ordering::Relaxed);
    }
    pub fn is_cancelled(&self) -> bool {
        self.0.load(std::sync::atomic::Ordering::Relaxed)
    }
    /// `Err(Cancelled)` once cancelled, for `?` at the points where work may stop.
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }
}

impl PartialEq for Cancel {
    fn eq(&self, _: &Cancel) -> bool {
        true
    }
}

impl SimplifyOptions {
    /// Options for reaching `ratio` of `input_faces`, with the defaults for everything else.
    pub fn with_ratio(input_faces: usize, ratio: f64) -> Result<Self> {
        if !(ratio > 0.0 && ratio <= 1.0) {
            return Err(Error::InvalidOption(format!(
                "ratio must be in (0, 1], got {ratio}"
            )));
        }
        Ok(Self::with_faces(
            (input_faces as f64 * ratio).round() as usize
        ))
    }

    pub fn with_faces(target_faces: usize) -> Self {
        SimplifyOptions {
            target_faces,
            max_error: None,
            lock_border: false,
            border_weight: 1.0,
            max_normal_angle_deg: 90.0,
            min_quality: 0.01,
            quality_threshold: 0.3,
            backend: Backend::Cpu,
            method: Method::Qem,
            partitions: None,
            pin: Vec::new(),
            feature_angle_deg: 60.0,
            removal: Removal::HalfEdge,
            attributes: AttributeWeights::default(),
            cancel: Cancel::default(),
        }
    }

    pub(crate) fn check(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidOption(m));
        if let Some(e) = self.max_error
            && !(e >= 0.0 && e.is_finite())
        {
            return bad(format!("max error must be a finite number >= 0, got {e}"));
        }
        if !(self.border_weight >= 0.0 && self.border_weight.is_finite()) {
            return bad(format!(
                "border weight must be >= 0, got {}",
                self.border_weight
            ));
        }
        if !(self.max_normal_angle_deg > 0.0 && self.max_normal_angle_deg <= 180.0) {
            return bad(format!(
                "max normal angle must be in (0, 180], got {}",
                self.max_normal_angle_deg
            ));
        }
        if !(0.0..1.0).contains(&self.min_quality) || !(0.0..=1.0).contains(&self.quality_threshold)
        {
            return bad("min quality and quality threshold must lie in [0, 1)".into());
        }
        if !(self.feature_angle_deg >= 0.0 && self.feature_angle_deg <= 180.0) {
            return bad(format!(
                "feature angle must be in [0, 180] degrees, got {}",
                self.feature_angle_deg
            ));
        }
        let w = self.attributes;
        for (name, x) in [("color", w.color), ("uv", w.uv), ("normal", w.normal)] {
            if !(x >= 0.0 && x.is_finite()) {
                return bad(format!(
                    "{name} weight must be a finite number >= 0, got {x}"
                ));
            }
        }
        if self.partitions == Some(0) {
            return bad("partitions must be at least 1".into());
        }
        Ok(())
    }
}

/// Why simplification stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum StopReason {
    /// The face target was reached (clustering: within 5% of it).
    TargetReached,
    /// Clustering: no cell size lands within 5% of the target (the count jumps past it, or
    /// the grid is at its finest); the result is the nearest found.
    ClusterBand,
    /// The next cheapest collapse would exceed the error bound.
    MaxError,
    /// No collapse is left that keeps the topology and the constraints (flips, needles, locked
    /// border, seams): the target cannot be reached without breaking them.
    NoValidCollapse,
}

impl StopReason {
    pub fn explain(self) -> &'static str {
        match self {
            StopReason::TargetReached => "reached the face target",
            StopReason::ClusterBand => {
                "no cell size lands within 5% of the face target; this is the nearest count found"
            }
            StopReason::MaxError => "stopped at the maximum error before reaching the face target",
            StopReason::NoValidCollapse => {
                "no collapse left that keeps the topology, normals and locked vertices; the target \
                 cannot be reached without breaking them"
            }
        }
    }
}

/// Why no collapse was left where a run stopped above its target: the result's edges, counted
/// by the first of the rounds' checks each fails (see [`crate::rounds::cpu::blocked_edges`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub struct Blocked {
    pub edges: usize,
    /// Their collapse would exceed `--max-error`.
    pub over_max_error: usize,
    /// A face would flip, turn past the normal limit or become a needle, or the edge has no
    /// allowed placement (a locked border, a seam junction, a non-manifold vertex).
    pub geometry: usize,
    /// The collapse would break the topology: the link condition (it would pinch the surface),
    /// a border pinch, a lone triangle or a tetrahedron folding flat — what is left are the
    /// smallest shapes each component and hole can have.
    pub topology: usize,
    /// Collapses these checks allow when the result is taken as a new input: the run itself
    /// also compared normals with the original's and carried its quadrics, so a few more may
    /// pass here than it could take.
    pub allowed: usize,
}

impl Blocked {
    /// One sentence: the reason that holds most of the edges, with the counts.
    pub fn explain(&self) -> String {
        let main = if self.topology >= self.geometry.max(self.over_max_error) {
            "most would break the topology (pinch the surface, or close a hole or a component \
             already at its smallest)"
        } else if self.geometry >= self.over_max_error {
            "most would flip or crush a face, or move a locked, seam or non-manifold vertex"
        } else {
            "most would exceed the maximum error"
        };
        format!(
            "{main}: of {} edges, {} topology, {} flip/shape/locked, {} over the error bound, {} \
             allowed when the result is taken as a new input",
            self.edges, self.topology, self.geometry, self.over_max_error, self.allowed
        )
    }
}

/// What a simplification did.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SimplifyReport {
    /// The backend that ran (never `Auto`).
    pub backend: Backend,
    /// Under [`Backend::Auto`]: what it picked and why, and a fallback from a failed GPU.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<String>,
    pub input_faces: usize,
    pub target_faces: usize,
    pub output_faces: usize,
    pub input_vertices: usize,
    pub output_vertices: usize,
    pub collapses: usize,
    /// Largest quadric error of an applied collapse, as RMS distance relative to the diagonal.
    pub max_collapse_error: f64,
    pub stop_reason: StopReason,
    /// Faces with a repeated vertex dropped from the input before simplifying.
    pub dropped_degenerate_faces: usize,
    /// Vertices kept in place: where the surface is not manifold, and (with `lock_border`)
    /// attribute seams that reach the border. Seam vertices elsewhere slide along their seam
    /// (`cpu`); the round-based backends keep seams whole.
    pub pinned_vertices: usize,
    /// Rounds, per-round removals and stage times of the round-based backends.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rounds: Option<RoundsReport>,
    /// Where the run stopped above its target: why no collapse was left.
    pub blocked: Option<Blocked>,
    /// What clustering did (`cluster`, `floating-cell`, `hybrid`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clustering: Option<ClusterReport>,
    /// What vertex decimation did (`decimate`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub decimation: Option<DecimateReport>,
}

impl SimplifyReport {
    /// The counts of `output`, a result of `input` by `backend`, with nothing else done yet:
    /// each method fills in the rest, and a result made elsewhere (a level read back from its
    /// file, a Pareto front member) is shown with this alone.
    pub fn counts(
        backend: Backend,
        input: &crate::Mesh,
        output: &crate::Mesh,
        stop_reason: StopReason,
    ) -> SimplifyReport {
        SimplifyReport {
            backend,
            auto: None,
            input_faces: input.triangles.len(),
            target_faces: output.triangles.len(),
            output_faces: output.triangles.len(),
            input_vertices: input.positions.len(),
            output_vertices: output.positions.len(),
            collapses: input.positions.len().saturating_sub(output.positions.len()),
            max_collapse_error: 0.0,
            stop_reason,
            dropped_degenerate_faces: 0,
            pinned_vertices: 0,
            rounds: None,
            blocked: None,
            clustering: None,
            decimation: None,
        }
    }
}

/// What decimation did, in the report of `--stats` and `--json`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct DecimateReport {
    pub removal: Removal,
    /// The input's vertices by class, before any removal.
    pub simple: usize,
    pub boundary: usize,
    pub interior_edge: usize,
    pub corner: usize,
    pub complex: usize,
    pub removed: usize,
    /// Removals the queue offered and the checks refused (a vertex may be refused again after
    /// its neighbourhood changed).
    pub refused: usize,
}

impl SimplifyReport {
    /// The report of a result that was changed after simplifying (remeshed): the same, with
    /// the output counts of `out`, the mesh a caller writes.
    pub fn describing(self, out: &crate::mesh::Mesh) -> SimplifyReport {
        SimplifyReport {
            output_faces: out.face_count(),
            output_vertices: out.vertex_count(),
            ..self
        }
    }
}

/// What the clustering methods did, reported by `--stats` and `--json`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct ClusterReport {
    pub method: Method,
    /// The cell size (grid side, or floating-cell radius), relative to the bounding-box
    /// diagonal.
    pub cell_size: f64,
    /// Cell sizes whose face count was taken while searching for the target (four a pass).
    pub sizes_counted: usize,
    /// Full clusterings run (the last is the result).
    pub builds: usize,
    /// Clusters (output vertices before unused ones are dropped).
    pub clusters: usize,
    /// Clusters beyond one per cell, from splitting cells by connectivity.
    pub split_clusters: usize,
    /// `hybrid`: clusters taken apart because they made a non-manifold edge.
    pub repaired_clusters: usize,
    /// How each cluster's vertex was placed: a single member kept, the clamped quadric
    /// minimum, the member of least error, the centroid.
    pub placed_single: usize,
    pub placed_solve: usize,
    pub placed_member: usize,
    pub placed_centroid: usize,
    /// `hybrid`: the faces clustering left for the rounds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub intermediate_faces: Option<usize>,
    /// `floating-cell`: rounds of choosing centres.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub centre_rounds: Option<usize>,
    /// Seconds in clustering (for `hybrid`, before the rounds).
    pub seconds: f64,
}

/// Seconds per stage name, in first-seen order, summed over rounds.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct StageTimes(pub Vec<(String, f64)>);

impl StageTimes {
    pub fn add(&mut self, stage: &str, seconds: f64) {
        match self.0.iter_mut().find(|(s, _)| s == stage) {
            Some(e) => e.1 += seconds,
            None => self.0.push((stage.to_string(), seconds)),
        }
    }
    pub fn total(&self) -> f64 {
        self.0.iter().map(|e| e.1).sum()
    }
    /// The stage that took longest.
    pub fn slowest(&self) -> Option<(&str, f64)> {
        self.0
            .iter()
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|(s, t)| (s.as_str(), *t))
    }
}

/// What the rounds did, reported by `--stats` and `--json`.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct RoundsReport {
    /// GPU adapter name (gpu backend only).
    pub adapter: Option<String>,
    pub rounds: usize,
    /// Faces removed by each round.
    pub faces_removed_per_round: Vec<usize>,
    /// Time per stage: GPU time from timestamp queries when the device has them (else the
    /// wall time of each submission), CPU time for cpu-parallel.
    pub stage_seconds: StageTimes,
    /// Whether `stage_seconds` comes from GPU timestamp queries.
    pub gpu_timestamps: bool,
    /// Shader compilation and pipeline creation (gpu backend), reported apart from simplifying.
    pub pipeline_seconds: f64,
    /// Upload and download between host and device (gpu backend).
    pub transfer_seconds: f64,
    /// Preparing the upload on the host before the rounds: weld, position classes, Morton
    /// order, normalization (gpu backend, `qem`; `hybrid`'s hand-over is in its clustering).
    pub prepare_seconds: f64,
    /// Where the mesh was welded, ordered and normalized for the rounds: `device` (the
    /// preparation's stages, for a plain mesh where the device has f64 in shaders) or `host`.
    pub prepared_on: Option<String>,
    /// The rounds' waits, from each submission of a round or a batch of them to their counters
    /// read back: the GPU's work and the driver's (gpu backend).
    pub wait_seconds: f64,
    /// What the call cost on the device's side (gpu backend; zero on the CPU backends):
    /// the host's waits for the device (each a round trip)...
    pub device_waits: u64,
    /// ...command buffers submitted, compute passes dispatched, bind groups made...
    pub submits: u64,
    pub dispatches: u64,
    pub bind_groups_created: u64,
    /// ...bytes written to the device's buffers and read back from them...
    pub bytes_uploaded: u64,
    pub bytes_read_back: u64,
    /// ...and the call's seconds less those blocked on the device (`wait_seconds` and the
    /// read-backs' waits): what the host itself spent.
    pub host_seconds: f64,
    /// How the device's pipelines were found: `hit` (compiled from the on-disk cache),
    /// `miss` (compiled, the cache written), `unsupported` (the adapter keeps none), or
    /// `shared` (made earlier in this process).
    pub pipeline_cache: Option<String>,
}
