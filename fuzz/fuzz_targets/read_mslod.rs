//! The cluster DAG reader on arbitrary bytes: an error or a DAG that writes back to the same
//! bytes, never a panic, a hang or an allocation the input does not justify.
#![no_main]

use libfuzzer_sys::fuzz_target;
use meshslim::dag::file;

fn check(data: &[u8]) {
    if let Ok(dag) = file::from_bytes(data, std::path::Path::new("fuzz.mslod")) {
        assert_eq!(file::to_bytes(&dag), data, "a DAG read must write back as read");
        // Cuts of whatever was read index only what is there.
        let _ = dag.mesh_of(&dag.cut_at_error(0.0));
    }
}

fuzz_target!(|data: &[u8]| {
    check(data);
    // A mutation almost never keeps the checksum: stamped again, the same bytes reach the
    // checks of the counts, indices and errors behind it.
    let mut stamped = data.to_vec();
    file::restamp(&mut stamped);
    if stamped != data {
        check(&stamped);
    }
});
