//! The partitioned levels that let large meshes use every core: regions of the Morton order
//! simplified at once through rising cost ceilings, their borders pinned, then written back.

use super::epochs::{self, Epochs};
use super::prepare::Prepared;
use super::queue::Queue;
use super::state::State;
use crate::options::SimplifyOptions;

/// Regions of the second level.
pub(super) const SECOND_LEVEL_REGIONS: usize = 4;
/// Cost ceiling step between the epochs of a level whose floors keep it from reaching its
/// stop (see [`partitioned_level`]); a few epochs still report progress.
const UNSTOPPABLE_LEVEL_STEP: f32 = 64.0;

/// Faces per task when sorting the faces into their regions' lists.
const REGION_LIST_CHUNK: usize = 1 << 16;

/// The partitioned levels stop once the mesh is within 20% of the target.
pub(super) fn partitioned_stop(target: usize) -> usize {
    (target as f64 * 1.2) as usize
}

#[derive(Default)]
pub(super) struct LevelStats {
    pub(super) collapses: usize,
    /// Times a region's queue was filled again (see `State::seeded_at`).
    pub(super) refills: usize,
    pub(super) max_collapse_err2: f64,
    pub(super) hit_max_error: bool,
}

/// Where a partitioned level cuts the topological vertices (Morton ranks `0..nt`): into `base`
/// equal runs of the Morton order, the first starting `shift` ranks along (so run 0 wraps
/// around the end of the order), grouped `base / regions` at a time into `regions` regions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Cuts {
    nt: usize,
    base: usize,
    regions: usize,
    shift: usize,
}

impl Cuts {
    /// The first level: `regions` runs from rank 0.
    pub(super) fn first(nt: usize, regions: usize) -> Cuts {
        Cuts {
            nt,
            base: regions,
            regions,
            shift: 0,
        }
    }

    /// A second level of at most `regions` regions made of this level's runs moved half a run
    /// along, so each of its cuts is half a run from every cut of this level. (Cutting the
    /// shifted order into `regions` equal parts instead put cuts right on first-level cuts
    /// whenever the first level's count was not a multiple of it.)
    pub(super) fn second(self, regions: usize) -> Cuts {
        Cuts {
            nt: self.nt,
            base: self.base,
            regions: regions.min(self.base),
            shift: self.nt / (2 * self.base),
        }
    }

    fn region_of(&self, t: u32) -> u32 {
        let nt = self.nt.max(1);
        let run = (t as usize + self.shift) % nt * self.base / nt;
        (run * self.regions / self.base) as u32
    }
}

/// `v` cut into consecutive pieces of the given lengths (which add up to its length).
fn split_lengths<'a, T>(mut v: &'a mut [T], lens: &[usize]) -> Vec<&'a mut [T]> {
    let pieces = lens
        .iter()
        .map(|&n| {
            let (piece, rest) = std::mem::take(&mut v).split_at_mut(n);
            v = rest;
            piece
        })
        .collect();
    assert!(v.is_empty(), "the lengths cover the slice");
    pieces
}

/// One region of a partitioned level: its own queue on its faces and the crossing faces that
/// touch it, down to `floor` faces.
struct Region<'a> {
    state: State<'a>,
    heap: Queue,
    /// Local topological vertex → topological vertex of the whole mesh.
    topo_global: Vec<u32>,
    floor: usize,
    /// The crossing faces it holds, counted once for the whole level.
    own_cut: usize,
}

impl Epochs for Region<'_> {
    fn counted(&self) -> usize {
        self.state.faces - self.own_cut
    }

    /// One face below the floor at the lowest (a collapse removes at most two), or where it
    /// is if that is lower already.
    fn lowest(&self) -> usize {
        self.state
            .faces
            .min(self.floor.saturating_sub(1))
            .saturating_sub(self.own_cut)
    }

    fn epoch(&mut self, limit: u32) -> bool {
        self.state
            .run(&mut self.heap, self.floor, limit, &mut |_| {})
    }
}

