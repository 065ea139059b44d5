//! Building the DAG level by level: group the current clusters, simplify every group to half
//! its triangles with the border to the other groups pinned, split each result into clusters,
//! and go on with them until one cluster is left or no group can halve.

use super::groups::{Member, group};
use super::meshlets::{Limits, split};
use super::{Cluster, Dag, Group, NONE, round_up, sphere_around, sphere_of_points};
use crate::error::{Error, Result};
use crate::mesh::Mesh;
use crate::mesh::weld::{bits, vertex_bits};
use crate::options::{AttributeWeights, Backend, Cancel, SimplifyOptions};
use rayon::prelude::*;
use rustc_hash::FxHashMap;
use serde::Serialize;

/// How a DAG is built.
#[derive(Debug, Clone)]
pub struct DagOptions {
    /// Triangles per cluster at most.
    pub max_triangles: usize,
    /// Vertices per cluster at most (a mesh shader's output limit).
    pub max_vertices: usize,
    /// Clusters per group at most (meshoptimizer's clusterlod uses 16).
    pub group_size: usize,
    /// What simplifies each group: `cpu` runs the greedy on every group at once across the
    /// cores; `cpu-parallel` and `gpu` run the rounds once per level, every group to its own
    /// target (`auto` picks one of those two as `simplify` does).
    pub backend: Backend,
    pub attributes: AttributeWeights,
    /// A group whose simplification keeps more than this fraction of its triangles is stuck: its
    /// clusters go on to the next level as they are, to be grouped with other neighbours.
    pub stuck_ratio: f64,
    pub cancel: Cancel,
}

impl Default for DagOptions {
    fn default() -> Self {
        DagOptions {
            max_triangles: 128,
            max_vertices: 255,
            group_size: 16,
            backend: Backend::Cpu,
            attributes: AttributeWeights::default(),
            stuck_ratio: 0.85,
            cancel: Cancel::default(),
        }
    }
}

impl DagOptions {
    fn check(&self) -> Result<()> {
        let bad = |m: String| Err(Error::InvalidOption(m));
        if !(1..=65536).contains(&self.max_triangles) {
            return bad(format!(
                "cluster triangles must be 1 to 65536, got {}",
                self.max_triangles
            ));
        }
        if self.max_vertices < 3 {
            return bad(format!(
                "cluster vertices must be at least 3, got {}",
                self.max_vertices
            ));
        }
        if !(2..=1024).contains(&self.group_size) {
            return bad(format!(
                "group size must be 2 to 1024 clusters, got {}",
                self.group_size
            ));
        }
        if !(self.stuck_ratio > 0.0 && self.stuck_ratio < 1.0) {
            return bad(format!(
                "the stuck ratio must be between 0 and 1, got {}",
                self.stuck_ratio
            ));
        }
        Ok(())
    }
}

/// What a build did.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct DagReport {
    pub backend: Backend,
    /// Levels: the input's clusters, then one per round of simplification.
    pub levels: usize,
    /// The triangles of each level's clusters, the input first.
    pub triangles_per_level: Vec<usize>,
    pub clusters: usize,
    pub groups: usize,
    /// The groups that made the last level's clusters (1: a single root).
    pub root_groups: usize,
    /// Every level's triangles, the input's included.
    pub dag_triangles: usize,
    /// Groups that could not get under `stuck_ratio` of their triangles, whose clusters went
    /// on as they were.
    pub stuck_groups: usize,
    /// Degenerate input faces left out.
    pub dropped_degenerate_faces: usize,
    pub seconds: f64,
}

/// Builds the cluster DAG of `mesh`.
pub fn build(mesh: &Mesh, opts: &DagOptions) -> Result<(Dag, DagReport)> {
    build_with_progress(mesh, opts, &mut |_| {})
}

