// Per cluster: its vertex as a drawable position (vec4, w = 1, the normalized frame), so that the
// build's result is a GpuMesh a renderer draws from the device: these positions and
// cluster_faces as the index buffer, nothing read back to the host and uploaded again.

@group(0) @binding(0) var<uniform> cluster: ClusterParams;
@group(0) @binding(1) var<storage, read> cell_head: array<u32>;                 // per vertex + 1
@group(0) @binding(2) var<storage, read> cluster_placed: array<ClusterPlaced>;  // per cell
@group(0) @binding(3) var<storage, read_write> mesh_positions: array<vec4<f32>>; // per cell

@compute @workgroup_size(256)
fn cluster_mesh(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let k = gid.x + gid.y * nwg.x * WG;
    if (k >= cell_head[cluster.vertex_count]) {
        return;
    }
    mesh_positions[k] = vec4<f32>(cluster_placed[k].pos.xyz, 1.0);
}
