//! What the viewer shows, made off the UI thread: a loaded model (the mesh, the rounds' upload,
//! a BVH for distances, its texture), the original and simplified [`SceneMesh`]es, and levels of
//! detail. Nothing here touches egui; the window (`app.rs`) and the tests drive it alike.

use super::camera::Up;
use super::corners::{corner_colors, corner_uvs};
use super::front::Front;
use super::render::{Extras, SceneMesh, vertex_normals};
use crate::error::{Error, Result};
use crate::lod::manifest::{self, ManifestKind};
use crate::mesh::{Mesh, UvOrigin};
use crate::metrics::{CompareOptions, TriangleBvh, compare};
use crate::options::{Backend, SimplifyOptions, SimplifyReport};
use crate::rounds::gpu::{GpuMesh, GpuRounds, GpuSimplifier};
use crate::rounds::{Driver, RoundRunner, SELECTION_PASSES, Upload, corner_attributes};
use crate::simplify::{Kept, OnDevice};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

/// An RGBA8 image.
#[derive(Clone)]
pub struct Image {
    pub rgba: Vec<u8>,
    pub size: (u32, u32),
}

/// A mesh ready to be drawn and simplified.
pub struct Model {
    /// Where it came from: a file, or how it was generated.
    pub name: String,
    pub path: Option<PathBuf>,
    pub mesh: Arc<Mesh>,
    /// The rounds' input (welded, position classes, normalized): both the GPU and the
    /// cpu-parallel runs start from it, and the original is drawn from it.
    pub up: Arc<Upload>,
    /// The original surface, for each vertex's distance in the heatmap.
    pub bvh: Arc<TriangleBvh>,
    pub diagonal: f64,
    pub texture: Option<Image>,
    /// A texture that was named but could not be used, and why.
    pub texture_note: Option<String>,
    pub load_seconds: f64,
    /// The axis drawn up: the side it rests on ([`super::camera::stands`]) where the format
    /// fixes no up axis, else its file format's convention ([`Up::of_file`]); +Y when generated.
    pub up_axis: Up,
    /// How it stands, read from its data: its up axis and the axis across the first view.
    pub stood: Option<(Up, glam::Vec3)>,
}

/// What opening a file gives: the model and its original drawn, and from a manifest the levels
/// of a `meshslim lods` run (for the LOD scene, the original first) or the front of a
/// `meshslim pareto` run.
pub struct Loaded {
    pub model: Model,
    pub original: SceneMesh,
    pub levels: Option<Vec<SceneMesh>>,
    pub front: Option<Front>,
    /// A cluster DAG (X.mslod), drawn as its cut; the model is its first level.
    pub dag: Option<super::dag::DagScene>,
}

/// What the window shows — the model and its original drawn, its simplification, the LOD
/// scene's levels, a Pareto front — and a count that changes whenever any of it does (the 3D
/// view draws again only then).
#[derive(Default)]
pub struct Scene {
    pub model: Option<Arc<Model>>,
    pub original: Option<Arc<SceneMesh>>,
    pub simplified: Option<Simplified>,
    /// The LOD scene's levels, the original first.
    pub lod: Option<Vec<SceneMesh>>,
    /// Where the levels came from (shown in the panel).
    pub lod_source: String,
    /// A Pareto front of the model: searched here or read from a manifest.
    pub front: Option<Front>,
    /// Why the texture mode is off, when a texture was named but not usable.
    pub texture_note: Option<String>,
    /// Bumped whenever a mesh or texture to show changes.
    pub(super) generation: u64,
    /// The model's cluster DAG when a .mslod was opened: drawn as its cut (locked to record
    /// the cut into a frame).
    pub dag: Option<std::sync::Mutex<super::dag::DagScene>>,
    /// The DAG as built in the window, until saved.
    pub dag_built: Option<Arc<crate::dag::Dag>>,
    /// A model came and has not yet been checked for a DAG of its own (a large mesh gets one).
    pub(super) dag_unchecked: bool,
}