/// As [`build`], calling `progress` with the fraction done (by triangles; about half the DAG
/// is the input's).
pub fn build_with_progress(
    mesh: &Mesh,
    opts: &DagOptions,
    progress: &mut dyn FnMut(f32),
) -> Result<(Dag, DagReport)> {
    let t0 = std::time::Instant::now();
    opts.check()?;
    mesh.validate()?;
    let limits = Limits {
        max_triangles: opts.max_triangles,
        max_vertices: opts.max_vertices,
    };
    let (store, input) = Store::of_input(mesh);
    let input = store.drop_degenerate(input);
    let dropped = mesh.triangles.len() - input.len();
    let mut b = Builder {
        dag: Dag {
            diagonal: mesh.bounds().map_or(0.0, |b| b.diagonal()),
            ..Dag::default()
        },
        store,
        limits,
    };
    let mut pool = b.add_clusters(input, 0, NONE, None);
    let mut report = DagReport {
        backend: opts.backend,
        levels: 0,
        triangles_per_level: Vec::new(),
        clusters: 0,
        groups: 0,
        root_groups: 0,
        dag_triangles: 0,
        stuck_groups: 0,
        dropped_degenerate_faces: dropped,
        seconds: 0.0,
    };
    let expected = 2.0 * b.triangles(&pool).max(1) as f64;
    let mut done = 0usize;
    for level in 0u32.. {
        let tris = b.triangles(&pool);
        report.triangles_per_level.push(tris);
        done += tris;
        progress((done as f64 / expected).min(1.0) as f32);
        if pool.len() <= 1 {
            break;
        }
        opts.cancel.check()?;
        let (next, simplified, stuck) = b.level(&pool, level, opts)?;
        report.stuck_groups += stuck;
        if simplified == 0 || b.triangles(&next) >= tris {
            break;
        }
        pool = next;
    }
    let mut roots: Vec<u32> = pool
        .iter()
        .map(|&c| b.dag.clusters[c as usize].parent_group)
        .collect();
    roots.sort_unstable();
    roots.dedup();
    let mut dag = b.dag;
    let mut vertices = b.store.mesh;
    vertices.triangles = std::mem::take(&mut dag.mesh.triangles);
    dag.mesh = vertices;
    report.levels = report.triangles_per_level.len();
    report.clusters = dag.clusters.len();
    report.groups = dag.groups.len();
    report.root_groups = roots.len();
    report.dag_triangles = dag.mesh.triangles.len();
    report.seconds = t0.elapsed().as_secs_f64();
    progress(1.0);
    Ok((dag, report))
}

/// The DAG so far and its vertices.
struct Builder {
    dag: Dag,
    store: Store,
    limits: Limits,
}

/// One group's simplification.
struct Simplified {
    mesh: Mesh,
    /// The largest collapse error, in mesh units.
    error: f64,
    /// The result's triangles as clusters (indices into `mesh.triangles`), split where the
    /// groups are simplified: in parallel.
    parts: Vec<Vec<u32>>,
    /// Per vertex of `mesh`: the DAG vertex it is (a pinned or unmoved one of the group's
    /// input, found by its bits), or `NONE` for a new one.
    known: Vec<u32>,
}

impl Builder {
    fn triangles(&self, pool: &[u32]) -> usize {
        pool.iter()
            .map(|&c| self.dag.clusters[c as usize].triangle_count as usize)
            .sum()
    }

