//! meshslim for Python: the core library behind PyO3 and numpy (the pure-Python package in
//! python/meshslim wraps this module, `meshslim._meshslim`, with the documented API). Arrays come
//! in as C-contiguous float32 / uint32 (the wrapper converts), are checked here with errors that
//! name the argument and the first offending row, and every library error becomes a Python
//! exception: `ValueError` for bad input or options, `OSError` for files, `KeyboardInterrupt` for
//! a cancelled run, `RuntimeError` for the GPU or a bug. A panic is caught at the boundary and
//! raised as `RuntimeError`, never an abort. Simplifying releases the GIL.

use meshslim::options::AttributeWeights;
use meshslim::{Backend, Error, Method, SimplifyOptions};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyReadonlyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A library error as the Python exception a user expects.
fn raise(e: Error) -> PyErr {
    let msg = e.to_string();
    match e {
        Error::Io { .. } => PyOSError::new_err(msg),
        Error::Cancelled => PyKeyboardInterrupt::new_err("cancelled"),
        Error::Gpu(_) | Error::BufferTooLarge { .. } | Error::Internal(_) => {
            PyRuntimeError::new_err(msg)
        }
        _ => PyValueError::new_err(msg),
    }
}

/// Runs `f`, turning a panic into `RuntimeError` (a bug in meshslim, reported, not an abort).
fn guarded<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| p.downcast_ref::<&str>().copied())
            .unwrap_or("a panic");
        Err(PyRuntimeError::new_err(format!(
            "internal error in meshslim (please report it): {what}"
        )))
    })
}

/// A triangle mesh: positions, faces and the per-vertex attributes it has.
#[pyclass(name = "Mesh", module = "meshslim", frozen)]
struct PyMesh {
    inner: meshslim::Mesh,
}

/// `(n, k)` rows of an array the wrapper made C-contiguous, checked for its shape.
fn rows<const K: usize, T: numpy::Element + Copy>(
    name: &str,
    a: &PyReadonlyArray2<T>,
) -> PyResult<Vec<[T; K]>> {
    let shape = a.shape();
    if shape[1] != K {
        return Err(PyValueError::new_err(format!(
            "{name}: expected an (n, {K}) array, got shape ({}, {})",
            shape[0], shape[1]
        )));
    }
    let flat = a
        .as_slice()
        .map_err(|_| PyValueError::new_err(format!("{name}: not a contiguous array")))?;
    Ok(flat
        .chunks_exact(K)
        .map(|c| std::array::from_fn(|k| c[k]))
        .collect())
}

/// The first row of `values` with a component that is not finite, as an error naming `name`.
fn finite<const K: usize>(name: &str, values: &[[f32; K]]) -> PyResult<()> {
    match values.iter().position(|r| r.iter().any(|x| !x.is_finite())) {
        Some(i) => Err(PyValueError::new_err(format!(
            "{name}: row {i} is not finite: {:?}",
            values[i]
        ))),
        None => Ok(()),
    }
}

/// An optional per-vertex attribute: `n` rows of `K` (or, for colours, 3 or 4) values.
fn per_vertex<const K: usize>(
    name: &str,
    a: Option<PyReadonlyArray2<f32>>,
    n: usize,
) -> PyResult<Option<Vec<[f32; K]>>> {
    let Some(a) = a else { return Ok(None) };
    let v = rows::<K, f32>(name, &a)?;
    if v.len() != n {
        return Err(PyValueError::new_err(format!(
            "{name}: {} rows for {n} vertices",
            v.len()
        )));
    }
    finite(name, &v)?;
    Ok(Some(v))
}

