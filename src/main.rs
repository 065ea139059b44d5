//! The `meshslim` binary: parse, run, print the error once, exit with its code.
//! Everything else lives in the library (`meshslim::cli` for the command-line runners).

use std::process::ExitCode;

use clap::Parser;
use meshslim::cli::{self, Cli};

/// Counts heap bytes so that `meshslim bench` can report each simplify call's peak memory.
#[global_allocator]
static ALLOC: meshslim::bench::alloc::CountingAlloc = meshslim::bench::alloc::CountingAlloc;

fn main() -> ExitCode {
    let _runtime_dir = meshslim::compute::context::quiet_wayland_probe().map(|(dir, value)| {
        // SAFETY: set_var races only with other threads reading or writing the environment, and
        // none exists yet: this is the first statement of main, before clap, rayon or wgpu
        // start anything, and no dependency spawns a thread before main.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", value) };
        dir
    });
    // clap prints its own usage errors and exits with 2.
    let args = Cli::parse();
    match cli::run(args) {
        Ok(code) => code,
        Err(err) => {
            eprintln!("error: {err:#}");
            cli::exit_code(&err)
        }
    }
}
