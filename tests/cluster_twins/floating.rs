//! CPU twins of the floating cells' WGSL stages (`shaders/fc_*.wgsl`, described in
//! src/cluster/gpu_schedule.rs), each taking the same buffers in the same order as slices and written as a
//! loop over invocation ids; the radix sort, the cells and the faces are the uniform grid's
//! (`twins.rs`). Fed the GPU's own inputs, every integer buffer comes out equal to the GPU's;
//! the grades (a square root and divisions) agree to rounding, and an ulp can move a grade
//! across a rank step, so the end-to-end comparison is the tests' business. `run` chains them
//! into the whole build: equal, centre for centre, to the CPU driver's `floating::claim`.

use super::{self as twins, CellsOut, FacesOut, grid_of, placed_of};
use meshslim::cluster::floating::{UNCLAIMED, cells_around, grade, hash_grid, radius, rank};
use meshslim::cluster::gpu::ClusterBuild;
use meshslim::cluster::gpu_schedule::{
    RANK_PASSES, ROUND_SLOTS, cluster_params, cluster_passes, float_params,
};
use meshslim::cluster::grid::CellGrid;
use meshslim::cluster::stages::{self, Csr};
use meshslim::compute::common::{V3, dot, sub, xyz};
use meshslim::compute::types::{ClusterParams, ClusterPlaced, FloatParams, Params, Quadric};

/// Per vertex: [`floating::grade`] over its faces in CSR order.
pub fn fc_grades(
    params: &Params,
    positions: &[[f32; 4]], // per vertex
    indices: &[u32],        // per face × 3
    offsets: &[u32],        // per vertex + 1
    vertex_faces: &[u32],   // per corner
    fc_grade: &mut [f32],   // per vertex
) {
    let faces: &[[u32; 3]] = bytemuck::cast_slice(&indices[..3 * params.face_count as usize]);
    let mut dirs = Vec::new();
    for v in 0..params.vertex_count as usize {
        let list = &vertex_faces[offsets[v] as usize..offsets[v + 1] as usize];
        fc_grade[v] = grade(positions, faces, list, v as u32, &mut dirs);
    }
}

/// Per vertex: the top word of [`floating::rank`], and at slot `n - 1 - v` the inverted word
/// and the id, which the stable sort leaves highest rank first.
pub fn fc_ranks(
    params: &Params,
    fc_grade: &[f32],      // per vertex
    fc_rank: &mut [u32],   // per vertex
    sort_keys: &mut [u32], // per vertex
    sort_vals: &mut [u32], // per vertex
) {
    let n = params.vertex_count as usize;
    for v in 0..n {
        let word = (rank(fc_grade[v], v as u32) >> 32) as u32;
        fc_rank[v] = word;
        sort_keys[n - 1 - v] = !word;
        sort_vals[n - 1 - v] = v as u32;
    }
}

/// Per slot of the rank order: the vertex's hash cell and its id.
pub fn fc_keys(
    cluster: &ClusterParams,
    positions: &[[f32; 4]], // per vertex
    fc_order: &[u32],       // per vertex, by rank
    sort_keys: &mut [u32],  // per vertex
    sort_vals: &mut [u32],  // per vertex
) {
    let grid = grid_of(cluster);
    for i in 0..cluster.vertex_count as usize {
        let v = fc_order[i];
        sort_keys[i] = grid.key(xyz(positions[v as usize]));
        sort_vals[i] = v;
    }
}

/// Per vertex: unclaimed, or (locked) its own centre, flagged.
pub fn fc_init(
    cluster: &ClusterParams,
    locked: &[u32],        // per vertex
    fc_centre: &mut [u32], // per vertex
    fc_head: &mut [u32],   // per vertex + 1
) {
    for v in 0..cluster.vertex_count as usize {
        let l = locked[v] != 0;
        fc_centre[v] = if l { v as u32 } else { UNCLAIMED };
        fc_head[v] = l as u32;
    }
}

/// u's rank above v's: the word, then the id.
#[inline]
fn outranks(rank_u: u32, u: u32, rank_v: u32, v: u32) -> bool {
    rank_u > rank_v || (rank_u == rank_v && u > v)
}

/// `d·d ≤ reach²` for `d = q − p`, in `cpu::common::dot`'s order as the shaders' `dot3`.
#[inline]
fn within(p: V3, q: V3, reach: f32) -> bool {
    let d = sub(q, p);
    dot(d, d) <= reach * reach
}