    /// Groups `pool`, simplifies every group, and returns the next level's clusters, how many
    /// groups were simplified and how many were stuck.
    fn level(
        &mut self,
        pool: &[u32],
        level: u32,
        opts: &DagOptions,
    ) -> Result<(Vec<u32>, usize, usize)> {
        let members: Vec<Member<'_>> = pool
            .iter()
            .map(|&c| {
                let cl = &self.dag.clusters[c as usize];
                Member {
                    triangles: self.dag.triangles(cl),
                    parent_group: cl.parent_group,
                    center: [cl.bounds[0], cl.bounds[1], cl.bounds[2]],
                }
            })
            .collect();
        let groups: Vec<Vec<u32>> = group(&members, &self.store.class, opts.group_size)
            .into_iter()
            .map(|g| g.into_iter().map(|i| pool[i as usize]).collect())
            .collect();
        let shared = self.shared_classes(&groups);
        let results: Vec<Result<Simplified>> = match opts.backend {
            Backend::Cpu => groups
                .par_iter()
                .map(|g| self.simplify_group(g, &shared, opts))
                .collect(),
            Backend::Auto => {
                let b = crate::simplify::auto_backend().0;
                match self.simplify_level(&groups, &shared, opts, b) {
                    Err(Error::Gpu(_) | Error::BufferTooLarge { .. }) if b == Backend::Gpu => {
                        self.simplify_level(&groups, &shared, opts, Backend::CpuParallel)?
                    }
                    r => r?,
                }
            }
            b => self.simplify_level(&groups, &shared, opts, b)?,
        };
        let (mut next, mut simplified, mut stuck) = (Vec::new(), 0, 0);
        for (g, r) in groups.iter().zip(results) {
            let r = r?;
            let before: usize = self.triangles(g);
            if r.mesh.triangles.len() as f64 > opts.stuck_ratio * before as f64 {
                stuck += 1;
                next.extend_from_slice(g);
                continue;
            }
            simplified += 1;
            next.extend(self.add_group(g, r, level));
        }
        Ok((next, simplified, stuck))
    }

    /// Per position class: whether faces of two of `groups` use it (the borders to pin).
    fn shared_classes(&self, groups: &[Vec<u32>]) -> Vec<bool> {
        let n = self.store.class_count();
        let (mut owner, mut shared) = (vec![u32::MAX; n], vec![false; n]);
        for (gi, g) in groups.iter().enumerate() {
            for &c in g {
                for t in self.dag.triangles(&self.dag.clusters[c as usize]) {
                    for &v in t {
                        let k = self.store.class[v as usize] as usize;
                        if owner[k] == u32::MAX {
                            owner[k] = gi as u32;
                        } else if owner[k] != gi as u32 {
                            shared[k] = true;
                        }
                    }
                }
            }
        }
        shared
    }

    /// The triangles of `groups` as one mesh over the DAG vertices they use (`ids`, in order
    /// of first use), each face's group in `face_groups`, the vertices on the borders between
    /// groups (`shared` classes) pinned.
    fn input_of(
        &self,
        groups: &[&[u32]],
        shared: &[bool],
        opts: &DagOptions,
    ) -> (Mesh, Vec<u32>, Vec<u32>) {
        let mut local = Local::default();
        let mut tris: Vec<[u32; 3]> = Vec::new();
        let mut face_groups: Vec<u32> = Vec::new();
        for (gi, g) in groups.iter().enumerate() {
            for &c in *g {
                for t in self.dag.triangles(&self.dag.clusters[c as usize]) {
                    tris.push(t.map(|v| local.id(v)));
                    face_groups.push(gi as u32);
                }
            }
        }
        let ids = local.ids;
        let mut sub = submesh(&self.store.mesh, &ids, tris);
        sub.face_groups = Some(face_groups);
        sub.groups = (0..groups.len()).map(|g| format!("group {g}")).collect();
        if opts.attributes.normal == 0.0 {
            // Normals out of the cost are made again from each result's faces, and differ
            // where two groups meet: carried in, they would be seams the next level's
            // simplification keeps whole (the horse's root stalled at 1,756 triangles).
            sub.normals = None;
        }
        let pin: Vec<u32> = (0..ids.len() as u32)
            .filter(|&l| shared[self.store.class[ids[l as usize] as usize] as usize])
            .collect();
        (sub, ids, pin)
    }

