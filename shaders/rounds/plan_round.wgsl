// One invocation: the next round of a batch planned on the device from the last round's
// counters (parameters, prefix-sum counts, indirect grids), so the host waits once a batch.
// Relies on rounds only shrinking the mesh: once a round removes nothing, grows it or reaches
// the target (grouped rounds: every group's), every grid of the batch is zero and the rounds past the stop change nothing.

@group(0) @binding(0) var<uniform> params: Params;
@group(0) @binding(1) var<storage, read> counters: array<u32, 16>;
@group(0) @binding(2) var<storage, read_write> plan: PlanState;
@group(0) @binding(3) var<storage, read_write> planned: Planned;
@group(0) @binding(4) var<storage, read_write> dispatch: array<u32, 16>; // four (x, y, z, _) grids

// Workgroups for n invocations of `per` each, split over y past the device's limit.
fn grid(n: u32, per: u32) -> vec4<u32> {
    let groups = max((n + per - 1u) / per, 1u);
    let x = min(groups, max(plan.max_groups, 1u));
    return vec4<u32>(x, (groups + x - 1u) / x, 1u, 0u);
}

@compute @workgroup_size(1)
fn plan_round() {
    if (plan.stopped == 0u) {
        let nv = counters[C_VERTICES_OUT];
        let nf = counters[C_FACES_OUT];
        // Twin of cpu::plan_round::goes_on: grouped rounds go on while a group is open.
        var above = nf > plan.target_faces;
        if (params.groups != 0u) {
            above = counters[C_OPEN_GROUPS] != 0u;
        }
        if (nf < plan.faces && nv <= plan.vertices && above) {
            plan.vertices = nv;
            plan.faces = nf;
            plan.executed = plan.executed + 1u;
        } else {
            plan.stopped = 1u;
        }
    }
    if (plan.stopped != 0u) {
        for (var i = 0u; i < GRID_SLOTS; i = i + 1u) {
            planned.grids[i] = vec4<u32>(0u);
        }
        for (var i = 0u; i < 16u; i = i + 1u) {
            dispatch[i] = 0u;
        }
        return;
    }
    let nv = plan.vertices;
    let nf = plan.faces;
    // Twin of cpu::plan_round::next_params. 5 × needed fits in u32: a face takes 12 bytes of
    // an index binding, so no device holds 2^32 / 5 faces.
    var p = params;
    // Grouped rounds need the open groups' excess, and never trim.
    var needed = 0u;
    if (params.groups != 0u) {
        needed = counters[C_OPEN_EXCESS];
    } else if (nf > plan.target_faces) {
        needed = nf - plan.target_faces;
    }
    p.vertex_count = nv;
    p.face_count = nf;
    p.target_faces = plan.target_faces;
    p.edge_capacity = 3u * nf;
    p.needed_faces = needed;
    let half = (needed + 1u) / 2u;
    var wanted = 0xffffffffu;
    if (half <= 0x7fffffffu) {
        wanted = 2u * half;
    }
    // Grouped rounds let a share of the open groups' faces compete, not of the closed ones'.
    var share = nf;
    if (params.groups != 0u) {
        share = counters[C_OPEN_FACES];
    }
    p.ceiling_wanted = max(max(wanted, share / 4u), 1u);
    p.trim = select(0u, 1u, 5u * needed < 2u * nf && params.groups == 0u);
    planned.params = p;
    let counts = vec3<u32>(nv, nf, p.edge_capacity);
    for (var i = 0u; i < 3u; i = i + 1u) {
        planned.scans[i].n = counts[i];
        planned.scans[i]._pad0 = 0u;
        planned.scans[i]._pad1 = 0u;
        planned.scans[i]._pad2 = 0u;
        planned.grids[GRID_VERTICES + i] = grid(counts[i], WG);
        planned.grids[GRID_SCAN_VERTICES + i] = grid(counts[i], SCAN_BLOCK);
    }
    planned.grids[GRID_VERTICES_OR_FACES] = grid(max(nv, nf), WG);
    planned.grids[GRID_ONE] = vec4<u32>(1u, 1u, 1u, 0u);
    var trim = vec3<u32>(0u);
    if (p.trim != 0u) {
        trim = vec3<u32>(GRID_EDGE_SLOTS, GRID_SCAN_VERTICES + 2u, GRID_ONE);
        planned.grids[GRID_TRIM_EDGE_SLOTS] = planned.grids[trim.x];
        planned.grids[GRID_TRIM_SCAN] = planned.grids[trim.y];
        planned.grids[GRID_TRIM_ONE] = planned.grids[trim.z];
    } else {
        planned.grids[GRID_TRIM_EDGE_SLOTS] = vec4<u32>(0u);
        planned.grids[GRID_TRIM_SCAN] = vec4<u32>(0u);
        planned.grids[GRID_TRIM_ONE] = vec4<u32>(0u);
    }
}