#[pymethods]
impl PyMesh {
    #[new]
    #[pyo3(signature = (vertices, faces, *, normals=None, uvs=None, colors=None))]
    fn new(
        vertices: PyReadonlyArray2<f32>,
        faces: PyReadonlyArray2<u32>,
        normals: Option<PyReadonlyArray2<f32>>,
        uvs: Option<PyReadonlyArray2<f32>>,
        colors: Option<PyReadonlyArray2<f32>>,
    ) -> PyResult<PyMesh> {
        let positions = rows::<3, f32>("vertices", &vertices)?;
        finite("vertices", &positions)?;
        let triangles = rows::<3, u32>("faces", &faces)?;
        let n = positions.len();
        if let Some(i) = triangles
            .iter()
            .position(|t| t.iter().any(|&v| v as usize >= n))
        {
            return Err(PyValueError::new_err(format!(
                "faces: row {i} {:?} names a vertex out of range (there are {n})",
                triangles[i]
            )));
        }
        let colors = match colors {
            None => None,
            Some(c) if c.shape()[1] == 3 => per_vertex::<3>("colors", Some(c), n)?
                .map(|v| v.into_iter().map(|[r, g, b]| [r, g, b, 1.0]).collect()),
            Some(c) => per_vertex::<4>("colors", Some(c), n)?,
        };
        if let Some(c) = &colors
            && let Some(i) = c
                .iter()
                .position(|c| c.iter().any(|x| !(0.0..=1.0).contains(x)))
        {
            return Err(PyValueError::new_err(format!(
                "colors: row {i} is outside 0..1: {:?}",
                c[i]
            )));
        }
        let inner = meshslim::Mesh {
            normals: per_vertex::<3>("normals", normals, n)?,
            uvs: per_vertex::<2>("uvs", uvs, n)?,
            colors,
            ..meshslim::Mesh::new(positions, triangles)
        };
        inner.validate().map_err(raise)?;
        Ok(PyMesh { inner })
    }

    /// Positions, `(n, 3)` float32.
    #[getter]
    fn vertices<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f32>> {
        array(py, &self.inner.positions)
    }

    /// Triangles, `(m, 3)` uint32 vertex indices.
    #[getter]
    fn faces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<u32>> {
        array(py, &self.inner.triangles)
    }

    /// Per-vertex normals, `(n, 3)` float32, or None.
    #[getter]
    fn normals<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f32>>> {
        self.inner.normals.as_ref().map(|v| array(py, v))
    }

    /// Per-vertex texture coordinates, `(n, 2)` float32, or None.
    #[getter]
    fn uvs<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f32>>> {
        self.inner.uvs.as_ref().map(|v| array(py, v))
    }

    /// Per-vertex colours, `(n, 4)` float32 RGBA in 0..1, or None.
    #[getter]
    fn colors<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray2<f32>>> {
        self.inner.colors.as_ref().map(|v| array(py, v))
    }

    fn __repr__(&self) -> String {
        let m = &self.inner;
        let mut extra = Vec::new();
        for (has, name) in [
            (m.normals.is_some(), "normals"),
            (m.uvs.is_some(), "uvs"),
            (m.colors.is_some(), "colors"),
        ] {
            if has {
                extra.push(name);
            }
        }
        let extra = if extra.is_empty() {
            String::new()
        } else {
            format!(", with {}", extra.join(", "))
        };
        format!(
            "meshslim.Mesh({} vertices, {} faces{extra})",
            m.positions.len(),
            m.triangles.len()
        )
    }
}

/// `rows` as an `(n, K)` numpy array (a copy the array owns).
fn array<'py, T: numpy::Element + Copy, const K: usize>(
    py: Python<'py>,
    rows: &[[T; K]],
) -> Bound<'py, PyArray2<T>> {
    let flat: Vec<T> = rows.iter().flatten().copied().collect();
    Array2::from_shape_vec((rows.len(), K), flat)
        .expect("rows × K values")
        .into_pyarray(py)
}

/// Reads a mesh file (OBJ, PLY, STL, glTF/GLB).
#[pyfunction]
fn read(py: Python<'_>, path: std::path::PathBuf) -> PyResult<PyMesh> {
    guarded(|| {
        let inner = py.detach(|| meshslim::io::read(&path)).map_err(raise)?;
        Ok(PyMesh { inner })
    })
}

/// Writes a mesh file, its format from the extension.
#[pyfunction]
fn write(py: Python<'_>, path: std::path::PathBuf, mesh: &PyMesh) -> PyResult<()> {
    guarded(|| {
        py.detach(|| meshslim::io::write(&path, &mesh.inner))
            .map_err(raise)
    })
}

/// A name from `names` (as the command line spells it).
fn pick<T: Copy>(what: &str, name: &str, all: &[T], of: impl Fn(T) -> &'static str) -> PyResult<T> {
    all.iter().copied().find(|&x| of(x) == name).ok_or_else(|| {
        let names: Vec<&str> = all.iter().map(|&x| of(x)).collect();
        PyValueError::new_err(format!(
            "{what}: unknown {name:?} (one of {})",
            names.join(", ")
        ))
    })
}