    /// The group's triangles as a mesh of their own, the shared border pinned, simplified to
    /// half.
    fn simplify_group(&self, g: &[u32], shared: &[bool], opts: &DagOptions) -> Result<Simplified> {
        let (mut sub, ids, pin) = self.input_of(&[g], shared, opts);
        sub.face_groups = None;
        sub.groups = Vec::new();
        let target = sub.triangles.len() / 2;
        let so = SimplifyOptions {
            backend: opts.backend,
            pin,
            attributes: opts.attributes,
            cancel: opts.cancel.clone(),
            ..SimplifyOptions::with_faces(target)
        };
        let diagonal = sub.bounds().map_or(0.0, |b| b.diagonal());
        let (mesh, r) = crate::simplify(&sub, &so)?;
        Ok(self.finish(&ids, mesh, r.max_collapse_error * diagonal))
    }

    /// Every group of a level simplified to half in one run of the rounds on `backend`, each
    /// group to its own target; the result cut back into the groups.
    fn simplify_level(
        &self,
        groups: &[Vec<u32>],
        shared: &[bool],
        opts: &DagOptions,
        backend: Backend,
    ) -> Result<Vec<Result<Simplified>>> {
        let refs: Vec<&[u32]> = groups.iter().map(|g| g.as_slice()).collect();
        let (sub, ids, pin) = self.input_of(&refs, shared, opts);
        let targets: Vec<u32> = groups
            .iter()
            .map(|g| (self.triangles(g) / 2) as u32)
            .collect();
        let sum = targets.iter().map(|&t| t as usize).sum();
        let so = SimplifyOptions {
            backend,
            pin,
            attributes: opts.attributes,
            cancel: opts.cancel.clone(),
            ..SimplifyOptions::with_faces(sum)
        };
        let (mesh, errors) = crate::rounds::simplify_grouped(&sub, targets, backend, &so)?;
        let parts = split_groups(&mesh, groups.len());
        // Each group's own input vertices, as DAG ids, for `finish`'s look-up of the kept ones.
        let mut group_ids: Vec<Vec<u32>> = vec![Vec::new(); groups.len()];
        let fg = sub.face_groups.as_ref().expect("input_of sets them");
        let mut seen = vec![u32::MAX; ids.len()];
        for (t, &g) in sub.triangles.iter().zip(fg) {
            for &l in t {
                if seen[l as usize] != g {
                    seen[l as usize] = g;
                    group_ids[g as usize].push(ids[l as usize]);
                }
            }
        }
        Ok(parts
            .into_par_iter()
            .zip(group_ids)
            .zip(errors)
            .map(|((m, gids), e)| Ok(self.finish(&gids, m, e)))
            .collect())
    }

    /// A group's simplified `mesh` (in mesh units, its largest collapse `error`) split into
    /// clusters, each of its vertices matched to one of the group's input vertices `ids` (DAG
    /// vertices) where its bits are theirs.
    fn finish(&self, ids: &[u32], mut mesh: Mesh, error: f64) -> Simplified {
        if self.store.mesh.normals.is_some() && mesh.normals.is_none() {
            mesh.recompute_normals();
        }
        let class = local_classes(&mesh.positions);
        let c = |v: u32| class[v as usize];
        mesh.triangles
            .retain(|t| c(t[0]) != c(t[1]) && c(t[1]) != c(t[2]) && c(t[0]) != c(t[2]));
        let parts = split(&mesh.triangles, &mesh.positions, &class, self.limits);
        // Not the normal: a pinned vertex keeps its place and appearance but gets a normal made
        // again.
        let mut by_bits: FxHashMap<[u32; 12], u32> = FxHashMap::default();
        for &g in ids {
            by_bits.insert(vertex_bits(&self.store.mesh, g as usize, false), g);
        }
        let known = (0..mesh.positions.len())
            .map(|v| {
                by_bits
                    .get(&vertex_bits(&mesh, v, false))
                    .copied()
                    .unwrap_or(NONE)
            })
            .collect();
        Simplified {
            mesh,
            error,
            parts,
            known,
        }
    }

