//! Pareto sets of vertex-removal levels of detail by NSGA-II (Campomanes-Álvarez et al. 2012,
//! on Deb et al. 2002). A candidate is a keep bit per removable vertex; it is decoded by the
//! decimation engine, which removes the masked vertices in its own greedy order. A removal the
//! engine refuses (it would flip or crush a face, or the vertex became a corner) keeps its
//! vertex, and the bit is set to say so: the genome always describes its mesh. The objectives
//! are the vertices kept and the error against the original, both minimized.
//!
//! What the source left out and this adds (each measured, docs/PERFORMANCE.md "Levels of
//! detail"): a real mutation; part of the first population seeded with the engine's greedy
//! masks at counts spread over the range; crossover by two cuts along the Morton order (a
//! spatial region from each parent) instead of bit by bit; mutation concentrated around the
//! candidate's removal threshold in the greedy order, where a bit decides something.

use super::nsga::{self, Point};
use crate::decimate::{Decimator, Outcome};
use crate::error::{Error, Result};
use crate::mesh::{Mesh, SplitMix64};
use crate::metrics::{CompareOptions, MeanDistance};
use crate::options::SimplifyOptions;
use rayon::prelude::*;
use std::collections::BTreeMap;

/// The error objective.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ErrorMeasure {
    /// The engine's vertex-to-plane error ([`Decimator::vertex_plane_error`]): microseconds.
    VertexPlane,
    /// The two-sided Metro mean distance, as `meshslim compare` measures it: a fraction of a
    /// second per candidate on a 100k-face mesh.
    Metro,
}

/// How the first population is made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Initialisation {
    /// Every candidate random: each keeps its bits with its own random probability.
    Random,
    /// Half the candidates the engine's greedy masks at vertex counts spread over the range,
    /// the other half random.
    Greedy,
}

/// The variation operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Variation {
    /// Crossover takes a span of the Morton order (a region of the surface) from one parent
    /// and the rest from the other; else each bit from either parent (uniform).
    pub region_crossover: bool,
    /// Mutation spends its flips around the candidate's removal threshold in the greedy order;
    /// else each bit flips with the mutation probability.
    pub threshold_mutation: bool,
}

/// The search's settings.
#[derive(Debug, Clone)]
pub struct ParetoOptions {
    pub population: usize,
    pub generations: usize,
    /// New candidates per generation (the source's 10).
    pub offspring: usize,
    /// Per-bit flip probability (with threshold mutation: the same expected number of flips).
    pub mutation: f64,
    pub tournament: usize,
    pub seed: u64,
    /// Worker threads; `None`: rayon's default. The result does not depend on it.
    pub threads: Option<usize>,
    pub error: ErrorMeasure,
    pub init: Initialisation,
    pub variation: Variation,
    /// The hypervolume's reference point is (all vertices, this error relative to the
    /// bounding-box diagonal).
    pub reference_error: f64,
    /// Greedy anchoring: each child enters with the greedy's mask at its vertex count, so the
    /// front keeps a member other than the greedy's only where it beats the greedy there.
    pub anchor: bool,
    /// Face samples per direction of the in-search Metro mean (`--error metro`); `None`: as
    /// `meshslim compare` (the final front is always measured that way).
    pub search_samples: Option<usize>,
    /// Also measure the final front and the greedy chain at the same vertex counts with the
    /// Metro mean (as `meshslim compare` does), for their hypervolumes.
    pub measure: bool,
    /// The decimation engine's settings (feature angle, removal, borders) and the cancel flag.
    pub engine: SimplifyOptions,
}

impl Default for ParetoOptions {
    fn default() -> Self {
        ParetoOptions {
            population: 100,
            generations: 20,
            offspring: 10,
            mutation: 1e-3,
            tournament: 5,
            seed: 1,
            threads: None,
            error: ErrorMeasure::VertexPlane,
            init: Initialisation::Greedy,
            variation: Variation {
                region_crossover: true,
                threshold_mutation: true,
            },
            reference_error: 0.01,
            anchor: true,
            search_samples: None,
            measure: true,
            engine: SimplifyOptions::with_faces(0),
        }
    }
}

