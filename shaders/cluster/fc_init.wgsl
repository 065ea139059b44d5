// Per vertex: unclaimed, or (locked) a centre of itself alone, flagged in fc_head. Every build
// starts here, so no buffer keeps anything from the build before.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> locked: array<u32>;          // per vertex
@group(0) @binding(2) var<storage, read_write> fc_centre: array<u32>; // per vertex
@group(0) @binding(3) var<storage, read_write> fc_head: array<u32>;   // per vertex + 1

@compute @workgroup_size(256)
fn fc_init(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let v = gid.x + gid.y * nwg.x * WG;
    if (v >= cluster.vertex_count) {
        return;
    }
    let l = locked[v] != 0u;
    fc_centre[v] = select(UNCLAIMED, v, l);
    fc_head[v] = select(0u, 1u, l);
}