/// Per unclaimed vertex: 1 when no unclaimed vertex within the sum of their radii outranks it;
/// the round's unclaimed vertices counted in its slot.
#[allow(clippy::too_many_arguments)] // the shader's bindings, in its order
pub fn fc_decide(
    cluster: &ClusterParams,
    floating: &FloatParams,
    positions: &[[f32; 4]], // per vertex
    fc_rank: &[u32],        // per vertex
    sort_vals: &[u32],      // per vertex, by (cell, rank)
    cell_head: &[u32],      // per vertex + 1, scanned
    cell_start: &[u32],     // per cell + 1
    cell_key: &[u32],       // per cell
    fc_centre: &[u32],      // per vertex
    fc_decided: &mut [u32], // per vertex
    fc_live: &mut [u32],    // per round slot
) {
    let grid = grid_of(cluster);
    let n = cluster.vertex_count as usize;
    let keys = &cell_key[..cell_head[n] as usize];
    for v in 0..n {
        if fc_centre[v] != UNCLAIMED {
            continue;
        }
        fc_live[floating.slot as usize] += 1;
        let p = xyz(positions[v]);
        let rv = radius(floating.r, v as u32);
        let (ranges, k) = cells_around(&grid, keys, cell_start, p);
        let outranked = ranges[..k].iter().any(|&(a, b)| {
            sort_vals[a as usize..b as usize]
                .iter()
                .take_while(|&&u| outranks(fc_rank[u as usize], u, fc_rank[v], v as u32))
                .any(|&u| {
                    fc_centre[u as usize] == UNCLAIMED
                        && within(p, xyz(positions[u as usize]), rv + radius(floating.r, u))
                })
        });
        fc_decided[v] = !outranked as u32;
    }
}

/// Per centre chosen this round: its claims within its radius, itself, its flag. The balls of
/// one round are disjoint, so the claims do not depend on the order: checked here, as the
/// shader relies on it.
#[allow(clippy::too_many_arguments)] // the shader's bindings, in its order
pub fn fc_claim(
    cluster: &ClusterParams,
    floating: &FloatParams,
    positions: &[[f32; 4]], // per vertex
    sort_vals: &[u32],      // per vertex, by (cell, rank)
    cell_head: &[u32],      // per vertex + 1, scanned
    cell_start: &[u32],     // per cell + 1
    cell_key: &[u32],       // per cell
    fc_decided: &[u32],     // per vertex
    fc_centre: &mut [u32],  // per vertex
    fc_head: &mut [u32],    // per vertex + 1
) {
    let grid = grid_of(cluster);
    let n = cluster.vertex_count as usize;
    let keys = &cell_key[..cell_head[n] as usize];
    // What every invocation reads: nobody writes inside another's ball.
    let before = fc_centre[..n].to_vec();
    let mut claim = |u: usize, c: u32| {
        assert_eq!(
            fc_centre[u], UNCLAIMED,
            "floating cells: vertex {u} claimed twice in one round"
        );
        fc_centre[u] = c;
    };
    for c in 0..n {
        if fc_decided[c] == 0 || before[c] != UNCLAIMED {
            continue;
        }
        let p = xyz(positions[c]);
        let rc = radius(floating.r, c as u32);
        let (ranges, k) = cells_around(&grid, keys, cell_start, p);
        for &(a, b) in &ranges[..k] {
            for &u in &sort_vals[a as usize..b as usize] {
                let u = u as usize;
                if u != c && within(p, xyz(positions[u]), rc) && before[u] == UNCLAIMED {
                    claim(u, c as u32);
                }
            }
        }
        claim(c, c as u32);
        fc_head[c] = 1;
    }
}

/// Per vertex: its centre's number (the scanned flags) and its id, the pairs the sort by
/// cluster orders.
pub fn fc_cluster_keys(
    cluster: &ClusterParams,
    fc_centre: &[u32],     // per vertex
    fc_head: &[u32],       // per vertex + 1, scanned
    sort_keys: &mut [u32], // per vertex
    sort_vals: &mut [u32], // per vertex
) {
    for v in 0..cluster.vertex_count as usize {
        sort_keys[v] = fc_head[fc_centre[v] as usize];
        sort_vals[v] = v as u32;
    }
}

