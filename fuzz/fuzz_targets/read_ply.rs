//! The PLY reader on arbitrary bytes: an error or a valid mesh that writes and reads back,
//! never a panic, a hang or an allocation the input does not justify.
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshslim::io::Format;

#[path = "../common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let _ = common::read(data, Format::Ply);
});