impl Scene {
    /// A new model replaces everything shown.
    pub(super) fn set_model(&mut self, model: Model, original: SceneMesh) {
        self.generation += 1;
        self.texture_note = model.texture_note.clone();
        self.model = Some(Arc::new(model));
        self.original = Some(Arc::new(original));
        self.simplified = None;
        self.lod = None;
        self.front = None;
        self.dag = None;
        self.dag_built = None;
        self.dag_unchecked = true;
    }

    pub(super) fn set_simplified(&mut self, s: Simplified) {
        self.simplified = Some(s);
        self.generation += 1;
    }

    pub(super) fn set_levels(&mut self, levels: Vec<SceneMesh>) {
        self.lod = Some(levels);
        self.generation += 1;
    }

    /// The texture changed (uploaded, or refused with `note`).
    pub(super) fn texture_changed(&mut self, note: Option<String>) {
        if note.is_some() {
            self.texture_note = note;
        }
        self.generation += 1;
    }

    /// The mesh the single view draws: the result, or the original when asked or when there
    /// is none.
    pub fn shown(&self, show_original: bool) -> Option<&SceneMesh> {
        match (&self.simplified, show_original) {
            (Some(s), false) => Some(&s.scene),
            _ => self.original.as_deref(),
        }
    }
}

/// Opens `path`: a mesh, or a manifest (`X.lods.json`, `X.pareto.json`) with the mesh it was
/// made from, read from where it names it — or `given`, when the command line has made it
/// (a `builtin:` input). `progress` gets the fraction of the level files read.
pub fn open(
    (pipelines, queue): (&crate::compute::gpu::Pipelines, &wgpu::Queue),
    path: &Path,
    given: Option<Model>,
    progress: &mut dyn FnMut(f32),
) -> Result<Loaded> {
    let device = pipelines.device();
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mslod"))
    {
        let dag = crate::dag::file::read(path)?;
        let mut model = Model::leaves_of(&dag, path.display().to_string())?;
        model.path = Some(path.to_path_buf());
        let original = model.original(device)?;
        let frame = (model.up.center, model.up.scale);
        let d = super::dag::DagScene::new(pipelines, queue, &dag, frame, model.dag_errors(&dag))?;
        return Ok(Loaded {
            model,
            original,
            levels: None,
            front: None,
            dag: Some(d),
        });
    }
    let model_of = |input: &str, relative: Option<&str>, given: Option<Model>| -> Result<Model> {
        if let Some(m) = given {
            return Ok(m);
        }
        if input.starts_with("builtin:") {
            return Err(Error::InvalidOption(format!(
                "{}: made from {input}, a generated mesh; `meshslim view {}` makes it again",
                path.display(),
                path.display()
            )));
        }
        Model::open(&manifest::resolve_input(path, input, relative)?, None)
    };
    let Some(kind) = ManifestKind::of(path) else {
        let model = Model::open(path, None)?;
        let original = model.original(device)?;
        return Ok(Loaded {
            model,
            original,
            levels: None,
            front: None,
            dag: None,
        });
    };
    match kind {
        ManifestKind::Lods => {
            let m: manifest::LodsManifest = manifest::read(path)?;
            let model = model_of(&m.input, m.input_from_manifest.as_deref(), given)?;
            if model.faces() != m.faces {
                return Err(Error::InvalidOption(format!(
                    "{}: made from a mesh of {} faces, but {} has {}: the levels are of \
                     another mesh",
                    path.display(),
                    m.faces,
                    model.name,
                    model.faces()
                )));
            }
            if m.levels.is_empty() {
                return Err(Error::InvalidOption(format!(
                    "{}: no levels",
                    path.display()
                )));
            }
            // Uploaded once: the scene's finest level is the original itself.
            let original = model.original(device)?;
            let mut levels = vec![original.clone()];
            for (k, e) in m.levels.iter().enumerate() {
                let mesh = crate::io::read(&manifest::resolve(path, &e.file)?)?;
                levels.push(model.level(device, &mesh)?);
                progress((k + 1) as f32 / m.levels.len() as f32);
            }
            Ok(Loaded {
                model,
                original,
                levels: Some(levels),
                front: None,
                dag: None,
            })
        }
        ManifestKind::Pareto => {
            let m: manifest::ParetoManifest = manifest::read(path)?;
            let model = model_of(&m.input, m.input_from_manifest.as_deref(), given)?;
            let front = Front::from_manifest(path, &m)?;
            let original = model.original(device)?;
            Ok(Loaded {
                model,
                original,
                levels: None,
                front: Some(front),
                dag: None,
            })
        }
    }
}

