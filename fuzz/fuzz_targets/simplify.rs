//! `simplify` on whatever a reader accepts, on the greedy (`cpu`) and the rounds' CPU twin
//! (`cpu-parallel`), with the invariant checks on. The first three bytes choose the format,
//! the target and the options; the rest is the file.
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshslim::io::Format;
use meshslim::{Backend, SimplifyOptions, StopReason};

#[path = "../common.rs"]
mod common;

/// Larger meshes only slow the fuzzer down; the readers' targets cover large inputs.
const MAX_FACES: usize = 4096;

fuzz_target!(|data: &[u8]| {
    let [format, ratio, flags, file @ ..] = data else {
        return;
    };
    let format = [Format::Obj, Format::Ply, Format::Stl, Format::Gltf, Format::Glb]
        [*format as usize % 5];
    let Ok(mesh) = common::read(file, format) else {
        return;
    };
    if mesh.face_count() > MAX_FACES {
        return;
    }
    // 0 to 100% in steps of 1/255: every target from "nothing" to "everything".
    let Ok(mut options) = SimplifyOptions::with_ratio(mesh.face_count(), *ratio as f64 / 255.0)
    else {
        return;
    };
    options.backend = if flags & 1 == 0 {
        Backend::Cpu
    } else {
        Backend::CpuParallel
    };
    options.lock_border = flags & 2 != 0;
    if flags & 4 != 0 {
        options.max_error = Some(1e-3);
    }
    let target = options.target_faces;
    match meshslim::simplify(&mesh, &options) {
        Ok((out, report)) => {
            out.validate().expect("simplify returned an invalid mesh");
            assert_eq!(out.face_count(), report.output_faces);
            assert!(out.face_count() <= mesh.face_count());
            if report.stop_reason == StopReason::TargetReached {
                assert!(out.face_count() <= target, "{report:?}");
            }
        }
        // A mesh with no faces left to simplify (every face degenerate) is a clean error.
        Err(_) => {}
    }
});
