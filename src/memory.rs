//! Memory: the machine's, the process's peak, and what the whole-mesh path would need — what
//! [`crate::simplify::stream_reason`] decides streaming by (the command line's `--stream` and
//! `--memory`, and `tiles merge`).

use std::path::Path;

/// A `/proc` field in kibibytes (`MemTotal` of /proc/meminfo, `VmHWM` of /proc/self/status),
/// in bytes; `None` where there is no /proc.
fn proc_kib(file: &str, field: &str) -> Option<u64> {
    let text = std::fs::read_to_string(file).ok()?;
    let line = text.lines().find(|l| l.starts_with(field))?;
    let kib: u64 = line[field.len()..]
        .trim()
        .trim_end_matches("kB")
        .trim()
        .parse()
        .ok()?;
    Some(kib * 1024)
}

/// The process's peak resident memory so far.
pub fn peak_resident_bytes() -> Option<u64> {
    proc_kib("/proc/self/status", "VmHWM:")
}

/// The default budget: half the machine's memory (4 GiB where it cannot be read).
pub fn default_budget() -> u64 {
    proc_kib("/proc/meminfo", "MemTotal:").map_or(4 << 30, |b| b / 2)
}

/// Bytes per input face the whole-mesh path holds at its peak: the mesh (12 B a face and 12 B a
/// vertex, two faces a vertex) plus the method's peak heap on the 1M scan (`meshslim bench
/// scan-1m.ply --backends cluster,hybrid`, docs/PERFORMANCE.md: 36 and 94 MiB), rounded up.
fn whole_bytes_per_face(method: crate::Method) -> u64 {
    match method {
        crate::Method::Hybrid => 128,
        _ => 64,
    }
}

/// Bytes of an OBJ file per triangle, about: a `v` line of ~30 characters per two faces and
/// an `f` line of ~25 per face. An OBJ has no header with its counts; this errs high on files
/// with `vt`/`vn` lines (more bytes per face), so they stream later rather than sooner.
const OBJ_BYTES_PER_FACE: u64 = 40;

/// What `method` would hold reading `path` whole: from a PLY header's face count, an OBJ's
/// size; `None` for the formats that do not stream.
pub fn whole_mesh_estimate(path: &Path, method: crate::Method) -> Option<u64> {
    let faces = match crate::io::Format::from_path(path).ok()? {
        crate::io::Format::Ply => crate::io::ply::header_counts(path).ok()?.1,
        crate::io::Format::Obj => std::fs::metadata(path).ok()?.len() / OBJ_BYTES_PER_FACE,
        _ => return None,
    };
    Some(faces.saturating_mul(whole_bytes_per_face(method)))
}

/// MiB, for messages.
pub fn mib(bytes: u64) -> String {
    format!("{:.0} MiB", bytes as f64 / (1u64 << 20) as f64)
}
