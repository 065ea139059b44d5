//! glTF 2.0, as `.gltf` (JSON with embedded or external buffers) and `.glb` (binary container).
//!
//! The document is deserialised into the `gltf::json` types; the GLB container, buffers and
//! accessors are read here, with checked arithmetic and every index looked up with `get`. (The
//! `gltf` crate's own importer panics on some hostile inputs: accessors with `count: 0`, strides
//! smaller than the element, URIs that percent-decode to invalid UTF-8.)
//!
//! Read: every triangle primitive (`TRIANGLES`, `TRIANGLE_STRIP`, `TRIANGLE_FAN`; points and lines
//! are skipped) of every mesh instance reachable from the default scene (else the first scene;
//! with no scene at all, every mesh once, untransformed), with the node transforms applied
//! (normals by the inverse transpose; winding flipped under a mirroring transform). Attributes:
//! `POSITION`, `NORMAL`, `TEXCOORD_0`, `COLOR_0` (float or normalised integers), indices u8/u16/u32
//! or none. UVs are kept as glTF counts them, from the image's top-left corner
//! (`Mesh::uv_origin` = `TopLeft`); the OBJ and PLY writers flip them, and this writer flips
//! those read from OBJ or PLY. Primitives that share attribute accessors under the same transform share vertices.
//! Materials: every document material, by name (`material_N` when unnamed), plus `default` for
//! primitives without one; `face_materials` is `None` when the document has no materials. Each
//! material's JSON (PBR factors, texture references, extensions), the textures, samplers and
//! images are carried to the output unchanged (`Mesh::textures`), each image as bytes from its
//! buffer view, data URI or file (written back embedded), so a textured scan comes out
//! textured; the extensions they use stay declared. Groups:
//! one per glTF mesh (`mesh_N` when unnamed); `face_groups` is `None` when only one unnamed mesh
//! is drawn. Vertices missing an attribute another primitive has get zero (white for colours).
//! Not supported (an error): sparse accessors, accessors without a buffer view.
//!
//! Write: one buffer (a base64 data URI in `.gltf`, the BIN chunk in `.glb`) holding positions,
//! normals, UVs and colours (f32) of all vertices once, and u32 indices; one glTF mesh and node
//! per group (groups without faces are dropped) and one primitive per material in it.
//!
//! `read` holds the reader (the GLB container, buffers, the scene walk, textures), with
//! `document` the parsed document and its accessors and `transform` the node matrices; `write`
//! holds the writer; `encoding` the GLB constants, base64 and percent-decoding both use.

mod document;
mod encoding;
mod read;
mod transform;
mod write;

pub use read::read;
pub(crate) use write::uses_other_uv_sets;
pub use write::write_gltf;