impl Model {
    /// Reads `path` and its texture: `texture` if given, else the first material's `map_Kd`
    /// image, else the only PNG or JPEG in the mesh's folder when the mesh has UVs.
    pub fn open(path: &Path, texture: Option<&Path>) -> Result<Model> {
        let t = Instant::now();
        let mesh = crate::io::read(path)?;
        let (texture, note) = match texture {
            Some(t) => (Some(read_texture(t)?), None),
            None => find_texture(path, &mesh),
        };
        let mut m = Model::from_mesh(path.display().to_string(), mesh)?;
        m.path = Some(path.to_path_buf());
        // glTF is +Y up by its specification; the other formats say nothing, so the data does.
        let gltf = matches!(
            crate::io::Format::from_path(path),
            Ok(crate::io::Format::Gltf | crate::io::Format::Glb)
        );
        let convention = Up::of_file(Some(path));
        m.stood = (!gltf)
            .then(|| super::camera::stands(&m.mesh.positions, &m.mesh.triangles, convention))
            .flatten();
        m.up_axis = m.stood.map_or(convention, |(up, _)| up);
        m.texture = texture;
        m.texture_note = note;
        m.load_seconds = t.elapsed().as_secs_f64();
        Ok(m)
    }

    pub fn from_mesh(name: String, mesh: Mesh) -> Result<Model> {
        let t = Instant::now();
        // With the default appearance weights, as the viewer simplifies.
        let up = Upload::new(&mesh).attributes(&crate::options::AttributeWeights::default());
        if up.face_count() == 0 {
            return Err(Error::InvalidMesh(format!(
                "{name}: nothing to draw, the mesh has no faces"
            )));
        }
        let bvh = TriangleBvh::new(&mesh);
        let diagonal = mesh
            .bounds()
            .map_or(1.0, |b| b.diagonal())
            .max(f64::MIN_POSITIVE);
        Ok(Model {
            name,
            path: None,
            mesh: Arc::new(mesh),
            up: Arc::new(up),
            bvh: Arc::new(bvh),
            diagonal,
            texture: None,
            texture_note: None,
            load_seconds: t.elapsed().as_secs_f64(),
            up_axis: Up::Y,
            stood: None,
        })
    }

    /// The input a DAG was built from, as a model: its first level's triangles and the
    /// vertices they use, standing as a mesh file opened in the window would.
    pub fn leaves_of(dag: &crate::dag::Dag, name: String) -> Result<Model> {
        let mut leaf = dag.mesh.clone();
        leaf.triangles = dag
            .clusters
            .iter()
            .filter(|c| c.depth == 0)
            .flat_map(|c| dag.triangles(c).iter().copied())
            .collect();
        leaf.remove_unused_vertices();
        let mut m = Model::from_mesh(name, leaf)?;
        let convention = Up::Y;
        m.stood = super::camera::stands(&m.mesh.positions, &m.mesh.triangles, convention);
        m.up_axis = m.stood.map_or(convention, |(up, _)| up);
        Ok(m)
    }

    /// The window's first view of the model on a view of `size`, as a screenshot takes it.
    pub fn home_camera(&self, size: (u32, u32)) -> super::camera::Camera {
        let mut eye = super::camera::Eye::default();
        eye.home(
            self.up_axis,
            self.stood,
            self.extent(),
            size.0 as f32 / size.1 as f32,
        );
        eye.camera
    }

    pub fn faces(&self) -> usize {
        self.mesh.triangles.len()
    }

