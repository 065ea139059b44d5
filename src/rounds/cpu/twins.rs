//! The rounds' stages and their CPU twins: the table `CpuRounds` runs a stage by, found by the
//! stage itself (the schedule's statics), never by its entry point's name. Each twin takes the
//! buffers its stage binds, in the stage's binding order, sized for the round as the GPU's are.

use super::*;

/// A stage's CPU twin: it takes the buffers the stage binds, in the stage's binding order.
type Twin = fn(&mut CpuRounds, &Params);

/// The vertex and face counts of the round.
fn counts(p: &Params) -> (usize, usize) {
    (p.vertex_count as usize, p.face_count as usize)
}

/// Every stage of the rounds with its twin, found by the stage itself (the schedule's statics),
/// never by its entry point's name; `tests::every_stage_has_one_twin` checks the list.
pub(super) static TWINS: &[(&Stage, Twin)] = &[
    (&schedule::ADJACENCY_COUNT, |s, p| {
        adjacency_count::adjacency_count(p, &s.indices, atomics(&mut s.offsets))
    }),
    (&schedule::ADJACENCY_FILL, |s, p| {
        let nf = counts(p).1;
        s.vertex_faces.resize(3 * nf, 0);
        adjacency_fill::adjacency_fill(
            p,
            &s.indices,
            &s.offsets,
            atomics(&mut s.cursor),
            Scatter::new(&mut s.vertex_faces),
        )
    }),
    (&schedule::ADJACENCY_SORT, |s, p| {
        adjacency_sort::adjacency_sort(p, &s.offsets, Scatter::new(&mut s.vertex_faces))
    }),
    (&schedule::FACE_PLANES, |s, p| {
        face_planes::face_planes(p, &s.positions, &s.indices, &mut s.face_normals)
    }),
    (&schedule::VERTEX_FLAGS, |s, p| {
        vertex_flags::vertex_flags(p, &s.indices, &s.offsets, &s.vertex_faces, &mut s.flags)
    }),
    (&schedule::VERTEX_QUADRICS, |s, p| {
        vertex_quadrics::vertex_quadrics(
            p,
            &s.positions,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.face_normals,
            &s.face_extra,
            &mut s.quadrics,
        )
    }),
    (&schedule::VERTEX_ATTRIBUTES, |s, p| {
        vertex_attributes::vertex_attributes(
            p,
            &s.positions,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.face_normals,
            &s.face_extra,
            &s.attr_values,
            &mut s.quadrics,
            Scatter::new(&mut s.attr_sums),
        )
    }),
    (&schedule::EDGES_COUNT, |s, p| {
        let nv = counts(p).0;
        reset(&mut s.edge_offsets, nv + 1);
        s.remap.resize(nv, 0);
        s.neighbours.resize(2 * s.vertex_faces.len(), 0);
        edges_count::edges_count(
            p,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            Scatter::new(&mut s.edge_offsets),
            Scatter::new(&mut s.remap),
            Scatter::new(&mut s.neighbours),
        )
    }),
    (&schedule::EDGES_FILL, |s, p| {
        let nv = counts(p).0;
        s.edges.resize(s.edge_offsets[nv] as usize, [0; 2]);
        edges_fill::edges_fill(
            p,
            &s.offsets,
            &s.neighbours,
            &s.edge_offsets,
            Scatter::new(&mut s.edges),
        )
    }),
    (&schedule::DISPATCH_ARGS, |s, p| {
        dispatch_args::dispatch_args(
            p,
            &s.edge_offsets,
            atomics(&mut s.counters),
            &mut s.dispatch,
        )
    }),
    (&schedule::EDGE_ERRORS, |s, p| {
        let nv = counts(p).0;
        let ne = s.edge_offsets[nv] as usize;
        s.candidates.resize(ne, EdgeCandidate::default());
        s.edge_state.resize(ne, 0);
        s.tentative.resize(ne, 0);
        edge_errors::edge_errors(
            p,
            &s.positions,
            &s.quadrics,
            &s.flags,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.edges,
            &s.edge_offsets,
            &s.face_extra,
            &s.vertex_attr,
            &s.attr_values,
            &s.attr_sums,
            &mut s.candidates,
            &mut s.edge_state,
            atomics(&mut s.histogram),
            atomics(&mut s.counters),
        )
    }),
    (&schedule::COST_CEILING, |s, p| {
        cost_ceiling::cost_ceiling(p, &s.histogram, atomics(&mut s.counters))
    }),
    (&schedule::LIVE_LIST, |s, p| {
        live_list::live_list(
            p,
            &s.edge_offsets,
            &s.candidates,
            &mut s.edge_state,
            atomics(&mut s.counters),
            &mut s.live,
        )
    }),
    (&schedule::EDGE_COSTS, |s, p| {
        edge_costs::edge_costs(
            p,
            &s.positions,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.face_normals,
            &s.live,
            Scatter::new(&mut s.candidates),
            Scatter::new(&mut s.edge_state),
            atomics(&mut s.counters),
        )
    }),
    (&schedule::SELECT_COST, |s, _| {
        select_cost::select_cost(
            &s.offsets,
            &s.vertex_faces,
            &s.edges,
            &s.live,
            &s.candidates,
            atomics(&mut s.vertex_lock),
            atomics(&mut s.counters),
            atomics(&mut s.edge_state),
            atomics(&mut s.face_best),
        )
    }),
    (&schedule::SELECT_ID, |s, _| {
        select_id::select_id(
            &s.offsets,
            &s.vertex_faces,
            &s.edges,
            &s.live,
            &s.candidates,
            atomics(&mut s.face_best),
            atomics(&mut s.counters),
            atomics(&mut s.edge_state),
            atomics(&mut s.face_id),
        )
    }),
    (&schedule::SELECT_WIN, |s, _| {
        select_win::select_win(
            &s.offsets,
            &s.vertex_faces,
            &s.edges,
            &s.live,
            atomics(&mut s.face_id),
            atomics(&mut s.edge_state),
            Scatter::new(&mut s.tentative),
            atomics(&mut s.counters),
        )
    }),
    (&schedule::VALIDATE, |s, p| {
        validate::validate(
            p,
            &s.flags,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.edges,
            &s.tentative,
            Scatter::new(&mut s.candidates),
            atomics(&mut s.edge_state),
            atomics(&mut s.vertex_lock),
            atomics(&mut s.counters),
        )
    }),
    (&schedule::TRIM_HISTOGRAM, |s, p| {
        trim_histogram::trim_histogram(
            p,
            &s.candidates,
            &s.edge_state,
            &s.edge_offsets,
            atomics(&mut s.trim_histogram),
        )
    }),
    (&schedule::TRIM_CEILING, |s, p| {
        trim_ceiling::trim_ceiling(p, &s.trim_histogram, atomics(&mut s.counters))
    }),
    (&schedule::TRIM_MARK, |s, p| {
        reset(&mut s.marks, p.edge_capacity as usize + 1);
        trim_mark::trim_mark(
            p,
            &s.candidates,
            &s.edge_state,
            &s.edge_offsets,
            atomics(&mut s.counters),
            &mut s.marks,
        )
    }),
    (&schedule::TRIM_APPLY, |s, p| {
        trim_apply::trim_apply(
            p,
            &s.candidates,
            &s.marks,
            atomics(&mut s.counters),
            &s.edge_offsets,
            &mut s.edge_state,
        )
    }),
    (&schedule::COLLAPSE, |s, p| {
        collapse::collapse(
            p,
            &s.candidates,
            &s.edge_state,
            &s.edge_offsets,
            &s.indices,
            &s.offsets,
            &s.vertex_faces,
            &s.vertex_attr,
            Scatter::new(&mut s.positions),
            Scatter::new(&mut s.quadrics),
            Scatter::new(&mut s.flags),
            Scatter::new(&mut s.remap),
            Scatter::new(&mut s.face_extra),
            Scatter::new(&mut s.attr_values),
            Scatter::new(&mut s.attr_sums),
        )
    }),
    (&schedule::COMPACT_MARK, |s, p| {
        let (nv, nf) = counts(p);
        reset(&mut s.vertex_keep, nv + 1);
        reset(&mut s.face_keep, nf + 1);
        compact_mark::compact_mark(
            p,
            &s.indices,
            &s.remap,
            &mut s.vertex_keep,
            &mut s.face_keep,
        )
    }),
    (&schedule::COMPACT_VERTICES, |s, p| {
        let nv = counts(p).0;
        let nv2 = s.vertex_keep[nv] as usize;
        s.out_positions.resize(nv2, [0.0; 4]);
        s.out_quadrics.resize(nv2, Quadric::default());
        s.out_flags.resize(nv2, 0);
        s.out_vertex_attr.resize(nv2, 0);
        compact_vertices::compact_vertices(
            p,
            &s.vertex_keep,
            &s.positions,
            &s.quadrics,
            &s.flags,
            &s.vertex_attr,
            Scatter::new(&mut s.out_positions),
            Scatter::new(&mut s.out_quadrics),
            Scatter::new(&mut s.out_flags),
            Scatter::new(&mut s.out_vertex_attr),
        )
    }),
    (&schedule::COMPACT_FACES, |s, p| {
        let nf = counts(p).1;
        let nf2 = s.face_keep[nf] as usize;
        s.out_indices.resize(3 * nf2, 0);
        s.out_face_normals.resize(nf2, [0.0; 4]);
        s.out_face_extra.resize(nf2, FaceExtra::default());
        compact_faces::compact_faces(
            p,
            &s.indices,
            &s.face_normals,
            &s.face_extra,
            &s.remap,
            &s.vertex_keep,
            &s.face_keep,
            Scatter::new(&mut s.out_indices),
            Scatter::new(&mut s.out_face_normals),
            Scatter::new(&mut s.out_face_extra),
        )
    }),
    (&schedule::DRAW_ARGS, |s, p| {
        let mut draw = DrawArgs::default();
        draw_args::draw_args(
            p,
            &s.vertex_keep,
            &s.face_keep,
            atomics(&mut s.counters),
            &mut draw,
        );
        s.draw = draw;
    }),
    (&schedule::PLAN_ROUND, |s, p| {
        let c: Counters = *bytemuck::from_bytes(bytemuck::cast_slice(&s.counters));
        plan_round::plan_round(p, &c, &mut s.plan, &mut s.planned, &mut s.dispatch)
    }),
    (&schedule::GROUP_FLAGS, |s, p| {
        group_flags::group_flags(
            p,
            &s.offsets,
            &s.vertex_faces,
            &s.face_extra,
            &s.face_group,
            &s.group_closed,
            &mut s.flags,
        )
    }),
    (&schedule::GROUP_ERRORS, |s, p| {
        group_errors::group_errors(
            p,
            &s.candidates,
            &s.edge_state,
            &s.edge_offsets,
            &s.offsets,
            &s.vertex_faces,
            &s.face_extra,
            &s.face_group,
            atomics(&mut s.group_err),
        )
    }),
    (&schedule::GROUP_FACES, |s, p| {
        group_faces::group_faces(
            p,
            &s.face_keep,
            &s.out_face_extra,
            &s.face_group,
            atomics(&mut s.group_count),
        )
    }),
    (&schedule::GROUP_OPEN, |s, p| {
        group_open::group_open(
            p,
            &s.group_target,
            &mut s.group_count,
            &mut s.group_closed,
            atomics(&mut s.counters),
        )
    }),
];

#[cfg(test)]
mod tests {
    use super::*;

    /// Every stage the rounds run has exactly one twin here, but the prefix sum's three, which
    /// the `PrefixSum` step runs as one (`prefix_sum::prefix_sum`).
    #[test]
    fn every_stage_has_one_twin() {
        for stage in schedule::STAGES.iter().flat_map(|l| l.iter()) {
            let twins = TWINS.iter().filter(|t| std::ptr::eq(t.0, *stage)).count();
            let want = usize::from(
                !schedule::PREFIX_SUM
                    .iter()
                    .any(|s| std::ptr::eq(*s, *stage)),
            );
            assert_eq!(twins, want, "{}: {twins} twins", stage.entry);
        }
        assert_eq!(
            TWINS.len(),
            schedule::STAGES.iter().map(|l| l.len()).sum::<usize>() - 3
        );
    }
}
