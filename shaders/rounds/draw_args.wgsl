// One invocation: the counts after compaction for the host, and the indexed indirect draw
// arguments a renderer uses to draw the current mesh without reading its size back.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> vertex_keep: array<u32>;  // per vertex + 1
@group(0) @binding(2) var<storage, read> face_keep: array<u32>;    // per face + 1
@group(0) @binding(3) var<storage, read_write> counters: array<atomic<u32>, 16>;
@group(0) @binding(4) var<storage, read_write> draw: DrawArgs;

@compute @workgroup_size(1)
fn draw_args() {
    let nv = vertex_keep[params.vertex_count];
    let nf = face_keep[params.face_count];
    atomicStore(&counters[C_VERTICES_OUT], nv);
    atomicStore(&counters[C_FACES_OUT], nf);
    draw.index_count = 3u * nf;
    draw.instance_count = 1u;
    draw.first_index = 0u;
    draw.base_vertex = 0;
    draw.first_instance = 0u;
}
