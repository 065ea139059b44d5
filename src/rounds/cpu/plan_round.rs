//! Twin of shaders/rounds/plan_round.wgsl: the next round of a batch planned from the last
//! one's counters, so the GPU runs several rounds between two waits for the host. The round
//! driver ([`crate::rounds::Driver`]) plans with [`next_params`] too, and checks every round
//! the device planned against its own.

use crate::compute::types::*;

/// The parameters of a round on a mesh of `nv` vertices and `nf` faces towards `target`: the
/// faces still needed, the ceiling's share of candidates and whether to trim, on top of the
/// round-independent `base`.
///
/// Integer arithmetic, as the shader's: `nf / 4` is `nf × CEILING_MIN_SHARE` (0.25) rounded
/// down exactly, and `5 × needed < 2 × nf` is `needed < TRIM_SHARE × nf` (0.4) for every count
/// (the f64 product of 0.4 and an integer below 2³² rounds to that integer when they are equal).
///
/// Grouped rounds ([`Params::groups`]) need `open_excess`, the faces the open groups have over
/// their targets, let a share of the open groups' `open_faces` compete (the closed groups'
/// edges cannot), and never trim: a group's last round may take it under its target.
pub fn next_params(
    base: &Params,
    nv: u32,
    nf: u32,
    target: u32,
    open_excess: u32,
    open_faces: u32,
) -> Params {
    use crate::rounds::{CEILING_FACTOR, CEILING_MIN_SHARE, TRIM_SHARE};
    const { assert!(CEILING_MIN_SHARE == 0.25 && TRIM_SHARE == 0.4 && CEILING_FACTOR == 2) };
    let grouped = base.groups != 0;
    let needed = if grouped {
        open_excess
    } else {
        nf.saturating_sub(target)
    };
    Params {
        vertex_count: nv,
        face_count: nf,
        target_faces: target,
        edge_capacity: 3 * nf,
        needed_faces: needed,
        ceiling_wanted: needed
            .div_ceil(2)
            .saturating_mul(CEILING_FACTOR)
            .max(if grouped { open_faces } else { nf } / 4)
            .max(1),
        trim: ((5 * needed as u64) < 2 * nf as u64 && !grouped) as u32,
        ..*base
    }
}

/// Whether a batch goes on after a round that left `c` from `plan`'s counts: it removed
/// something, grew nothing, and is still above the target (`grouped`: a group is still above
/// its own). The driver stops or retries (exhaustively) exactly where this says no.
pub fn goes_on(plan: &PlanState, c: &Counters, grouped: bool) -> bool {
    let above = if grouped {
        c.open_groups != 0
    } else {
        c.faces_out > plan.target_faces
    };
    c.faces_out < plan.faces && c.vertices_out <= plan.vertices && above
}

/// Workgroups for `n` invocations of `per` each, split over y past `max_groups` (the shaders
/// fold y back into their index): `[x, y, 1, 0]`.
pub fn grid(n: u32, per: u32, max_groups: u32) -> [u32; 4] {
    let groups = n.div_ceil(per).max(1);
    let x = groups.min(max_groups.max(1));
    [x, groups.div_ceil(x), 1, 0]
}