/// Per floating cell: [`stages::cluster_quadric`] with no border planes about its centre, in the
/// box of half-side r (a locked centre: itself).
#[allow(clippy::too_many_arguments)] // the shader's bindings, in its order
pub fn fc_quadrics(
    cluster: &ClusterParams,
    floating: &FloatParams,
    positions: &[[f32; 4]],               // per vertex
    indices: &[u32],                      // per face × 3
    offsets: &[u32],                      // per vertex + 1
    vertex_faces: &[u32],                 // per corner
    face_normals: &[[f32; 4]],            // per face
    locked: &[u32],                       // per vertex
    fc_centre: &[u32],                    // per vertex
    sort_vals: &[u32],                    // per vertex, by cluster
    cell_head: &[u32],                    // per vertex + 1, scanned
    cell_start: &[u32],                   // per cluster + 1
    cluster_placed: &mut [ClusterPlaced], // per cluster
    cluster_quadric: &mut [Quadric],      // per cluster
) {
    let csr = twins::gather_lists(offsets, vertex_faces);
    let surface = twins::gather_surface(cluster, positions, indices, face_normals, &csr);
    for k in 0..cell_head[cluster.vertex_count as usize] as usize {
        let members = &sort_vals[cell_start[k] as usize..cell_start[k + 1] as usize];
        let centre = fc_centre[members[0] as usize] as usize;
        let o = xyz(positions[centre]);
        let half = if locked[centre] != 0 { 0.0 } else { floating.r };
        let lo = o.map(|x| x - half);
        let hi = o.map(|x| x + half);
        let p = stages::cluster_quadric(&surface, members, o, lo, hi);
        cluster_placed[k] = placed_of(&p);
        cluster_quadric[k] = p.quadric;
    }
}

/// One round's buffers as the twins leave them.
#[derive(Clone)]
pub struct Round {
    /// The round's unclaimed vertices (`fc_live` of its slot).
    pub live: u32,
    pub decided: Vec<u32>,
    /// After the claims.
    pub centre: Vec<u32>,
    pub head: Vec<u32>,
}

/// Every buffer of a floating-cell build on the CPU, as each stage leaves it.
pub struct FloatBuild {
    pub cluster: ClusterParams,
    pub grid: CellGrid,
    pub grades: Vec<f32>,
    pub ranks: Vec<u32>,
    /// `fc_ranks`' keys and values, then the rank sort's passes.
    pub rank_keys: (Vec<u32>, Vec<u32>),
    pub rank_passes: Vec<(Vec<u32>, Vec<u32>, Vec<u32>)>,
    pub order: Vec<u32>,
    /// `fc_keys`' keys and values, then the hash sort's passes and cells.
    pub keys: (Vec<u32>, Vec<u32>),
    pub passes: Vec<(Vec<u32>, Vec<u32>, Vec<u32>)>,
    pub cells: CellsOut,
    /// `fc_init`'s centres and flags.
    pub init: (Vec<u32>, Vec<u32>),
    /// Every round that had unclaimed vertices.
    pub rounds: Vec<Round>,
    /// The centre flags scanned, then `fc_cluster_keys`' keys, the sort by cluster and its cells.
    pub head: Vec<u32>,
    pub cluster_keys: (Vec<u32>, Vec<u32>),
    pub cluster_sort: Vec<(Vec<u32>, Vec<u32>, Vec<u32>)>,
    pub clusters: CellsOut,
    pub cluster_placed: Vec<ClusterPlaced>,
    pub cluster_quadric: Vec<Quadric>,
    pub faces: FacesOut,
}