impl ParetoOptions {
    fn check(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidOption(m));
        if self.population < 2 {
            return bad(format!(
                "the population must be 2 or more, got {}",
                self.population
            ));
        }
        if self.offspring == 0 {
            return bad("the offspring per generation must be 1 or more".into());
        }
        if self.tournament == 0 {
            return bad("the tournament size must be 1 or more".into());
        }
        if !(0.0..=1.0).contains(&self.mutation) {
            return bad(format!(
                "the mutation probability must be in [0, 1], got {}",
                self.mutation
            ));
        }
        if !(self.reference_error > 0.0 && self.reference_error.is_finite()) {
            return bad(format!(
                "the reference error must be > 0, got {}",
                self.reference_error
            ));
        }
        if self.threads == Some(0) {
            return bad("--threads must be 1 or more".into());
        }
        self.engine.check()
    }
}

/// One decoded candidate.
#[derive(Debug, Clone, PartialEq)]
pub struct Candidate {
    /// Per removable vertex, in the engine's greedy order ([`Pareto::order`]): kept. Repaired:
    /// a removal the engine refused reads as kept.
    pub keep: Vec<bool>,
    /// Live vertices and faces of its mesh.
    pub vertices: usize,
    pub faces: usize,
    /// The error objective.
    pub error: f64,
}

/// One generation's non-dominated front and its hypervolume.
#[derive(Debug, Clone, PartialEq)]
pub struct Generation {
    /// (share of the vertices kept, error), by vertices.
    pub front: Vec<Point>,
    pub hypervolume: f64,
}

/// A mesh measured with the Metro mean.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    pub vertices: usize,
    pub faces: usize,
    /// The error objective.
    pub objective: f64,
    /// Two-sided Metro mean, relative to the bounding-box diagonal.
    pub metro_mean: f64,
}

/// What [`pareto_front`] found.
#[derive(Debug, Clone)]
pub struct ParetoRun {
    /// Live vertices of the input (after welding) and how many the genome may remove.
    pub input_vertices: usize,
    pub removable: usize,
    pub reference: Point,
    /// Index 0 is the first population, then one per generation.
    pub generations: Vec<Generation>,
    /// The final front, by vertices, without repeats.
    pub front: Vec<Candidate>,
    /// The front's meshes, and their measures (the Metro mean only with `measure`, else NaN).
    pub front_meshes: Vec<Mesh>,
    pub front_measured: Vec<Measured>,
    /// With `measure`: the greedy chain at the front's vertex counts, and its meshes.
    pub baseline_meshes: Vec<Mesh>,
    pub baseline: Vec<Measured>,
    pub evaluations: usize,
}

impl ParetoRun {
    /// The hypervolume of points (vertices, Metro mean) against the reference.
    pub fn metro_hypervolume(&self, of: &[Measured]) -> f64 {
        let n = self.input_vertices as f64;
        let pts: Vec<Point> = of
            .iter()
            .map(|m| [m.vertices as f64 / n, m.metro_mean])
            .collect();
        nsga::hypervolume(&pts, self.reference)
    }
}

/// The decoder: the prepared engine and its greedy order.
pub struct Pareto {
    base: Decimator,
    order: Vec<u32>,
    live: usize,
}

impl Pareto {
    /// Prepares the engine on `mesh` and runs it greedily as far as it goes: the order in
    /// which it removed vertices is the genome's order.
    pub fn new(mesh: &Mesh, engine: &SimplifyOptions) -> Result<Pareto> {
        let base = Decimator::new(mesh, engine);
        let mut greedy = base.clone();
        let run = greedy.run(0, &mut |_| {}, &engine.cancel)?;
        Ok(Pareto {
            live: base.live_vertices(),
            base,
            order: run.order.iter().map(|o| o.0).collect(),
        })
    }

    /// The removable vertices (engine ids) in the greedy order.
    pub fn order(&self) -> &[u32] {
        &self.order
    }

    /// Live vertices before any removal.
    pub fn live_vertices(&self) -> usize {
        self.live
    }

