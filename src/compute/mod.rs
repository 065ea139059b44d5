//! The compute core every GPU family shares (house rules 1, 2, 4 and 10 of the architecture, summed
//! up in docs/DESIGN.md): the vocabulary a family's schedule is written in ([`schedule`]: stages
//! described by their bindings, steps, the stages every family runs written once), and on the
//! device ([`gpu`]) one pipeline cache per device, one error capture and one pass recorder.
//!
//! A family — the QEM rounds (`crate::rounds::schedule`, run by `crate::rounds::gpu` and twinned in
//! `crate::rounds::cpu`) and the clustering (`crate::cluster::gpu_schedule`) — owns its buffer,
//! count and grid enums, its stages and parts, and the runner glue that binds its buffers; the
//! recorder and the caches here do the rest.

// The f32 math of shaders/common.inc.wgsl, for every family's CPU twins.
pub mod common;
// The process's device and the checks on buffers any family makes.
pub mod context;
// The compiled pipelines kept on disk between processes.
pub mod disk_cache;
pub mod gpu;
pub mod schedule;
pub(crate) mod shaders;
// The structs and constants the WGSL stages share with their Rust twins: public for the
// stage-by-stage tests.
#[doc(hidden)]
pub mod types;

#[cfg(test)]
mod tests {
    /// Every family's schedule against its WGSL through naga, with the same checks: what a
    /// family adds runs through this one test.
    #[test]
    fn every_family_binds_what_its_shaders_declare() {
        crate::rounds::schedule::check_schedule();
        crate::cluster::gpu_schedule::check_schedule();
        crate::rounds::prepare::check_schedule();
        crate::dag::schedule::check_schedule();
    }

    /// The pipeline cache is keyed by entry point: two families may name one entry only when it
    /// is the same stage of the same shader (the shared ones).
    #[test]
    fn an_entry_point_names_one_stage_across_families() {
        // Each family's stages are of its own buffer type, so a macro rather than a function.
        macro_rules! entries {
            ($($stages:path),*) => {
                [$($stages
                    .iter()
                    .flat_map(|l| l.iter())
                    .map(|s| (s.entry, s.shader))
                    .collect::<Vec<(&str, &str)>>()),*]
                .concat()
            };
        }
        let all = entries!(
            crate::rounds::schedule::STAGES,
            crate::cluster::gpu_schedule::STAGES,
            crate::rounds::prepare::STAGES,
            crate::dag::schedule::STAGES
        );
        for (i, (entry, shader)) in all.iter().enumerate() {
            for (e2, s2) in &all[..i] {
                assert!(
                    e2 != entry || s2 == shader,
                    "{entry} is shaders/{shader}.wgsl and shaders/{s2}.wgsl"
                );
            }
        }
    }
}