    /// The box the normalized positions fill (centred on the origin, diagonal 1).
    pub fn extent(&self) -> glam::Vec3 {
        let (lo, hi) = self.up.positions.iter().fold(
            (glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)),
            |(lo, hi), p| {
                let v = glam::Vec3::new(p[0], p[1], p[2]);
                (lo.min(v), hi.max(v))
            },
        );
        (hi - lo).max(glam::Vec3::ZERO)
    }

    /// The input as the rounds see it, drawn with the same renderer as every result.
    pub fn original(&self, device: &wgpu::Device) -> Result<SceneMesh> {
        let up = &self.up;
        let gpu = GpuMesh::from_arrays(device, &up.positions, &up.indices, up.center, up.scale)?;
        let corners = corner_attributes(&up.flags, &up.vertex_attr, &up.indices, &up.face_extra);
        let extras = Extras {
            error: Vec::new(),
            normals: vertex_normals(&up.positions, &up.indices),
            uvs: corner_uvs(&up.welded, &corners),
            colors: corner_colors(&up.welded, corners.iter().copied()),
        };
        SceneMesh::new(device, gpu, up.positions.len(), up.face_count(), &extras)
    }

    /// Each vertex's distance to the original surface, relative to the diagonal; `positions`
    /// are in the normalized frame.
    /// Each vertex of `dag` (this model its first level), its distance to the model's surface
    /// relative to the diagonal: the heatmap of a cut, as of a simplified mesh.
    pub fn dag_errors(&self, dag: &crate::dag::Dag) -> Vec<f32> {
        self.errors(&self.normalized(&dag.mesh))
    }

    fn errors(&self, positions: &[[f32; 4]]) -> Vec<f32> {
        use rayon::prelude::*;
        let up = &self.up;
        positions
            .par_iter()
            .map(|p| {
                let w = [0, 1, 2].map(|i| p[i] as f64 / up.scale + up.center[i]);
                self.bvh
                    .closest(w, None)
                    .map_or(0.0, |h| (h.dist2.sqrt() / self.diagonal) as f32)
            })
            .collect()
    }

    fn normalized(&self, mesh: &Mesh) -> Vec<[f32; 4]> {
        let (c, s) = (self.up.center, self.up.scale);
        mesh.positions
            .iter()
            .map(|p| {
                let q = [0, 1, 2].map(|i| ((p[i] as f64 - c[i]) * s) as f32);
                [q[0], q[1], q[2], 1.0]
            })
            .collect()
    }
}

/// A glTF material's base colour texture, else the first material library's first `map_Kd`;
/// a note when one is named but unusable (the texture mode says why it is off).
fn find_texture(path: &Path, mesh: &Mesh) -> (Option<Image>, Option<String>) {
    if let Some(found) = gltf_base_color(path, mesh) {
        return found;
    }
    // A bare file name has the empty path as its parent: the current folder.
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    for lib in &mesh.material_libs {
        let mtl = dir.join(lib);
        let Ok(text) = std::fs::read_to_string(&mtl) else {
            return (None, Some(format!("{}: cannot read", mtl.display())));
        };
        let Some(name) = text
            .lines()
            .find_map(|l| l.trim().strip_prefix("map_Kd"))
            // Options (-s, -o …) precede the file name, which comes last.
            .and_then(|rest| rest.split_whitespace().last())
        else {
            continue;
        };
        let file = mtl.parent().unwrap_or(dir).join(name);
        return match read_texture(&file) {
            Ok(img) => (Some(img), None),
            Err(e) => (None, Some(e.to_string())),
        };
    }
    // No material names one: a mesh with UVs whose folder holds exactly one PNG or JPEG (a scan
    // and its texture, as ../shared/models/spot ships) takes that one.
    if mesh.uvs.is_some()
        && let Some(only) = crate::io::texture::lone_texture_beside(path)
    {
        return match read_texture(&only) {
            Ok(img) => (Some(img), None),
            Err(e) => (None, Some(e.to_string())),
        };
    }
    (None, None)
}