/// One partitioned level of [`simplify_greedy`](super::simplify_greedy), its regions as `cuts`
/// says: returns the whole mesh, reduced, prepared for the next level or the final queue; adds
/// to `stats`. `step` overrides the factor between the epochs' cost ceilings (tests).
pub(super) fn partitioned_level(
    mut p: Prepared,
    opts: &SimplifyOptions,
    cuts: Cuts,
    step: Option<f32>,
    stats: &mut LevelStats,
    progress: &mut dyn FnMut(usize),
) -> Prepared {
    let nt = p.pos.len();
    assert_eq!(cuts.nt, nt, "cuts made for another mesh");
    let marks = Marks::new(&p, cuts);
    let mut subs = marks.regions(&p, opts, cuts.regions);
    run_epochs(&mut subs, opts, marks.cut.len(), step, progress);
    // Write the regions back into the whole mesh: moved vertices, merged quadrics, live faces.
    let (faces, origin, ref_normal) = marks.live_faces(&p, &subs);
    marks.write_vertices(&mut p, &subs);
    marks.write_attributes(&mut p, &subs, stats);
    p.faces = faces;
    p.face_origin = origin;
    p.ref_normal = ref_normal;
    p
}

/// Face `f`'s topological vertices in `p`.
#[inline]
fn face_topo(p: &Prepared, f: usize) -> [u32; 3] {
    p.faces[f].map(|v| p.topo[v as usize])
}

/// Where a level's regions lie on the whole mesh: each vertex's and each face's region, and
/// the faces that cross regions, whose vertices stay put in this level.
struct Marks {
    /// Each topological vertex's region.
    vertex_region: Vec<u32>,
    /// Each face's region; `u32::MAX` for a face that crosses regions.
    face_region: Vec<u32>,
    /// The crossing faces, in face order.
    cut: Vec<u32>,
    /// The vertices of crossing faces.
    frontier: Vec<bool>,
}

impl Marks {
    /// The regions of `p`'s vertices and faces as `cuts` says, and the frontier.
    fn new(p: &Prepared, cuts: Cuts) -> Marks {
        use rayon::prelude::*;
        let nt = p.pos.len();
        // Each vertex's region looked up, not worked out (two divisions) for every corner of
        // every face and again at the write-back; both passes on every core.
        let vertex_region: Vec<u32> = (0..nt as u32)
            .into_par_iter()
            .with_min_len(1 << 14)
            .map(|t| cuts.region_of(t))
            .collect();
        let face_region: Vec<u32> = (0..p.faces.len())
            .into_par_iter()
            .with_min_len(1 << 14)
            .map(|f| {
                let r = face_topo(p, f).map(|t| vertex_region[t as usize]);
                if r[0] == r[1] && r[1] == r[2] {
                    r[0]
                } else {
                    u32::MAX
                }
            })
            .collect();
        // Vertices of faces that cross regions stay put in this level. The crossing faces (a
        // few percent) are found on every core, then marked.
        let cut: Vec<u32> = face_region
            .par_iter()
            .enumerate()
            .with_min_len(1 << 14)
            .filter_map(|(f, &r)| (r == u32::MAX).then_some(f as u32))
            .collect();
        let mut frontier = vec![false; nt];
        for &f in &cut {
            for t in face_topo(p, f as usize) {
                frontier[t as usize] = true;
            }
        }
        Marks {
            vertex_region,
            face_region,
            cut,
            frontier,
        }
    }

    /// Topological vertex `t`'s region.
    #[inline]
    fn region_of(&self, t: u32) -> u32 {
        self.vertex_region[t as usize]
    }

    /// Each region's own faces and the crossing faces that touch it, in face order, from one
    /// pass over the faces (filtering all faces once per region cost R times as much).
    /// Chunks of the faces sorted into regions on every core, then each region's lists joined
    /// in chunk order: the same lists.
    fn region_faces(&self, p: &Prepared, regions: usize) -> Vec<Vec<u32>> {
        use rayon::prelude::*;
        let chunked: Vec<Vec<Vec<u32>>> = self
            .face_region
            .par_chunks(REGION_LIST_CHUNK)
            .enumerate()
            .map(|(i, chunk)| {
                let mut lists: Vec<Vec<u32>> = vec![Vec::new(); regions];
                for (f, &fr) in (i * REGION_LIST_CHUNK..).zip(chunk) {
                    if fr != u32::MAX {
                        lists[fr as usize].push(f as u32);
                    } else {
                        let [a, b, c] = face_topo(p, f).map(|t| self.region_of(t));
                        lists[a as usize].push(f as u32);
                        if b != a {
                            lists[b as usize].push(f as u32);
                        }
                        if c != a && c != b {
                            lists[c as usize].push(f as u32);
                        }
                    }
                }
                lists
            })
            .collect();
        (0..regions)
            .into_par_iter()
            .map(|r| {
                chunked
                    .iter()
                    .flat_map(|lists| lists[r].iter().copied())
                    .collect()
            })
            .collect()
    }