/// The whole floating-cell build at nominal radius `r` through the twins, stage by stage, in
/// the unit frame's box `[lo, hi]`; from `given` grades in place of `fc_grades`' when given (a
/// device's own, so that the rest of its build, all integers and sums, can be compared with the
/// twins' exactly).
pub fn run(
    positions: &[[f32; 4]],
    faces: &[[u32; 3]],
    locked: &[bool],
    lo: V3,
    hi: V3,
    r: f32,
    given: Option<&[f32]>,
) -> FloatBuild {
    let (nv, nf) = (positions.len(), faces.len());
    let indices: &[u32] = bytemuck::cast_slice(faces);
    let csr = Csr::new(nv, faces);
    let params = Params {
        vertex_count: nv as u32,
        face_count: nf as u32,
        ..Default::default()
    };
    let last = |keys: &[u32], vals: &[u32], passes: &[(Vec<u32>, Vec<u32>, Vec<u32>)]| {
        passes.last().map_or((keys.to_vec(), vals.to_vec()), |p| {
            (p.1.clone(), p.2.clone())
        })
    };
    let mut grades = vec![0f32; nv];
    fc_grades(
        &params,
        positions,
        indices,
        &csr.offsets,
        &csr.vertex_faces,
        &mut grades,
    );
    if let Some(given) = given {
        grades.copy_from_slice(given);
    }
    let (mut ranks, mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv], vec![0u32; nv]);
    fc_ranks(&params, &grades, &mut ranks, &mut keys, &mut vals);
    let rank_passes = twins::sort(&keys, &vals, RANK_PASSES);
    let order = last(&keys, &vals, &rank_passes).1;
    let rank_keys = (keys, vals);

    let grid = hash_grid(lo, hi, r);
    let c = cluster_params(&grid, nv, nf);
    let (mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv]);
    fc_keys(&c, positions, &order, &mut keys, &mut vals);
    let hash_keys = (keys.clone(), vals.clone());
    // Locked vertices are keyed like the others: no SINGLETON key, no fourth pass for it.
    let passes = twins::sort(&keys, &vals, twins::radix_passes(&c, false));
    let (sorted, members) = last(&keys, &vals, &passes);
    let cells = twins::cells(&c, &sorted, &members);
    let locked: Vec<u32> = locked.iter().map(|&l| l as u32).collect();
    let (mut centre, mut head) = (vec![0u32; nv], vec![0u32; nv + 1]);
    fc_init(&c, &locked, &mut centre, &mut head);
    let init = (centre.clone(), head.clone());
    let mut decided = vec![0u32; nv];
    let mut rounds = Vec::new();
    for slot in (0..ROUND_SLOTS as u32).cycle() {
        let f = float_params(r, slot);
        let mut live = vec![0u32; ROUND_SLOTS];
        fc_decide(
            &c,
            &f,
            positions,
            &ranks,
            &members,
            &cells.cell_head,
            &cells.cell_start,
            &cells.cell_key,
            &centre,
            &mut decided,
            &mut live,
        );
        if live[slot as usize] == 0 {
            break;
        }
        fc_claim(
            &c,
            &f,
            positions,
            &members,
            &cells.cell_head,
            &cells.cell_start,
            &cells.cell_key,
            &decided,
            &mut centre,
            &mut head,
        );
        rounds.push(Round {
            live: live[slot as usize],
            decided: decided.clone(),
            centre: centre.clone(),
            head: head.clone(),
        });
    }
    meshslim::rounds::cpu::prefix_sum::prefix_sum(nv as u32, &mut head, &mut Vec::new());
    let (mut keys, mut vals) = (vec![0u32; nv], vec![0u32; nv]);
    fc_cluster_keys(&c, &centre, &head, &mut keys, &mut vals);
    let cluster_sort = twins::sort(&keys, &vals, cluster_passes(nv));
    let (sorted, members) = last(&keys, &vals, &cluster_sort);
    let cluster_keys = (keys, vals);
    let clusters = twins::cells(&c, &sorted, &members);
    let n = clusters.cell_key.len();
    let mut cluster_placed = vec![ClusterPlaced::default(); n];
    let mut cluster_quadric = vec![Quadric::default(); n];
    fc_quadrics(
        &c,
        &float_params(r, 0),
        positions,
        indices,
        &csr.offsets,
        &csr.vertex_faces,
        &stages::face_planes(positions, faces),
        &locked,
        &centre,
        &members,
        &clusters.cell_head,
        &clusters.cell_start,
        &mut cluster_placed,
        &mut cluster_quadric,
    );
    let faces = twins::faces(&c, indices, &clusters.vertex_cell);
    FloatBuild {
        cluster: c,
        grid,
        grades,
        ranks,
        rank_keys,
        rank_passes,
        order,
        keys: hash_keys,
        passes,
        cells,
        init,
        rounds,
        head,
        cluster_keys,
        cluster_sort,
        clusters,
        cluster_placed,
        cluster_quadric,
        faces,
    }
}

impl FloatBuild {
    /// The build's result, as the GPU's is read back.
    pub fn result(&self) -> ClusterBuild {
        super::build_of(
            &self.cluster_placed,
            &self.cluster_quadric,
            &self.clusters,
            &self.faces,
        )
    }

    /// Every vertex's centre after the rounds.
    pub fn centre(&self) -> &[u32] {
        self.rounds.last().map_or(&self.init.0, |r| &r.centre)
    }
}