    /// The greedy run's mask after its first `removed` removals.
    pub fn greedy_mask(&self, removed: usize) -> Vec<bool> {
        (0..self.order.len()).map(|k| k >= removed).collect()
    }

    /// Removes the vertices `keep` masks, in the greedy order; a refused removal sets its bit.
    /// Returns the engine afterwards (its mesh is the candidate's).
    pub fn decode(&self, keep: &mut [bool]) -> Decimator {
        assert_eq!(keep.len(), self.order.len(), "one bit per removable vertex");
        let mut d = self.base.clone();
        for (k, bit) in keep.iter_mut().enumerate() {
            if !*bit && matches!(d.remove(self.order[k]), Outcome::Refused(_)) {
                *bit = true;
            }
        }
        d
    }

    /// Decodes `keep` (repairing it) and measures the candidate with `error` (`metro`: the
    /// Metro mean against the input).
    fn evaluate(
        &self,
        mut keep: Vec<bool>,
        metro: &MeanDistance,
        error: ErrorMeasure,
    ) -> Result<Candidate> {
        let d = self.decode(&mut keep);
        let error = match error {
            ErrorMeasure::VertexPlane => d.vertex_plane_error(),
            ErrorMeasure::Metro => metro.mean_rel(&d.mesh())?,
        };
        Ok(Candidate {
            keep,
            vertices: d.live_vertices(),
            faces: d.face_count(),
            error,
        })
    }
}

/// The random stream of candidate `i` of generation `g`: the result depends on the seed only,
/// not on which thread made which candidate.
fn stream(seed: u64, g: usize, i: usize) -> SplitMix64 {
    let mut r = SplitMix64(seed);
    r.0 ^= SplitMix64(((g as u64) << 32) | i as u64).next_u64();
    r.next_u64();
    r
}

/// NSGA-II over `mesh`'s vertex-removal levels of detail; `progress` gets the fraction of the
/// evaluations done.
pub fn pareto_front(
    mesh: &Mesh,
    opts: &ParetoOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<ParetoRun> {
    opts.check()?;
    mesh.validate()?;
    if mesh.triangles.is_empty() {
        return Err(Error::InvalidMesh("the mesh has no faces".into()));
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads.unwrap_or(0))
        .build()
        .map_err(|e| Error::Internal(format!("could not start the worker threads: {e}")))?;
    search(mesh, opts, &pool, progress)
}

/// The search; every parallel step runs on `pool`, and `progress` is called between them.
fn search(
    mesh: &Mesh,
    opts: &ParetoOptions,
    pool: &rayon::ThreadPool,
    progress: &mut dyn FnMut(f32),
) -> Result<ParetoRun> {
    let s = Search::new(mesh, opts, pool)?;
    let m = s.pr.order.len();
    let total =
        (opts.population + opts.generations * opts.offspring * (1 + opts.anchor as usize)) as f32;
    let seeded = match opts.init {
        Initialisation::Greedy => opts.population / 2,
        Initialisation::Random => 0,
    };
    let mut pop = s.first_population(seeded)?;
    // The greedy masks evaluated (the seeds, the twins), by vertex count.
    let mut greedy_known: BTreeMap<usize, Candidate> = pop[..seeded]
        .iter()
        .map(|c| (c.vertices, c.clone()))
        .collect();
    let (twins, evaluated) = anchor(&s.pr, pool, &s.metro, opts, &pop, &[], &mut greedy_known)?;
    pop.extend(twins);
    let mut done = opts.population + evaluated;
    progress(done as f32 / total);
    let mut generations = vec![s.front_of(&pop)];
    for g in 1..=opts.generations {
        pop = s.generation(g, pop, &mut greedy_known, &mut done)?;
        generations.push(s.front_of(&pop));
        progress(done as f32 / total);
    }
    let front = s.final_front(&pop);
    let (front_meshes, front_measured) = s.measure_front(&front)?;
    let (baseline_meshes, baseline) = if opts.measure {
        s.baselines(&front, &front_meshes, &front_measured, &greedy_known)?
    } else {
        (Vec::new(), Vec::new())
    };
    Ok(ParetoRun {
        input_vertices: s.pr.live,
        removable: m,
        reference: s.reference,
        generations,
        front,
        front_meshes,
        front_measured,
        baseline_meshes,
        baseline,
        evaluations: done,
    })
}

/// What the search's steps share: the engine's run over the mesh, the Metro measures, the
/// options and the pool every parallel step runs on.
struct Search<'a> {
    pr: Pareto,
    /// `meshslim compare`'s sampling, so the figures are the ones it prints.
    full: MeanDistance<'a>,
    /// The search's own sampling (`opts.search_samples`).
    metro: MeanDistance<'a>,
    opts: &'a ParetoOptions,
    pool: &'a rayon::ThreadPool,
    /// The hypervolume's reference point.
    reference: [f64; 2],
}