/// One invocation: after the round that ran with `params` and left `counters`, either the
/// next round (its parameters, prefix-sum counts and grids into `planned`, `plan` advanced),
/// or the batch's stop: every grid, and the per-edge `dispatch` grids, zero.
pub fn plan_round(
    params: &Params,
    counters: &Counters,
    plan: &mut PlanState,
    planned: &mut Planned,
    dispatch: &mut [u32],
) {
    if plan.stopped == 0 {
        if goes_on(plan, counters, params.groups != 0) {
            plan.vertices = counters.vertices_out;
            plan.faces = counters.faces_out;
            plan.executed += 1;
        } else {
            plan.stopped = 1;
        }
    }
    if plan.stopped != 0 {
        planned.grids = [[0; 4]; grid_slot::COUNT];
        dispatch.fill(0);
        return;
    }
    let (nv, nf) = (plan.vertices, plan.faces);
    let p = next_params(
        params,
        nv,
        nf,
        plan.target_faces,
        counters.open_excess,
        counters.open_faces,
    );
    let m = plan.max_groups;
    planned.params = p;
    let counts = [nv, nf, p.edge_capacity];
    for (i, &n) in counts.iter().enumerate() {
        planned.scans[i] = ScanParams { n, _pad: [0; 3] };
        planned.grids[grid_slot::VERTICES + i] = grid(n, WG, m);
        planned.grids[grid_slot::SCAN_VERTICES + i] = grid(n, SCAN_BLOCK, m);
    }
    planned.grids[grid_slot::VERTICES_OR_FACES] = grid(nv.max(nf), WG, m);
    planned.grids[grid_slot::ONE] = [1, 1, 1, 0];
    // The trim runs over the edge slots' grids only in a round that trims.
    let g = planned.grids;
    let trims = |slot: usize| if p.trim != 0 { g[slot] } else { [0; 4] };
    planned.grids[grid_slot::TRIM_EDGE_SLOTS] = trims(grid_slot::EDGE_SLOTS);
    planned.grids[grid_slot::TRIM_SCAN] = trims(grid_slot::SCAN_VERTICES + 2);
    planned.grids[grid_slot::TRIM_ONE] = trims(grid_slot::ONE);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn state(vertices: u32, faces: u32, target_faces: u32) -> PlanState {
        PlanState {
            vertices,
            faces,
            target_faces,
            executed: 1,
            max_groups: 65535,
            ..Default::default()
        }
    }

    fn after(vertices_out: u32, faces_out: u32) -> Counters {
        Counters {
            vertices_out,
            faces_out,
            ..Default::default()
        }
    }

    /// 1000 faces to 100: the round left 800, so the next needs 700, lets 700 compete (more
    /// than a quarter of 800), does not trim (700 is not under 0.4 × 800), and runs 800 faces'
    /// worth of invocations.
    #[test]
    fn a_round_that_removed_faces_plans_the_next() {
        let base = Params {
            lock_border: 1,
            cos_max_angle: 0.5,
            ..Default::default()
        };
        let mut plan = state(520, 1000, 100);
        let mut planned = Planned::default();
        let mut dispatch = [7u32; 16];
        plan_round(
            &base,
            &after(420, 800),
            &mut plan,
            &mut planned,
            &mut dispatch,
        );
        assert_eq!((plan.vertices, plan.faces, plan.executed), (420, 800, 2));
        assert_eq!(plan.stopped, 0);
        let p = planned.params;
        assert_eq!(
            (p.vertex_count, p.face_count, p.edge_capacity),
            (420, 800, 2400)
        );
        assert_eq!((p.needed_faces, p.ceiling_wanted, p.trim), (700, 700, 0));
        assert_eq!((p.lock_border, p.cos_max_angle), (1, 0.5));
        assert_eq!(planned.scans.map(|s| s.n), [420, 800, 2400]);
        assert_eq!(planned.grids[grid_slot::EDGE_SLOTS], [10, 1, 1, 0]);
        assert_eq!(planned.grids[grid_slot::SCAN_VERTICES], [1, 1, 1, 0]);
        assert_eq!(planned.grids[grid_slot::ONE], [1, 1, 1, 0]);
        assert_eq!(dispatch, [7; 16], "dispatch_args writes the per-edge grids");
        assert_eq!(planned.grids[grid_slot::TRIM_EDGE_SLOTS], [0; 4], "no trim");
        assert_eq!(planned.grids[grid_slot::TRIM_ONE], [0; 4], "no trim");
    }

    /// A round that trims gets the trim's grids: those of the edge slots, their scan, one group.
    #[test]
    fn a_planned_round_that_trims_runs_the_trim() {
        let mut plan = state(100, 200, 120);
        let mut planned = Planned::default();
        let mut dispatch = [0u32; 16];
        plan_round(
            &Params::default(),
            &after(80, 130),
            &mut plan,
            &mut planned,
            &mut dispatch,
        );
        assert_eq!(planned.params.trim, 1);
        let g = planned.grids;
        assert_eq!(g[grid_slot::TRIM_EDGE_SLOTS], g[grid_slot::EDGE_SLOTS]);
        assert_eq!(g[grid_slot::TRIM_SCAN], g[grid_slot::SCAN_VERTICES + 2]);
        assert_eq!(g[grid_slot::TRIM_ONE], [1, 1, 1, 0]);
    }

    /// Near the target a round trims: 5 × 30 < 2 × 130.
    #[test]
    fn a_round_close_to_its_target_trims() {
        let p = next_params(&Params::default(), 70, 130, 100, 0, 0);
        assert_eq!((p.needed_faces, p.ceiling_wanted, p.trim), (30, 32, 1));
        // Exactly 0.4 of the faces still needed does not trim, as `needed < 0.4 × nf` says.
        assert_eq!(next_params(&Params::default(), 70, 100, 60, 0, 0).trim, 0);
    }

    /// A round that removed nothing, grew the mesh or reached the target stops the batch:
    /// every later pass dispatches no workgroup, and the state stays the last accepted round's.
    #[test]
    fn a_round_that_removed_nothing_or_reached_the_target_stops_the_batch() {
        for (c, why) in [
            (after(500, 1000), "removed nothing"),
            (after(530, 990), "grew the vertices"),
            (after(60, 100), "reached the target"),
        ] {
            let mut plan = state(520, 1000, 100);
            let mut planned = Planned {
                grids: [[1; 4]; grid_slot::COUNT],
                ..Default::default()
            };
            let mut dispatch = [7u32; 16];
            plan_round(
                &Params::default(),
                &c,
                &mut plan,
                &mut planned,
                &mut dispatch,
            );
            assert_eq!(plan.stopped, 1, "{why}");
            assert_eq!((plan.vertices, plan.faces, plan.executed), (520, 1000, 1));
            assert_eq!(planned.grids, [[0; 4]; grid_slot::COUNT], "{why}");
            assert_eq!(dispatch, [0; 16], "{why}");
            // Stopped stays stopped, whatever the counters of a round that did not run say.
            plan_round(
                &Params::default(),
                &after(1, 1),
                &mut plan,
                &mut planned,
                &mut dispatch,
            );
            assert_eq!((plan.stopped, plan.executed), (1, 1));
        }
    }

    /// Grouped rounds go on while a group is open, whatever the face count says, need the
    /// open groups' excess, and never trim; with every group closed the batch stops.
    #[test]
    fn grouped_rounds_plan_from_the_open_groups() {
        let base = Params {
            groups: 3,
            ..Default::default()
        };
        let mut plan = state(520, 1000, 900);
        let mut planned = Planned::default();
        let mut dispatch = [0u32; 16];
        // Under the targets' sum (900), but one group is 40 faces over its own.
        let c = Counters {
            open_groups: 1,
            open_excess: 40,
            open_faces: 400,
            ..after(420, 850)
        };
        plan_round(&base, &c, &mut plan, &mut planned, &mut dispatch);
        assert_eq!(plan.stopped, 0);
        let p = planned.params;
        assert_eq!((p.needed_faces, p.trim, p.groups), (40, 0, 3));
        assert_eq!(
            p.ceiling_wanted,
            400 / 4,
            "a quarter of the open groups' faces"
        );
        let closed = Counters {
            open_groups: 0,
            ..after(400, 800)
        };
        plan_round(&base, &closed, &mut plan, &mut planned, &mut dispatch);
        assert_eq!((plan.stopped, plan.faces), (1, 850));
        assert_eq!(planned.grids, [[0; 4]; grid_slot::COUNT]);
    }

    /// A grid past the device's limit is split over y, as the host splits a direct one.
    #[test]
    fn a_large_grid_is_split_over_y() {
        assert_eq!(grid(6_000_000, WG, 65535), [23438, 1, 1, 0]);
        assert_eq!(grid(30_000_000, WG, 65535), [65535, 2, 1, 0]);
        assert_eq!(grid(0, WG, 65535), [1, 1, 1, 0]);
    }
}