/// Method, backend, border and appearance weights (`None`: the default) into `opts`.
fn configure(
    opts: &mut SimplifyOptions,
    method: &str,
    backend: &str,
    lock_border: bool,
    (color, uv, normal): (Option<f64>, Option<f64>, Option<f64>),
) -> PyResult<()> {
    opts.lock_border = lock_border;
    opts.method = pick(
        "method",
        method,
        &[
            Method::Qem,
            Method::Cluster,
            Method::FloatingCell,
            Method::Hybrid,
            Method::Decimate,
        ],
        Method::name,
    )?;
    opts.backend = pick(
        "backend",
        backend,
        &[
            Backend::Cpu,
            Backend::CpuParallel,
            Backend::Gpu,
            Backend::Auto,
        ],
        Backend::name,
    )?;
    let d = AttributeWeights::default();
    opts.attributes = AttributeWeights {
        color: color.unwrap_or(d.color),
        uv: uv.unwrap_or(d.uv),
        normal: normal.unwrap_or(d.normal),
    };
    Ok(())
}

/// Runs `work` without the GIL, with progress and Ctrl+C: the library calls back from its own
/// thread; each call takes the GIL briefly, reports to `progress`, and checks for a pending
/// signal. A signal (KeyboardInterrupt) or an exception from the callback cancels the run
/// through `opts.cancel` and is raised once it has stopped.
fn detached<T: Send>(
    py: Python<'_>,
    opts: &SimplifyOptions,
    progress: Option<Py<PyAny>>,
    work: impl FnOnce(&SimplifyOptions, &mut dyn FnMut(f32)) -> meshslim::Result<T> + Send,
) -> PyResult<T> {
    let cancel = opts.cancel.clone();
    let mut stopped: Option<PyErr> = None;
    let mut report_progress = |f: f32| {
        if stopped.is_some() {
            return;
        }
        Python::attach(|py| {
            // The driver's fraction can pass 1 by a face's worth (a round lands one below its
            // target); callers get 0..=1.
            let f = f.clamp(0.0, 1.0);
            let called = py.check_signals().and_then(|()| match &progress {
                Some(cb) => cb.call1(py, (f,)).map(drop),
                None => Ok(()),
            });
            if let Err(e) = called {
                stopped = Some(e);
                cancel.cancel();
            }
        })
    };
    let result = py.detach(|| work(opts, &mut report_progress));
    if let Some(e) = stopped {
        return Err(e);
    }
    result.map_err(raise)
}

/// Simplifies `mesh`; returns the result and the report as JSON (the wrapper makes it a dict).
#[pyfunction]
#[pyo3(signature = (mesh, *, ratio=None, target_faces=None, max_error=None, method="qem",
    backend="cpu", lock_border=false, color_weight=None, uv_weight=None, normal_weight=None,
    progress=None))]
