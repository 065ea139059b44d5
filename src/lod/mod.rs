//! Levels of detail: the chain of levels in one run ([`lod_chain`]), and Pareto sets of vertex
//! removal levels by NSGA-II ([`pareto_front`]; Deb, Pratap, Agarwal & Meyarivan, "A Fast and
//! Elitist Multiobjective Genetic Algorithm: NSGA-II", IEEE TEC 2002, applied to LODs as in
//! Campomanes-Álvarez et al., "Multi-objective optimization of level-of-detail meshes", 2012).

mod chain;
pub mod manifest;
pub mod nsga;
mod pareto;
pub mod svg;

pub use chain::{LodLevel, check_ratios, lod_chain};
pub use pareto::{
    Candidate, ErrorMeasure, Generation, Initialisation, Measured, Pareto, ParetoOptions,
    ParetoRun, Variation, pareto_front,
};