impl<'a> Search<'a> {
    /// The engine's greedy run over `mesh` and the Metro measures against it; an error when no
    /// vertex can be removed.
    fn new(
        mesh: &'a Mesh,
        opts: &'a ParetoOptions,
        pool: &'a rayon::ThreadPool,
    ) -> Result<Search<'a>> {
        let pr = pool.install(|| Pareto::new(mesh, &opts.engine))?;
        let full = MeanDistance::new(mesh, &CompareOptions::default())?;
        let metro = MeanDistance::new(
            mesh,
            &CompareOptions {
                samples: opts.search_samples,
                ..CompareOptions::default()
            },
        )?;
        if pr.order.is_empty() {
            return Err(Error::InvalidMesh(
                "no vertex of the mesh can be removed (every one is a corner, complex or locked), \
                 so it has one level of detail only"
                    .into(),
            ));
        }
        Ok(Search {
            pr,
            full,
            metro,
            opts,
            pool,
            reference: [1.0, opts.reference_error],
        })
    }

    /// A candidate's objectives: the fraction of the vertices it keeps and its error.
    fn point(&self, c: &Candidate) -> Point {
        [c.vertices as f64 / self.pr.live as f64, c.error]
    }

    /// The points of `pop`'s first front, sorted and deduplicated, and their hypervolume.
    fn front_of(&self, pop: &[Candidate]) -> Generation {
        let pts: Vec<Point> = pop.iter().map(|c| self.point(c)).collect();
        let mut front: Vec<Point> = nsga::non_dominated_sort(&pts)[0]
            .iter()
            .map(|&i| pts[i])
            .collect();
        front.sort_by(|a, b| a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1])));
        front.dedup();
        Generation {
            hypervolume: nsga::hypervolume(&front, self.reference),
            front,
        }
    }

    /// The first population, evaluated: its first `seeded` candidates the greedy masks, the
    /// rest random.
    fn first_population(&self, seeded: usize) -> Result<Vec<Candidate>> {
        let (pr, opts, m) = (&self.pr, self.opts, self.pr.order.len());
        self.pool.install(|| {
            (0..opts.population)
                .into_par_iter()
                .map(|i| {
                    opts.engine.cancel.check()?;
                    let keep = if i < seeded {
                        // Removal counts spread evenly over the greedy run.
                        pr.greedy_mask(m * (i + 1) / (seeded + 1))
                    } else {
                        let mut rng = stream(opts.seed, 0, i);
                        let q = rng.next_f64();
                        (0..m).map(|_| rng.next_f64() < q).collect()
                    };
                    pr.evaluate(keep, &self.metro, opts.error)
                })
                .collect::<Result<_>>()
        })
    }

    /// Generation `g`: offspring bred from `pop` and evaluated, their greedy twins (see
    /// [`anchor`]), then the survivors; adds the evaluations to `done`.
    fn generation(
        &self,
        g: usize,
        mut pop: Vec<Candidate>,
        greedy_known: &mut BTreeMap<usize, Candidate>,
        done: &mut usize,
    ) -> Result<Vec<Candidate>> {
        let (pr, opts) = (&self.pr, self.opts);
        opts.engine.cancel.check()?;
        let pts: Vec<Point> = pop.iter().map(|c| self.point(c)).collect();
        let rc = nsga::rank_and_crowding(&pts);
        let children: Vec<Candidate> = self.pool.install(|| {
            (0..opts.offspring)
                .into_par_iter()
                .map(|j| {
                    let mut rng = stream(opts.seed, g, j);
                    let a = nsga::tournament(&rc, opts.tournament, &mut rng);
                    let b = nsga::tournament(&rc, opts.tournament, &mut rng);
                    let mut child = crossover(pr, &pop[a].keep, &pop[b].keep, opts, &mut rng);
                    mutate(&mut child, opts, &mut rng);
                    pr.evaluate(child, &self.metro, opts.error)
                })
                .collect::<Result<_>>()
        })?;
        let twins = anchor(
            pr,
            self.pool,
            &self.metro,
            opts,
            &children,
            &pop,
            greedy_known,
        )?;
        *done += twins.1;
        let twins = twins.0;
        pop.extend(children);
        pop.extend(twins);
        let pts: Vec<Point> = pop.iter().map(|c| self.point(c)).collect();
        let keep = nsga::select_survivors(&pts, opts.population);
        let mut next = Vec::with_capacity(opts.population);
        for (i, c) in pop.into_iter().enumerate() {
            if keep.binary_search(&i).is_ok() {
                next.push(c);
            }
        }
        *done += opts.offspring;
        Ok(next)
    }

    /// The final front, by vertices, one candidate per point.
    fn final_front(&self, pop: &[Candidate]) -> Vec<Candidate> {
        let pts: Vec<Point> = pop.iter().map(|c| self.point(c)).collect();
        let mut front: Vec<Candidate> = nsga::non_dominated_sort(&pts)[0]
            .iter()
            .map(|&i| pop[i].clone())
            .collect();
        front.sort_by(|a, b| {
            a.vertices
                .cmp(&b.vertices)
                .then(a.error.total_cmp(&b.error))
        });
        front.dedup_by(|a, b| a.vertices == b.vertices && a.error == b.error);
        front
    }

    /// The mesh `keep` decodes to, measured: with `measure` (or a Metro search) its Metro
    /// mean, which `known` gives when the search measured with `meshslim compare`'s own
    /// sampling, as its figures are then final.
    fn decode(&self, keep: &[bool], known: Option<f64>) -> Result<(Mesh, Measured)> {
        let opts = self.opts;
        let exact = opts.error == ErrorMeasure::Metro && opts.search_samples.is_none();
        opts.engine.cancel.check()?;
        let d = self.pr.decode(&mut keep.to_vec());
        let out = d.mesh();
        let metro_mean = if let Some(e) = known.filter(|_| exact) {
            e
        } else if opts.measure || opts.error == ErrorMeasure::Metro {
            self.full.mean_rel(&out)?
        } else {
            f64::NAN
        };
        let objective = match opts.error {
            ErrorMeasure::VertexPlane => d.vertex_plane_error(),
            ErrorMeasure::Metro => metro_mean,
        };
        let m = Measured {
            vertices: d.live_vertices(),
            faces: d.face_count(),
            objective,
            metro_mean,
        };
        Ok((out, m))
    }

    /// Each member of `front`'s mesh and its measures.
    fn measure_front(&self, front: &[Candidate]) -> Result<(Vec<Mesh>, Vec<Measured>)> {
        Ok(self
            .pool
            .install(|| {
                front
                    .par_iter()
                    .map(|c| self.decode(&c.keep, Some(c.error)))
                    .collect::<Result<Vec<_>>>()
            })?
            .into_iter()
            .unzip())
    }

    /// The greedy chain's mesh and measures at each member's vertex count (the greedy run's
    /// first `live - count` removals), the errors of masks evaluated already from
    /// `greedy_known`.
    fn baselines(
        &self,
        front: &[Candidate],
        front_meshes: &[Mesh],
        front_measured: &[Measured],
        greedy_known: &BTreeMap<usize, Candidate>,
    ) -> Result<(Vec<Mesh>, Vec<Measured>)> {
        let pr = &self.pr;
        Ok(self
            .pool
            .install(|| {
                front
                    .par_iter()
                    .zip(front_meshes)
                    .zip(front_measured)
                    .map(|((c, mesh), m)| {
                        let greedy = pr.greedy_mask(pr.live - c.vertices);
                        // A member that is the greedy's own mask (a seed that survived) is its
                        // baseline.
                        if greedy == c.keep {
                            Ok((mesh.clone(), m.clone()))
                        } else {
                            self.decode(&greedy, greedy_known.get(&c.vertices).map(|t| t.error))
                        }
                    })
                    .collect::<Result<Vec<_>>>()
            })?
            .into_iter()
            .unzip())
    }
}