#[allow(clippy::too_many_arguments)]
fn simplify(
    py: Python<'_>,
    mesh: &PyMesh,
    ratio: Option<f64>,
    target_faces: Option<usize>,
    max_error: Option<f64>,
    method: &str,
    backend: &str,
    lock_border: bool,
    color_weight: Option<f64>,
    uv_weight: Option<f64>,
    normal_weight: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(PyMesh, String)> {
    guarded(|| {
        let m = &mesh.inner;
        let mut opts = match (ratio, target_faces) {
            (Some(_), Some(_)) => {
                return Err(PyValueError::new_err(
                    "give ratio or target_faces, not both",
                ));
            }
            (None, Some(n)) => SimplifyOptions::with_faces(n),
            (r, None) => {
                SimplifyOptions::with_ratio(m.face_count(), r.unwrap_or(0.1)).map_err(raise)?
            }
        };
        opts.max_error = max_error;
        let weights = (color_weight, uv_weight, normal_weight);
        configure(&mut opts, method, backend, lock_border, weights)?;
        let (out, report) = detached(py, &opts, progress, |opts, p| {
            meshslim::simplify_with_progress(m, opts, p)
        })?;
        let json = serde_json::to_string(&report)
            .map_err(|e| PyRuntimeError::new_err(format!("the report: {e}")))?;
        Ok((PyMesh { inner: out }, json))
    })
}

/// Levels of detail of `mesh` at falling `ratios`, in one run (each level goes on from the one
/// before); returns each level's mesh and its facts as JSON, and the backend that ran them.
#[pyfunction]
#[pyo3(signature = (mesh, ratios, *, method="qem", backend="cpu", lock_border=false,
    color_weight=None, uv_weight=None, normal_weight=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn lods(
    py: Python<'_>,
    mesh: &PyMesh,
    ratios: Vec<f64>,
    method: &str,
    backend: &str,
    lock_border: bool,
    color_weight: Option<f64>,
    uv_weight: Option<f64>,
    normal_weight: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(Vec<(PyMesh, String)>, String)> {
    guarded(|| {
        let m = &mesh.inner;
        let mut opts = SimplifyOptions::with_faces(0);
        let weights = (color_weight, uv_weight, normal_weight);
        configure(&mut opts, method, backend, lock_border, weights)?;
        let (levels, ran) = detached(py, &opts, progress, |opts, p| {
            meshslim::lod::lod_chain(m, opts, &ratios, p)
        })?;
        let levels = levels
            .into_iter()
            .map(|l| {
                let facts = serde_json::json!({
                    "ratio": l.ratio,
                    "target_faces": l.target_faces,
                    "output_faces": l.mesh.triangles.len(),
                    "stop_reason": l.stop_reason,
                    "max_error": l.max_error,
                    "seconds": l.seconds,
                });
                (PyMesh { inner: l.mesh }, facts.to_string())
            })
            .collect();
        Ok((levels, ran.name().to_string()))
    })
}

/// Isotropic remeshing (Botsch & Kobbelt 2004): near-equilateral triangles at one edge length
/// (`edge_factor` × the mean edge, an `edge_length`, or the length that gives `target_faces`),
/// creases over `feature_angle` degrees kept; returns the mesh and the report as JSON.
#[pyfunction]
#[pyo3(signature = (mesh, *, edge_factor=None, edge_length=None, target_faces=None,
    iterations=5, feature_angle=45.0, lock_border=false))]
#[allow(clippy::too_many_arguments)]
fn remesh(
    py: Python<'_>,
    mesh: &PyMesh,
    edge_factor: Option<f64>,
    edge_length: Option<f64>,
    target_faces: Option<usize>,
    iterations: usize,
    feature_angle: f64,
    lock_border: bool,
) -> PyResult<(PyMesh, String)> {
    use meshslim::remesh::{EdgeTarget, RemeshOptions};
    guarded(|| {
        let target = match (edge_factor, edge_length, target_faces) {
            (None, None, None) => EdgeTarget::MeanEdge,
            (Some(f), None, None) => EdgeTarget::MeanEdgeTimes(f),
            (None, Some(l), None) => EdgeTarget::Length(l),
            (None, None, Some(n)) => EdgeTarget::Faces(n),
            _ => {
                return Err(PyValueError::new_err(
                    "give one of edge_factor, edge_length and target_faces",
                ));
            }
        };
        let opts = RemeshOptions {
            target,
            iterations,
            feature_angle_deg: feature_angle,
            lock_border,
            ..Default::default()
        };
        let (out, report) = py
            .detach(|| meshslim::remesh::remesh(&mesh.inner, &opts))
            .map_err(raise)?;
        let json = serde_json::to_string(&report)
            .map_err(|e| PyRuntimeError::new_err(format!("the report: {e}")))?;
        Ok((PyMesh { inner: out }, json))
    })
}

/// Compares two meshes (two-sided Metro distance, appearance, area, volume, quality,
/// topology); returns the comparison as JSON (the wrapper makes it a dict).
#[pyfunction]
#[pyo3(signature = (a, b, *, samples=None, seed=None))]
fn compare(
    py: Python<'_>,
    a: &PyMesh,
    b: &PyMesh,
    samples: Option<usize>,
    seed: Option<u64>,
) -> PyResult<String> {
    guarded(|| {
        let d = meshslim::metrics::CompareOptions::default();
        let opts = meshslim::metrics::CompareOptions {
            samples,
            seed: seed.unwrap_or(d.seed),
            ..d
        };
        let c = py
            .detach(|| meshslim::metrics::compare(&a.inner, &b.inner, &opts))
            .map_err(raise)?;
        serde_json::to_string(&c)
            .map_err(|e| PyRuntimeError::new_err(format!("the comparison: {e}")))
    })
}