    /// Records group `g` simplified into `r`: the group, and the clusters of its result.
    fn add_group(&mut self, g: &[u32], r: Simplified, level: u32) -> Vec<u32> {
        let gid = self.dag.groups.len() as u32;
        let mut error = r.error;
        let mut spheres = Vec::with_capacity(g.len());
        for &c in g {
            let cl = &mut self.dag.clusters[c as usize];
            cl.group = gid;
            error = error.max(cl.error as f64);
            spheres.push(cl.lod_sphere);
        }
        let group = Group {
            depth: level,
            sphere: sphere_around(&spheres, &r.mesh.positions),
            error: round_up(error),
        };
        self.dag.groups.push(group);
        let ids = self.store.add_new(&r.mesh, &r.known);
        let tris: Vec<[u32; 3]> = r
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| ids[v as usize]))
            .collect();
        let lod = Some((group.sphere, group.error));
        self.add_parts(&tris, r.parts, level + 1, gid, lod)
    }

    /// `tris` split into clusters at `depth`, made by `parent` with its sphere and error
    /// (`None`: the input's, their own bounds and no error); their ids.
    fn add_clusters(
        &mut self,
        tris: Vec<[u32; 3]>,
        depth: u32,
        parent: u32,
        lod: Option<([f32; 4], f32)>,
    ) -> Vec<u32> {
        let parts = split(
            &tris,
            &self.store.mesh.positions,
            &self.store.class,
            self.limits,
        );
        self.add_parts(&tris, parts, depth, parent, lod)
    }

    /// As [`Builder::add_clusters`], the split into `parts` made.
    fn add_parts(
        &mut self,
        tris: &[[u32; 3]],
        parts: Vec<Vec<u32>>,
        depth: u32,
        parent: u32,
        lod: Option<([f32; 4], f32)>,
    ) -> Vec<u32> {
        let mut ids = Vec::with_capacity(parts.len());
        for part in parts {
            let first = self.dag.mesh.triangles.len() as u32;
            self.dag
                .mesh
                .triangles
                .extend(part.iter().map(|&f| tris[f as usize]));
            let pos = &self.store.mesh.positions;
            let own = &self.dag.mesh.triangles[first as usize..];
            let bounds = sphere_of_points(own.iter().flatten().map(|&v| pos[v as usize]));
            let (lod_sphere, error) = lod.unwrap_or((bounds, 0.0));
            ids.push(self.dag.clusters.len() as u32);
            self.dag.clusters.push(Cluster {
                first_triangle: first,
                triangle_count: part.len() as u32,
                depth,
                group: NONE,
                parent_group: parent,
                bounds,
                lod_sphere,
                error,
            });
        }
        ids
    }
}

/// The DAG's vertices and their position classes.
struct Store {
    mesh: Mesh,
    /// Per vertex: its position class.
    class: Vec<u32>,
    /// Per position (bits): its class. A vertex that comes back with other attributes (the
    /// normals a simplification made again on a pinned border) is a new vertex of the old
    /// class, or the groups it borders would no longer meet there.
    by_position: FxHashMap<[u32; 3], u32>,
}

impl Store {
    /// The input, welded (equal position and attributes) and without unused vertices, as the
    /// first vertices; its triangles over them.
    fn of_input(input: &Mesh) -> (Store, Vec<[u32; 3]>) {
        let mut mesh = crate::mesh::weld(input).mesh;
        mesh.remove_unused_vertices();
        mesh.face_materials = None;
        mesh.face_groups = None;
        let tris = std::mem::take(&mut mesh.triangles);
        let (class, _) = crate::mesh::weld::position_classes(&mesh.positions);
        let by_position = mesh
            .positions
            .iter()
            .zip(&class)
            .map(|(p, &c)| (p.map(bits), c))
            .collect();
        let store = Store {
            mesh,
            class,
            by_position,
        };
        (store, tris)
    }

    fn class_count(&self) -> usize {
        self.by_position.len()
    }