/// Greedy anchoring: the greedy's mask at the vertex count of each of `newcomers` joins them
/// (from `known`, else evaluated and added there), unless `pop` or `newcomers` hold it already,
/// so that a newcomer survives only where it beats the greedy chain at its count. Returns the
/// twins to add and how many were evaluated.
fn anchor(
    pr: &Pareto,
    pool: &rayon::ThreadPool,
    metro: &MeanDistance,
    opts: &ParetoOptions,
    newcomers: &[Candidate],
    pop: &[Candidate],
    known: &mut BTreeMap<usize, Candidate>,
) -> Result<(Vec<Candidate>, usize)> {
    if !opts.anchor {
        return Ok((Vec::new(), 0));
    }
    let mut counts: Vec<usize> = newcomers.iter().map(|c| c.vertices).collect();
    counts.sort_unstable();
    counts.dedup();
    let missing: Vec<usize> = counts
        .iter()
        .copied()
        .filter(|n| !known.contains_key(n))
        .collect();
    let fresh: Vec<Candidate> = pool.install(|| {
        missing
            .par_iter()
            .map(|&n| pr.evaluate(pr.greedy_mask(pr.live - n), metro, opts.error))
            .collect::<Result<_>>()
    })?;
    known.extend(fresh.into_iter().map(|c| (c.vertices, c)));
    let twins = counts
        .iter()
        .map(|n| &known[n])
        .filter(|t| {
            !pop.iter()
                .chain(newcomers)
                .any(|p| p.vertices == t.vertices && p.keep == t.keep)
        })
        .cloned()
        .collect();
    Ok((twins, missing.len()))
}