/// A cluster DAG (Karis 2021; `meshslim dag build`): every level's triangles over one set of
/// vertices, the clusters (meshlets) that index them, and the groups that join them.
#[pyclass(name = "Dag", module = "meshslim", frozen)]
struct PyDag {
    inner: meshslim::dag::Dag,
}

/// Per item of `items`, `f` of it, as a 1-D numpy array.
fn column<'py, I, T: numpy::Element>(
    py: Python<'py>,
    items: &[I],
    f: impl Fn(&I) -> T,
) -> Bound<'py, PyArray1<T>> {
    items.iter().map(f).collect::<Vec<T>>().into_pyarray(py)
}

#[pymethods]
impl PyDag {
    /// The vertices and, cluster after cluster, the triangles of every level.
    #[getter]
    fn mesh(&self) -> PyMesh {
        PyMesh {
            inner: self.inner.mesh.clone(),
        }
    }

    /// The input's bounding-box diagonal (object-space errors are fractions of it).
    #[getter]
    fn diagonal(&self) -> f64 {
        self.inner.diagonal
    }

    /// The clusters as arrays, one entry per cluster: `first_triangle`, `triangle_count`,
    /// `depth`, `group` (the group that simplifies it, 2**32-1 for a root), `parent_group` (the
    /// group that made it, 2**32-1 at depth 0) as uint32; `bounds` and `lod_sphere` (k, 4)
    /// float32 (centre, radius); `error` float32, in mesh units.
    fn clusters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let c = &self.inner.clusters;
        let d = PyDict::new(py);
        d.set_item("first_triangle", column(py, c, |c| c.first_triangle))?;
        d.set_item("triangle_count", column(py, c, |c| c.triangle_count))?;
        d.set_item("depth", column(py, c, |c| c.depth))?;
        d.set_item("group", column(py, c, |c| c.group))?;
        d.set_item("parent_group", column(py, c, |c| c.parent_group))?;
        let bounds: Vec<[f32; 4]> = c.iter().map(|c| c.bounds).collect();
        d.set_item("bounds", array(py, &bounds))?;
        let lod: Vec<[f32; 4]> = c.iter().map(|c| c.lod_sphere).collect();
        d.set_item("lod_sphere", array(py, &lod))?;
        d.set_item("error", column(py, c, |c| c.error))?;
        Ok(d)
    }

    /// The groups as arrays, one entry per group: `depth` uint32 (of the clusters it
    /// simplifies), `sphere` (g, 4) float32, `error` float32 in mesh units.
    fn groups<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let g = &self.inner.groups;
        let d = PyDict::new(py);
        d.set_item("depth", column(py, g, |g| g.depth))?;
        let spheres: Vec<[f32; 4]> = g.iter().map(|g| g.sphere).collect();
        d.set_item("sphere", array(py, &spheres))?;
        d.set_item("error", column(py, g, |g| g.error))?;
        Ok(d)
    }

    /// The clusters of one cut and, for an object-space one, its threshold (of the diagonal):
    /// see the wrapper's `Dag.cut`.
    #[pyo3(signature = (*, error=None, triangles=None, camera=None, pixels=None, fov=60.0,
        height=1080.0))]
    #[allow(clippy::too_many_arguments)]
    fn cut_clusters<'py>(
        &self,
        py: Python<'py>,
        error: Option<f64>,
        triangles: Option<usize>,
        camera: Option<[f64; 3]>,
        pixels: Option<f64>,
        fov: f64,
        height: f64,
    ) -> PyResult<(Bound<'py, PyArray1<u32>>, Option<f64>)> {
        guarded(|| {
            let dag = &self.inner;
            let diagonal = dag.diagonal.max(f64::MIN_POSITIVE);
            let (ids, threshold) = match (error, triangles, camera, pixels) {
                (Some(e), None, None, None) => {
                    if !(e >= 0.0 && e.is_finite()) {
                        return Err(PyValueError::new_err(format!(
                            "error: must be a finite number, 0 or more, got {e}"
                        )));
                    }
                    (dag.cut_at_error(e * dag.diagonal), Some(e))
                }
                (None, Some(n), None, None) => {
                    let (ids, t) = py.detach(|| dag.cut_to_triangles(n));
                    (ids, Some(t / diagonal))
                }
                (None, None, Some(eye), Some(pixels)) => {
                    let cam = meshslim::dag::CameraCut {
                        eye,
                        pixels,
                        fov_deg: fov,
                        height,
                    };
                    cam.check().map_err(raise)?;
                    (dag.cut_from_camera(&cam), None)
                }
                _ => {
                    return Err(PyValueError::new_err(
                        "give one of error=E, triangles=N, or camera=(x, y, z) with pixels=P",
                    ));
                }
            };
            Ok((ids.into_pyarray(py), threshold))
        })
    }

    /// The mesh of the clusters `ids` (from `cut_clusters`): their triangles, the vertices
    /// they use.
    fn mesh_of(&self, ids: Vec<u32>) -> PyResult<PyMesh> {
        let n = self.inner.clusters.len();
        if let Some(i) = ids.iter().position(|&c| c as usize >= n) {
            return Err(PyValueError::new_err(format!(
                "ids: entry {i} is {} but there are {n} clusters",
                ids[i]
            )));
        }
        Ok(PyMesh {
            inner: self.inner.mesh_of(&ids),
        })
    }

    /// Writes the DAG as a .mslod file (docs/MSLOD.md).
    fn write(&self, py: Python<'_>, path: std::path::PathBuf) -> PyResult<()> {
        guarded(|| {
            py.detach(|| meshslim::dag::file::write(&path, &self.inner))
                .map_err(raise)
        })
    }

    fn __repr__(&self) -> String {
        let d = &self.inner;
        format!(
            "meshslim.Dag({} levels, {} clusters, {} groups, {} triangles)",
            d.levels(),
            d.clusters.len(),
            d.groups.len(),
            d.mesh.triangles.len()
        )
    }
}