/// A PNG or JPEG file (scans ship their textures as either) as RGBA8.
pub fn read_texture(path: &Path) -> Result<Image> {
    if !crate::io::texture::is_texture_file(path) {
        return Err(Error::InvalidOption(format!(
            "{}: only PNG and JPEG textures are read",
            path.display()
        )));
    }
    let bytes = std::fs::read(path).map_err(|e| Error::Io {
        path: path.to_path_buf(),
        source: e,
    })?;
    decode_texture(&bytes).map_err(|message| Error::Parse {
        path: path.to_path_buf(),
        location: crate::error::Location::Unknown,
        message,
    })
}

fn decode_texture(bytes: &[u8]) -> std::result::Result<Image, String> {
    let img =
        image::load_from_memory(bytes).map_err(|e| format!("not a readable PNG or JPEG: {e}"))?;
    let rgba = img.to_rgba8();
    Ok(Image {
        size: rgba.dimensions(),
        rgba: rgba.into_raw(),
    })
}

/// The base colour texture of the first glTF material that has one, decoded; `None` when no
/// material names one.
fn gltf_base_color(path: &Path, mesh: &Mesh) -> Option<(Option<Image>, Option<String>)> {
    let t = &mesh.textures;
    let (i, image) = mesh
        .materials
        .iter()
        .filter_map(|m| m.gltf.as_ref())
        .find_map(|g| {
            let ti = g
                .pointer("/pbrMetallicRoughness/baseColorTexture/index")?
                .as_u64()?;
            let src = t.textures.get(ti as usize)?.get("source")?.as_u64()? as usize;
            Some((src, t.images.get(src)?))
        })?;
    let note = |m: String| format!("{}: image {i}: {m}", path.display());
    Some(match &image.data {
        Some(bytes) => match decode_texture(bytes) {
            Ok(img) => (Some(img), None),
            Err(e) => (None, Some(note(e))),
        },
        None => (
            None,
            Some(note(format!(
                "cannot read {}",
                image.uri.as_deref().unwrap_or("its data")
            ))),
        ),
    })
}

/// Samples per direction for the window's mean and max error.
pub const VIEWER_SAMPLES: usize = 200_000;

/// A simplification as the viewer keeps it.
pub struct Simplified {
    pub scene: SceneMesh,
    /// The result on the host, for saving.
    pub mesh: Mesh,
    pub report: SimplifyReport,
    pub seconds: f64,
    /// Two-sided distance to the original, relative to its diagonal: mean and max; `None` when
    /// the result has no faces to measure.
    pub error: Option<(f64, f64)>,
    /// What made it when not a run in the window (a Pareto front member), for the panel.
    pub made_by: Option<String>,
}

/// Simplifies `model` by the library's one dispatch ([`crate::simplify::simplify_on`]): the
/// `gpu` backend runs on `on`'s pipelines (the window's own device) and the result stays there:
/// its [`GpuMesh`] is the rounds' buffers, or for `cluster` and `floating-cell` the build's.
/// The CPU backends' results are uploaded once so that one renderer draws them all.
pub fn simplify(
    device: &wgpu::Device,
    on: OnDevice,
    model: &Model,
    opts: &SimplifyOptions,
    progress: &mut dyn FnMut(f32),
    phase: &dyn Fn(&str),
) -> Result<Simplified> {
    let t = Instant::now();
    phase(&format!("simplifying ({})", opts.backend.name()));
    let on = OnDevice {
        upload: Some(&model.up),
        ..on
    };
    let (mesh, report, kept) = crate::simplify::simplify_on(on, &model.mesh, opts, progress)?;
    let (gpu, positions, indices, uvs, colors) = match kept {
        Some(Kept::Rounds(kept)) => {
            let (mut rounds, up) = *kept;
            // The per-vertex extras (heatmap, normals, UVs) are made from the result read
            // back; what is drawn is the rounds' own buffers.
            let d = rounds.download()?;
            let indices = d.indices.clone();
            let corners = corner_attributes(&d.flags, &d.vertex_attr, &d.indices, &d.face_extra);
            // The colours and UVs the collapses solved.
            let shown = up.solved_appearance(&d);
            let uvs = corner_uvs(&shown, &corners);
            let colors = corner_colors(&shown, corners.iter().copied());
            let gpu = rounds.into_mesh(&up)?;
            (gpu, d.positions, indices, uvs, colors)
        }
        Some(Kept::Cluster(drawn)) => {
            // The output's corners are the drawn faces' corners, in the same order.
            let uvs = mesh.uvs_from(UvOrigin::BottomLeft).map(|uv| {
                mesh.triangles
                    .iter()
                    .flatten()
                    .map(|&v| uv[v as usize])
                    .collect()
            });
            let colors = corner_colors(&mesh, mesh.triangles.iter().flatten().copied());
            (drawn.gpu, drawn.positions, drawn.indices, uvs, colors)
        }
        None => {
            let d = model.upload(device, &mesh)?;
            (d.gpu, d.positions, d.indices, d.uvs, d.colors)
        }
    };
    let seconds = t.elapsed().as_secs_f64();
    let drawn = Drawn {
        gpu,
        positions,
        indices,
        uvs,
        colors,
    };
    finish(
        device,
        model,
        drawn,
        mesh,
        report,
        seconds,
        &opts.cancel,
        phase,
    )
}