    /// The level's `regions` regions of `p`, each with its sub-problem, queue and floor, set up
    /// on every core.
    fn regions<'a>(
        &self,
        p: &Prepared,
        opts: &'a SimplifyOptions,
        regions: usize,
    ) -> Vec<Region<'a>> {
        use rayon::prelude::*;
        let ratio = opts.target_faces as f64 / p.faces.len() as f64;
        self.region_faces(p, regions)
            .into_par_iter()
            .enumerate()
            .map(|(r, faces)| self.region(p, opts, r as u32, &faces, ratio))
            .collect()
    }

    /// Region `r` of `p` on its `faces`, its floor at `ratio` of its own faces.
    fn region<'a>(
        &self,
        p: &Prepared,
        opts: &'a SimplifyOptions,
        r: u32,
        faces: &[u32],
        ratio: f64,
    ) -> Region<'a> {
        let own = faces
            .iter()
            .filter(|&&f| self.face_region[f as usize] == r)
            .count();
        let own_cut = faces.len() - own;
        let (sub, topo_faces, topo_global) = p.subset(faces, &self.frontier);
        // Pinned frontier vertices cannot thin out; if the interior were simplified far below
        // their density, its faces would fan out from them into long slivers. So a region
        // stops where its frontier would be a quarter of its vertices (a closed triangle mesh
        // has about two faces per vertex) and the next level or the final queue takes it from
        // there.
        let own_frontier = topo_global
            .iter()
            .filter(|&&t| self.frontier[t as usize] && self.region_of(t) == r)
            .count();
        let floor = own_cut + ((own as f64 * ratio).ceil() as usize).max(8 * own_frontier);
        let (mut state, heap) = State::with_topo_faces(sub, topo_faces, opts);
        state.one_thread = true;
        Region {
            state,
            heap,
            topo_global,
            floor,
            own_cut,
        }
    }

    /// The faces of the reduced whole mesh: the crossing faces first, then each region's own
    /// live faces, picked out on every core; returns them with their origins and reference
    /// normals. A sub-problem's faces carry their attribute vertices of the whole mesh (or,
    /// with attributes, its own, mapped back) and, as origin, their index in the whole mesh's
    /// faces.
    fn live_faces(
        &self,
        p: &Prepared,
        subs: &[Region],
    ) -> (Vec<[u32; 3]>, Vec<u32>, Vec<[f32; 3]>) {
        use rayon::prelude::*;
        let live: Vec<Vec<(u32, [u32; 3])>> = subs
            .par_iter()
            .enumerate()
            .map(|(r, sub)| {
                let st = &sub.state;
                let to_whole = |t: [u32; 3]| {
                    if st.p.attr_global.is_empty() {
                        t
                    } else {
                        t.map(|a| st.p.attr_global[a as usize])
                    }
                };
                st.face_alive
                    .iter()
                    .enumerate()
                    .filter_map(|(sf, &alive)| {
                        let gf = st.p.face_origin[sf];
                        (alive && self.face_region[gf as usize] == r as u32)
                            .then(|| (gf, to_whole(st.attr_face(sf))))
                    })
                    .collect()
            })
            .collect();
        // Laid out on every core: each part's place in the whole is known from the lengths
        // before it.
        let cut_part: Vec<(u32, [u32; 3])> = self
            .cut
            .par_iter()
            .map(|&f| (f, p.faces[f as usize]))
            .collect();
        let parts: Vec<&[(u32, [u32; 3])]> = std::iter::once(cut_part.as_slice())
            .chain(live.iter().map(Vec::as_slice))
            .collect();
        let part_lens: Vec<usize> = parts.iter().map(|part| part.len()).collect();
        let n_live = part_lens.iter().sum();
        let mut faces = vec![[0u32; 3]; n_live];
        let mut origin = vec![0u32; n_live];
        let mut ref_normal = vec![[0f32; 3]; n_live];
        split_lengths(&mut faces, &part_lens)
            .into_par_iter()
            .zip(split_lengths(&mut origin, &part_lens))
            .zip(split_lengths(&mut ref_normal, &part_lens))
            .zip(&parts)
            .for_each(|(((faces, origin), ref_normal), part)| {
                for (i, &(gf, t)) in part.iter().enumerate() {
                    faces[i] = t;
                    origin[i] = p.face_origin[gf as usize];
                    ref_normal[i] = p.ref_normal[gf as usize];
                }
            });
        (faces, origin, ref_normal)
    }

    /// The regions' vertices written back into `p`: positions, quadrics and border flags of
    /// the live ones.
    ///
    /// A region's own vertices are one run of the Morton order, or two where the second
    /// level's shifted cut wraps around its end: the vertex arrays split where the region
    /// changes, each run written from its region's state on every core. The state numbers its
    /// vertices in ascending order, so a run's are one stretch of `topo_global`.
    fn write_vertices(&self, p: &mut Prepared, subs: &[Region]) {
        use rayon::prelude::*;
        let nt = p.pos.len();
        let vertex_region = &self.vertex_region;
        let starts: Vec<usize> = (0..nt)
            .into_par_iter()
            .with_min_len(1 << 14)
            .filter(|&g| g == 0 || vertex_region[g] != vertex_region[g - 1])
            .collect();
        let run_lens: Vec<usize> = starts
            .iter()
            .zip(starts.iter().skip(1).chain([&nt]))
            .map(|(start, end)| end - start)
            .collect();
        split_lengths(&mut p.pos, &run_lens)
            .into_par_iter()
            .zip(split_lengths(&mut p.quadrics, &run_lens))
            .zip(split_lengths(&mut p.border, &run_lens))
            .zip(starts)
            .for_each(|(((pos, quadrics), border), start)| {
                let sub = &subs[vertex_region[start] as usize];
                let (st, global) = (&sub.state, &sub.topo_global);
                let end = start + pos.len();
                let lo = global.partition_point(|&g| (g as usize) < start);
                let hi = global.partition_point(|&g| (g as usize) < end);
                for lt in (lo..hi).filter(|&lt| st.alive[lt]) {
                    let i = global[lt] as usize - start;
                    pos[i] = st.p.pos[lt];
                    quadrics[i] = st.p.quadrics[lt];
                    border[i] = st.p.border[lt];
                }
            });
    }

    /// Each region's counts added to `stats`, and the attribute vertices of its own vertices
    /// written back into `p`: values and sums as solved.
    fn write_attributes(&self, p: &mut Prepared, subs: &[Region], stats: &mut LevelStats) {
        for (r, sub) in subs.iter().enumerate() {
            let st = &sub.state;
            stats.collapses += st.collapses;
            stats.refills += st.refills;
            stats.max_collapse_err2 = stats.max_collapse_err2.max(st.max_collapse_err2);
            stats.hit_max_error |= st.hit_max_error;
            if let (Some(whole), Some(local)) = (p.attrs.as_mut(), st.p.attrs.as_ref()) {
                let (m, s) = (whole.layout.m, whole.layout.stride());
                for (la, &ga) in st.p.attr_global.iter().enumerate() {
                    if self.region_of(p.topo[ga as usize]) == r as u32 {
                        let (la, ga) = (la, ga as usize);
                        whole.value[ga * m..(ga + 1) * m]
                            .copy_from_slice(&local.value[la * m..(la + 1) * m]);
                        whole.sums[ga * s..(ga + 1) * s]
                            .copy_from_slice(&local.sums[la * s..(la + 1) * s]);
                    }
                }
            }
        }
    }
}