    /// The ids of `m`'s vertices: `known[v]` where it is one, else a new vertex for each vertex
    /// the faces use.
    fn add_new(&mut self, m: &Mesh, known: &[u32]) -> Vec<u32> {
        let mut used = vec![false; m.positions.len()];
        for &v in m.triangles.as_flattened() {
            used[v as usize] = true;
        }
        (0..m.positions.len())
            .map(|v| match (known[v], used[v]) {
                (NONE, true) => self.push(m, v),
                (k, _) => k,
            })
            .collect()
    }

    fn push(&mut self, m: &Mesh, v: usize) -> u32 {
        let id = self.mesh.positions.len() as u32;
        let next = self.by_position.len() as u32;
        let class = *self
            .by_position
            .entry(m.positions[v].map(bits))
            .or_insert(next);
        self.class.push(class);
        self.mesh.positions.push(m.positions[v]);
        if let Some(n) = &mut self.mesh.normals {
            n.push(m.normals.as_ref().map_or([0.0; 3], |s| s[v]));
        }
        if let Some(t) = &mut self.mesh.uvs {
            t.push(m.uvs.as_ref().map_or([0.0; 2], |s| s[v]));
        }
        if let Some(c) = &mut self.mesh.colors {
            c.push(m.colors.as_ref().map_or([1.0; 4], |s| s[v]));
        }
        id
    }

    /// `tris` without those that use a position twice.
    fn drop_degenerate(&self, tris: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
        let c = |v: u32| self.class[v as usize];
        tris.into_iter()
            .filter(|t| c(t[0]) != c(t[1]) && c(t[1]) != c(t[2]) && c(t[0]) != c(t[2]))
            .collect()
    }
}

/// `mesh`'s faces split by their group (`face_groups`, below `n`), each group a mesh of the
/// vertices its faces use, in order of first use.
fn split_groups(mesh: &Mesh, n: usize) -> Vec<Mesh> {
    let fg = mesh
        .face_groups
        .as_ref()
        .expect("grouped rounds keep the faces' groups");
    let mut tris: Vec<Vec<[u32; 3]>> = vec![Vec::new(); n];
    for (t, &g) in mesh.triangles.iter().zip(fg) {
        tris[g as usize].push(*t);
    }
    tris.into_par_iter()
        .map(|tris| {
            let mut local = Local::default();
            let triangles = tris.iter().map(|t| t.map(|v| local.id(v))).collect();
            submesh(mesh, &local.ids, triangles)
        })
        .collect()
}

/// Vertices renumbered in order of first use.
#[derive(Default)]
struct Local {
    of: FxHashMap<u32, u32>,
    /// Per new id: the vertex it was.
    ids: Vec<u32>,
}

impl Local {
    fn id(&mut self, v: u32) -> u32 {
        *self.of.entry(v).or_insert_with(|| {
            self.ids.push(v);
            self.ids.len() as u32 - 1
        })
    }
}

/// The vertices `ids` of `m` (in that order) and `tris` over them, without face materials or
/// groups.
fn submesh(m: &Mesh, ids: &[u32], tris: Vec<[u32; 3]>) -> Mesh {
    fn pick<T: Copy>(ids: &[u32], s: &[T]) -> Vec<T> {
        ids.iter().map(|&v| s[v as usize]).collect()
    }
    Mesh {
        positions: pick(ids, &m.positions),
        triangles: tris,
        normals: m.normals.as_deref().map(|s| pick(ids, s)),
        uvs: m.uvs.as_deref().map(|s| pick(ids, s)),
        colors: m.colors.as_deref().map(|s| pick(ids, s)),
        face_groups: None,
        face_materials: None,
        groups: Vec::new(),
        ..m.clone_without_geometry()
    }
}

/// Per vertex: a class id shared by the vertices at its position.
fn local_classes(positions: &[[f32; 3]]) -> Vec<u32> {
    let mut by: FxHashMap<[u32; 3], u32> = FxHashMap::default();
    positions
        .iter()
        .map(|p| {
            let n = by.len() as u32;
            *by.entry(p.map(bits)).or_insert(n)
        })
        .collect()
}