/// A result made elsewhere (a Pareto front member, a level read back from its file), shown as
/// a simplification of `model`: uploaded, its heatmap and two-sided error measured.
pub fn show(
    device: &wgpu::Device,
    model: &Model,
    mesh: Mesh,
    report: SimplifyReport,
    cancel: &crate::options::Cancel,
    phase: &dyn Fn(&str),
) -> Result<Simplified> {
    let drawn = model.upload(device, &mesh)?;
    finish(device, model, drawn, mesh, report, 0.0, cancel, phase)
}

/// A result ready to be drawn: its buffers on the device, and on the host the positions (in
/// the normalized frame) and corners its extras are made from.
struct Drawn {
    gpu: GpuMesh,
    positions: Vec<[f32; 4]>,
    indices: Vec<u32>,
    uvs: Option<Vec<[f32; 2]>>,
    colors: Option<Vec<u32>>,
}

impl Model {
    /// Uploads `mesh`, a result of this model, in the model's normalized frame, so that one
    /// renderer draws it beside the GPU's own results.
    fn upload(&self, device: &wgpu::Device, mesh: &Mesh) -> Result<Drawn> {
        let positions = self.normalized(mesh);
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let gpu =
            GpuMesh::from_arrays(device, &positions, &indices, self.up.center, self.up.scale)?;
        let uvs = mesh
            .uvs_from(UvOrigin::BottomLeft)
            .map(|uv| indices.iter().map(|&v| uv[v as usize]).collect());
        let colors = corner_colors(mesh, indices.iter().copied());
        Ok(Drawn {
            gpu,
            positions,
            indices,
            uvs,
            colors,
        })
    }

    /// A level of detail of this model made elsewhere (a `meshslim lods` file, a Pareto front
    /// member), ready for the LOD scene.
    pub fn level(&self, device: &wgpu::Device, mesh: &Mesh) -> Result<SceneMesh> {
        let d = self.upload(device, mesh)?;
        let extras = Extras {
            error: Vec::new(),
            normals: vertex_normals(&d.positions, &d.indices),
            uvs: d.uvs,
            colors: d.colors,
        };
        SceneMesh::new(
            device,
            d.gpu,
            d.positions.len(),
            d.indices.len() / 3,
            &extras,
        )
    }
}