/// The level's epochs of rising cost ceilings over `subs`, from far below the cheapest edge,
/// each region going on to its next as soon as no earlier epoch can be the level's last (see
/// `epochs`). `step` overrides the factor between the ceilings.
fn run_epochs(
    subs: &mut [Region],
    opts: &SimplifyOptions,
    cut_faces: usize,
    step: Option<f32>,
    progress: &mut dyn FnMut(usize),
) {
    let stop_at = partitioned_stop(opts.target_faces);
    let total = |subs: &[Region]| subs.iter().map(Epochs::counted).sum::<usize>() + cut_faces;
    // The ceilings matter only for where the level stops: a region's collapses come in its own
    // cost order whatever the ceilings, so a region that runs down to its floor ends the same.
    // When the floors keep the level above `stop_at` (every level at 1%, the first at 10%),
    // large steps give the same result in fewer epochs; each epoch walks through every
    // region's data again from a cold cache.
    let lowest = subs.iter().map(Epochs::lowest).sum::<usize>() + cut_faces;
    let step = step.unwrap_or(if lowest > stop_at {
        UNSTOPPABLE_LEVEL_STEP
    } else {
        2.0
    });
    epochs::run(
        subs,
        epochs::Stop {
            step,
            stop_at,
            cut_faces,
            cancel: &opts.cancel,
        },
        rayon::current_num_threads(),
        progress,
    );
    debug_assert!(total(subs) >= lowest, "a region went below its floor");
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A level that its floors keep above its stop ends the same whatever the steps between
    /// its cost ceilings: each region takes its collapses in its own cost order down to its
    /// floor, and fills its queue again when it runs dry exactly where an uninterrupted run
    /// would. (This is what lets such a level take steps of 64 instead of doubling.)
    #[test]
    fn unstoppable_level_ignores_ceiling_steps() {
        let m = crate::mesh::noisy_sphere(5, 0.002, 3);
        let mut opts = SimplifyOptions::with_ratio(m.triangles.len(), 0.01).unwrap();
        // Without an error bound the regions run down to their floors; with a tight one their
        // queues run dry above them and are filled again (edges refused earlier may have
        // become valid), the path a cut-up run used to skip.
        for max_error in [None, Some(1e-4)] {
            opts.max_error = max_error;
            let level = |step| {
                let p = Prepared::new(&m, &opts);
                let cuts = Cuts::first(p.pos.len(), 8);
                let mut stats = LevelStats::default();
                let p = partitioned_level(p, &opts, cuts, Some(step), &mut stats, &mut |_| {});
                let state = (p.faces, p.pos, p.quadrics, p.border);
                (state, stats.collapses, stats.refills)
            };
            let doubling = level(2.0);
            let what = format!("max error {max_error:?}");
            assert!(
                doubling.0.0.len() > partitioned_stop(opts.target_faces),
                "{what}: the floors should keep this level above its stop: {} faces",
                doubling.0.0.len()
            );
            assert!(doubling.1 > 0, "{what}: the level collapsed nothing");
            if max_error.is_some() {
                assert!(doubling.2 > 0, "{what}: no region filled its queue again");
            }
            // 1e30: ceilings 1e-30, 1, 1e30 and infinity, so nearly one uninterrupted run.
            for step in [64.0, 1e30] {
                assert!(
                    level(step) == doubling,
                    "{what}: steps of {step} changed the level"
                );
            }
        }
    }

    /// Every cut of the second level is half a first-level run from the nearest first-level
    /// cut, whatever the first level's region count, and the second level has all its regions.
    #[test]
    fn second_level_cuts_fall_between_first_level_cuts() {
        let nt = 100_003;
        let cut_ranks = |c: Cuts| -> Vec<usize> {
            (1..nt)
                .filter(|&t| c.region_of(t as u32) != c.region_of(t as u32 - 1))
                .collect()
        };
        for base in 2..=40 {
            let first = Cuts::first(nt, base);
            let second = first.second(SECOND_LEVEL_REGIONS);
            let (a, b) = (cut_ranks(first), cut_ranks(second));
            assert_eq!(a.len(), base - 1);
            let regions: std::collections::BTreeSet<u32> =
                (0..nt as u32).map(|t| second.region_of(t)).collect();
            assert_eq!(regions.len(), SECOND_LEVEL_REGIONS.min(base), "{base} runs");
            let run = nt / base;
            for &c in &b {
                let nearest = a.iter().map(|&x| x.abs_diff(c)).min().unwrap_or(nt);
                assert!(
                    nearest + 2 >= run / 2,
                    "{base} runs: a second-level cut at {c} is {nearest} from a first-level cut"
                );
            }
        }
    }
}
