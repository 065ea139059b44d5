//! meshslim — triangle-mesh simplification by quadric error metrics.
//!
//! Backends of one idea (Garland & Heckbert, "Surface Simplification Using Quadric Error
//! Metrics", SIGGRAPH 1997):
//! - `cpu` (the `greedy` module): greedy edge collapse with a priority queue, in f64 — the quality
//!   reference.
//! - `gpu` ([`rounds::gpu`]): rounds of independent-set parallel collapses as WGSL compute
//!   passes through wgpu; `shaders/` holds one file per stage.
//! - `cpu-parallel` ([`rounds::cpu`]): the same rounds, stage for stage, on the CPU with rayon —
//!   the validator of every GPU stage. [`rounds`] drives both:
//!
//! ```text
//! adjacency (count, prefix sum, fill, sort) -> [face planes, vertex flags, quadrics]
//!   -> unique edges -> edge errors -> cost ceiling -> live list -> edge costs
//!   -> passes of (select cost, select id, select win, validate) -> [trim] -> collapse -> compact
//! ```
//!
//! Papers and sources this crate follows:
//! - M. Garland, P. Heckbert. Surface Simplification Using Quadric Error Metrics. SIGGRAPH 1997.
//! - H. Hoppe. New Quadric Metric for Simplifying Meshes with Appearance Attributes. 1999
//!   (boundary constraint planes).
//! - T. Dey, H. Edelsbrunner, S. Guha, D. Nekhayev. Topology Preserving Edge Contraction. 1999
//!   (the link condition).
//! - P. Cignoni, C. Montani, C. Rocchini, R. Scopigno. A general method for preserving attribute
//!   values on simplified meshes / vcglib quadric collapse (triangle-quality weighted priority).
//! - M. Luby. A Simple Parallel Algorithm for the Maximal Independent Set Problem. 1986 (repeated
//!   selection passes on what stays unblocked).
//! - A. Papageorgiou, N. Platis. Triangular mesh simplification on the GPU. The Visual Computer,
//!   2015 (independent-set collapses on the GPU; our rounds remove 13–18% per round where its
//!   single local-minimum pass removed 8–9%).
//! - B. Karis, R. Stubbe, G. Wihlidal. A Deep Dive into Nanite Virtualized Geometry. SIGGRAPH
//!   2021 (the cluster DAG of [`dag`]).
//!
//! The other families:
//! - J. Rossignac, P. Borrel. Multi-Resolution 3D Approximations for Rendering Complex Scenes.
//!   1993 (uniform vertex clustering, `cluster`).
//! - K.-L. Low, T.-S. Tan. Model Simplification Using Vertex-Clustering. I3D 1997 (floating
//!   cells, `cluster`).
//! - P. Lindstrom. Out-of-Core Simplification of Large Polygonal Models. SIGGRAPH 2000 (a
//!   cluster's quadric, the hybrid's first phase, and the streaming of [`io::stream`] and
//!   [`tiles`]).
//! - W. Schroeder, J. Zarge, W. Lorensen. Decimation of Triangle Meshes. SIGGRAPH 1992
//!   ([`decimate`]).
//! - M. Botsch, L. Kobbelt. A Remeshing Approach to Multiresolution Modeling. SGP 2004
//!   (isotropic remeshing, [`remesh`]).
//! - K. Deb, A. Pratap, S. Agarwal, T. Meyarivan. A Fast and Elitist Multiobjective Genetic
//!   Algorithm: NSGA-II. IEEE TEC 2002 (the Pareto levels of detail of [`lod`]).

#[cfg(feature = "bench")]
pub mod bench;
#[cfg(feature = "cli")]
pub mod cli;
// Vertex clustering; public (hidden) for the tests of its stages.
#[doc(hidden)]
pub mod cluster;
// The GPU layer every family shares: schedules' vocabulary, pipeline cache, error capture.
#[doc(hidden)]
pub mod compute;
// Cluster levels of detail (Nanite-style meshlet DAGs).
pub mod dag;
pub mod decimate;
pub mod error;
mod greedy;
pub mod io;
pub mod lod;
pub mod memory;
pub mod mesh;
pub mod metrics;
pub mod options;
mod prefetch;
mod quadric;
#[cfg(any(feature = "bench", feature = "viewer"))]
pub mod raster;
pub mod remesh;
// The QEM rounds (backends `gpu` and `cpu-parallel`): their schedule, driver and both runners.
pub mod rounds;
pub mod simplify;
pub mod tiles;
#[cfg(feature = "viewer")]
pub mod viewer;

pub use error::{Error, Location, Result};
pub use mesh::{Aabb, Material, Mesh, UvOrigin};
pub use options::{Backend, Method, SimplifyOptions, SimplifyReport, StopReason};
pub use simplify::{simplify, simplify_with_progress};
