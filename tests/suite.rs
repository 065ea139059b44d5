//! Every integration test, one module per file of tests/, in one binary: linked once rather
//! than 26 times (the release build spent ~130 s of CPU on the separate binaries), and the
//! harness keeps both threads busy across files. `cargo test --release gpu::` runs one file's.

mod cluster_twins;
mod common;
mod io_support;
mod viewer_support;

mod appearance;
#[cfg(feature = "bench")]
mod bench;
#[cfg(feature = "cli")]
mod cli;
#[cfg(feature = "cli")]
mod cli_remesh;
mod cluster;
mod dag;
mod decimate;
mod gpu;
mod gpu_cluster;
mod gpu_dag;
mod gpu_floating;
mod gpu_prepare;
mod greedy;
mod house;
mod io;
mod io_hostile;
mod lod;
mod metrics;
mod parallel;
mod remesh;
#[cfg(feature = "cli")]
mod slurm;
mod stream;
mod targets;
#[cfg(feature = "cli")]
mod tiles;
#[cfg(all(feature = "cli", feature = "viewer"))]
mod viewer;
#[cfg(feature = "cli")]
mod viewer_app;
mod viewer_panel;
