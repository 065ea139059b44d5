//! The glTF reader on arbitrary bytes, as a `.glb` when they start with the binary container's
//! magic and as a `.gltf` otherwise: an error or a valid mesh that writes and reads back.
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshslim::io::Format;

#[path = "../common.rs"]
mod common;

fuzz_target!(|data: &[u8]| {
    let format = if data.starts_with(b"glTF") {
        Format::Glb
    } else {
        Format::Gltf
    };
    let _ = common::read(data, format);
});