/// Builds the cluster DAG of `mesh`; returns it and the report as JSON.
#[pyfunction]
#[pyo3(signature = (mesh, *, backend="cpu", cluster_triangles=128, cluster_vertices=255,
    group_size=16, color_weight=None, uv_weight=None, normal_weight=None, progress=None))]
#[allow(clippy::too_many_arguments)]
fn dag_build(
    py: Python<'_>,
    mesh: &PyMesh,
    backend: &str,
    cluster_triangles: usize,
    cluster_vertices: usize,
    group_size: usize,
    color_weight: Option<f64>,
    uv_weight: Option<f64>,
    normal_weight: Option<f64>,
    progress: Option<Py<PyAny>>,
) -> PyResult<(PyDag, String)> {
    guarded(|| {
        let mut opts = SimplifyOptions::with_faces(0);
        let weights = (color_weight, uv_weight, normal_weight);
        configure(&mut opts, "qem", backend, false, weights)?;
        let dag_opts = meshslim::dag::DagOptions {
            max_triangles: cluster_triangles,
            max_vertices: cluster_vertices,
            group_size,
            backend: opts.backend,
            attributes: opts.attributes,
            cancel: opts.cancel.clone(),
            ..Default::default()
        };
        let m = &mesh.inner;
        let (dag, report) = detached(py, &opts, progress, |_, p| {
            meshslim::dag::build_with_progress(m, &dag_opts, p)
        })?;
        let json = serde_json::to_string(&report)
            .map_err(|e| PyRuntimeError::new_err(format!("the report: {e}")))?;
        Ok((PyDag { inner: dag }, json))
    })
}

/// Reads a .mslod file.
#[pyfunction]
fn read_dag(py: Python<'_>, path: std::path::PathBuf) -> PyResult<PyDag> {
    guarded(|| {
        let inner = py
            .detach(|| meshslim::dag::file::read(&path))
            .map_err(raise)?;
        Ok(PyDag { inner })
    })
}

#[pymodule]
fn _meshslim(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyMesh>()?;
    m.add_class::<PyDag>()?;
    m.add_function(wrap_pyfunction!(dag_build, m)?)?;
    m.add_function(wrap_pyfunction!(read_dag, m)?)?;
    m.add_function(wrap_pyfunction!(read, m)?)?;
    m.add_function(wrap_pyfunction!(write, m)?)?;
    m.add_function(wrap_pyfunction!(simplify, m)?)?;
    m.add_function(wrap_pyfunction!(compare, m)?)?;
    m.add_function(wrap_pyfunction!(lods, m)?)?;
    m.add_function(wrap_pyfunction!(remesh, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
