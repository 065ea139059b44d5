// Each face's unit normal and area (first round): the area weights its quadric, the normal stays
// with the face as the reference of the flip test. Relies on positions being normalized.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> positions: array<vec4<f32>>;         // per vertex
@group(0) @binding(2) var<storage, read> indices: array<u32>;                 // per face × 3
@group(0) @binding(3) var<storage, read_write> face_normals: array<vec4<f32>>; // per face

@compute @workgroup_size(256)
fn face_planes(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(num_workgroups) nwg: vec3<u32>) {
    let f = gid.x + gid.y * nwg.x * WG;
    if (f >= params.face_count) {
        return;
    }
    let p0 = positions[indices[3u * f]].xyz;
    let p1 = positions[indices[3u * f + 1u]].xyz;
    let p2 = positions[indices[3u * f + 2u]].xyz;
    let c = cross(p1 - p0, p2 - p0);
    let l = length(c);
    if (l > 0.0) {
        let n = c * (1.0 / l);
        face_normals[f] = vec4<f32>(n, 0.5 * l);
    } else {
        face_normals[f] = vec4<f32>(0.0);
    }
}
