//! PLY (Stanford polygon format): ascii, binary_little_endian and binary_big_endian.
//!
//! Reader: a streaming parser of its own over a `BufReader`. Every scalar type PLY names is
//! accepted (`char uchar short ushort int uint float double` and the sized aliases `int8 uint8
//! int16 uint16 int32 uint32 float32 float64`), for properties, list counts and list items.
//!
//! - `vertex`: `x y z`; `nx ny nz`; `red green blue [alpha]` (integer types are scaled by their
//!   maximum, so `uchar` becomes `/255`; float colours are kept as they are); texture coordinates as
//!   `s t`, `u v`, `texture_u texture_v` or `texture_s texture_t`. Other vertex properties are skipped.
//! - `face`: the `vertex_indices` (or `vertex_index`) list; polygons are fan-triangulated, lists of
//!   fewer than three indices (points, edges) are dropped. Other face properties are skipped.
//! - `tristrips`: one list of indices per element; `-1` restarts a strip; strip triangles alternate
//!   their winding; triangles with a repeated index (the degenerate triangles strips use to turn
//!   corners and join strips) are dropped.
//! - Any other element is skipped, lists included.
//!
//! Zero-area faces with three distinct indices are kept: the topology report counts them.
//!
//! Hostile input: counts declared in the header are checked against the bytes that follow it
//! before anything is allocated (each element needs a minimum number of bytes), so a header that
//! claims four billion faces in a tiny file fails at once; reservations are capped by the file
//! size and vectors otherwise grow as data arrives. Binary errors carry byte offsets, ascii and
//! header errors line numbers. Non-finite vertex coordinates and out-of-range indices are errors
//! that name the vertex or face.
//!
//! Throughput (release build, warm page cache, this 2-core machine, `cargo bench --bench io`):
//! horse.ply (2.4 MB, binary LE, `uchar int` face lists) 370 MiB/s, igea.ply (3.1 MB,
//! binary LE, one tristrips element) 430 MiB/s.
//! A 100 MB binary PLY therefore reads in about a quarter of a second.
//!
//! Writer: binary little endian by default, or ascii / big endian through [`write_ply`]; normals,
//! colours (as `uchar` when every channel is exactly `k/255`, else as `float`) and texture
//! coordinates (`s t`) are written when present. Materials and groups have no PLY equivalent and
//! are not written.
//!
//! `header` holds the header parser and the scalar types, `read` the body reader, `write` the
//! writer.

mod header;
mod read;
mod write;

pub use header::PlyEncoding;
pub use read::{header_counts, read, read_into};
pub use write::write_ply;
