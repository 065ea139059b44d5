// The preparation on the device (`src/rounds/prepare.rs`): the exact weld, the position classes
// in Morton order, the faces in the order of their lowest class and the normalized positions,
// as `mesh::prepare::Surface` and `rounds::Upload` make them on the host. Only the stages of the
// preparation include this file: its uniform holds f64, which needs the device's SHADER_F64.

// Twin of `PrepParams` in src/compute/types.rs: keep in sync.
struct PrepParams {
    // Input vertices and faces.
    vertex_count: u32,
    face_count: u32,
    // Slots of the weld's hash table less one (a power of two at least twice the vertices).
    table_mask: u32,
    _pad: u32,
    // The Morton grid over the box, as the host's `mesh::morton::grid_codes` takes it: the
    // box's low corner (xyz) and its longest side (w).
    grid: vec4<f32>,
    // The frame: the box's centre (xyz) and one over its diagonal (w), in f64.
    frame: vec4<f64>,
}

// A key never met: sorts after every class and every face's lowest class.
const PREP_PAD: u32 = 0xffffffffu;
