// The attribute vertices of the faces' corners (face_extra), for the seam rules; prepended
// (after common.wgsl and mesh.wgsl) to the stages that bind face_extra beside the faces' CSR
// lists.

// The attribute vertex face f uses at its corner on vertex v.
fn corner_attr(f: u32, v: u32) -> u32 {
    let t = face_of(f);
    let x = face_extra[f];
    if (t.x == v) { return x.attr0; }
    if (t.y == v) { return x.attr1; }
    return x.attr2;
}
