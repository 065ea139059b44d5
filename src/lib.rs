//! meshslim — triangle-mesh simplification by quadric error metrics.
//!
//! Backends of one idea (Garland & Heckbert, "Surface Simplification Using Quadric Error
//! Metrics", SIGGRAPH 1997):
//! - `cpu`: greedy edge collapse with a priority queue, in f64 — the quality reference.
//!
//! Papers and sources this crate follows:
//! - M. Garland, P. Heckbert. Surface Simplification Using Quadric Error Metrics. SIGGRAPH 1997.
//! - H. Hoppe. New Quadric Metric for Simplifying Meshes with Appearance Attributes. 1999
//!   (boundary constraint planes).
//! - T. Dey, H. Edelsbrunner, S. Guha, D. Nekhayev. Topology Preserving Edge Contraction. 1999
//!   (the link condition).
//! - P. Cignoni, C. Montani, C. Rocchini, R. Scopigno. A general method for preserving attribute
//!   values on simplified meshes / vcglib quadric collapse (triangle-quality weighted priority).

pub mod bench;
pub mod cli;
pub mod cpu;
pub mod error;
pub mod gpu;
pub mod greedy;
pub mod io;
pub mod mesh;
pub mod metrics;
pub mod parallel;
pub mod quadric;
pub mod simplify;

pub use error::{Error, Location, Result};
pub use mesh::{Aabb, Material, Mesh};
pub use simplify::{
    Backend, SimplifyOptions, SimplifyReport, StopReason, simplify, simplify_with_progress,
};