/// The heatmap, normals and two-sided error of a result, and its [`SceneMesh`].
#[allow(clippy::too_many_arguments)]
fn finish(
    device: &wgpu::Device,
    model: &Model,
    drawn: Drawn,
    mesh: Mesh,
    report: SimplifyReport,
    seconds: f64,
    cancel: &crate::options::Cancel,
    phase: &dyn Fn(&str),
) -> Result<Simplified> {
    cancel.check()?;
    phase("measuring the error");
    let Drawn {
        gpu,
        positions,
        indices,
        uvs,
        colors,
    } = drawn;
    let extras = Extras {
        error: model.errors(&positions),
        normals: vertex_normals(&positions, &indices),
        uvs,
        colors,
    };
    let scene = SceneMesh::new(device, gpu, positions.len(), indices.len() / 3, &extras)?;
    // The mean and max shown in the window: the same two-sided measure as `meshslim compare`,
    // on fewer samples (on a 1M-face input the default takes several seconds more).
    let sampling = CompareOptions {
        samples: Some(VIEWER_SAMPLES),
        ..CompareOptions::default()
    };
    let error = if mesh.triangles.is_empty() {
        None
    } else {
        let d = compare(&model.mesh, &mesh, &sampling)?.distance.two_sided;
        Some((d.mean_rel, d.max_rel))
    };
    cancel.check()?;
    Ok(Simplified {
        scene,
        mesh,
        report,
        seconds,
        error,
        made_by: None,
    })
}

/// Levels of detail for the LOD scene, made in one run of the GPU rounds: the rounds stop at
/// each ratio in turn (falling), the mesh is copied on the GPU, and they go on from there with
/// their quadrics. Level 0 is the original.
pub fn lod_levels(
    device: &wgpu::Device,
    sim: &GpuSimplifier,
    model: &Model,
    ratios: &[f64],
    cancel: &crate::options::Cancel,
    progress: &mut dyn FnMut(f32),
) -> Result<Vec<SceneMesh>> {
    let up = &model.up;
    let mut levels = vec![model.original(device)?];
    let mut rounds = GpuRounds::new(sim, up, SELECTION_PASSES)?;
    rounds.share_queue = true;
    let mut opts = SimplifyOptions::with_faces(up.face_count());
    opts.backend = Backend::Gpu;
    opts.cancel = cancel.clone();
    let mut driver = Driver::new(up, &opts);
    for (i, &r) in ratios.iter().enumerate() {
        let target = (up.face_count() as f64 * r).round() as usize;
        let n = ratios.len() as f32;
        driver.run_to(&mut rounds, target, &mut |f| progress((i as f32 + f) / n))?;
        let gpu = rounds.snapshot(up, driver.vertices, driver.faces)?;
        levels.push(SceneMesh::new(
            device,
            gpu,
            driver.vertices,
            driver.faces,
            &Extras::default(),
        )?);
    }
    Ok(levels)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// PNG and JPEG textures read to the same RGBA8 (JPEG within its loss); other files and
    /// broken ones give errors naming the file.
    #[test]
    fn textures_read_from_png_and_jpeg() {
        let dir = tempfile::tempdir().unwrap();
        let img = image::RgbImage::from_fn(16, 8, |x, _| {
            if x < 8 {
                image::Rgb([200, 30, 30])
            } else {
                image::Rgb([240, 240, 240])
            }
        });
        for name in ["t.png", "t.JPG", "t.jpeg"] {
            let path = dir.path().join(name);
            img.save(&path).unwrap();
            let t = read_texture(&path).unwrap();
            assert_eq!(t.size, (16, 8), "{name}");
            assert_eq!(t.rgba.len(), 16 * 8 * 4);
            let left = &t.rgba[4 * 2..4 * 2 + 4];
            let right = &t.rgba[4 * 13..4 * 13 + 4];
            assert!(
                left[0] > 150 && left[1] < 80 && left[3] == 255,
                "{name}: {left:?}"
            );
            assert!(right.iter().all(|&c| c > 200), "{name}: {right:?}");
        }
        let bad = dir.path().join("broken.jpg");
        std::fs::write(&bad, b"not a jpeg").unwrap();
        let e = read_texture(&bad)
            .err()
            .expect("broken.jpg read")
            .to_string();
        assert!(e.contains("broken.jpg"), "{e}");
        let other = dir.path().join("t.tga");
        std::fs::write(&other, b"").unwrap();
        let e = read_texture(&other).err().expect("t.tga read").to_string();
        assert!(e.contains("PNG and JPEG"), "{e}");
    }
}