/// A child of `a` and `b`.
fn crossover(
    pr: &Pareto,
    a: &[bool],
    b: &[bool],
    opts: &ParetoOptions,
    rng: &mut SplitMix64,
) -> Vec<bool> {
    if opts.variation.region_crossover {
        // Engine ids are in Morton order: a span of ids is a compact region of the surface.
        let nv = pr.base.vertex_count() as u64;
        let (x, y) = (rng.next_u64() % nv, rng.next_u64() % nv);
        let (lo, hi) = (x.min(y) as u32, x.max(y) as u32);
        pr.order
            .iter()
            .enumerate()
            .map(|(k, &v)| if (lo..hi).contains(&v) { a[k] } else { b[k] })
            .collect()
    } else {
        let mut bits = 0u64;
        (0..a.len())
            .map(|k| {
                if k % 64 == 0 {
                    bits = rng.next_u64();
                }
                if bits >> (k % 64) & 1 == 1 {
                    a[k]
                } else {
                    b[k]
                }
            })
            .collect()
    }
}

/// Flips bits: each with the mutation probability, or (threshold mutation) as many in
/// expectation, within a window around the candidate's threshold (its removal count as a
/// position in the greedy order: below it a greedy mask removes, above it keeps).
fn mutate(keep: &mut [bool], opts: &ParetoOptions, rng: &mut SplitMix64) {
    let m = keep.len();
    let (lo, hi, p) = if opts.variation.threshold_mutation {
        let t = keep.iter().filter(|&&k| !k).count();
        let w = (m / 50).max(16);
        let (lo, hi) = (t.saturating_sub(w), (t + w).min(m));
        let p = (opts.mutation * m as f64 / (hi - lo).max(1) as f64).min(1.0);
        (lo, hi, p)
    } else {
        (0, m, opts.mutation)
    };
    for bit in &mut keep[lo..hi] {
        if rng.next_f64() < p {
            *bit = !*bit;
        }
    }
}
