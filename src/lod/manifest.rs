//! The JSON files `meshslim lods` and `meshslim pareto` write beside their meshes, as types: the
//! command line writes them and the viewer reads them back (`meshslim view X.lods.json` shows the
//! levels in the LOD scene, `X.pareto.json` the front), so both sides share one definition.

use crate::error::{Error, Location, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// `<name>.lods.json`: one `meshslim lods` run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LodsManifest {
    /// The input as given: a path (relative to where the command ran) or `builtin:NAME`.
    pub input: String,
    /// The input file's path from the manifest's folder, so that the manifest finds it from
    /// anywhere; `None` for a builtin.
    #[serde(default)]
    pub input_from_manifest: Option<String>,
    pub faces: usize,
    pub vertices: usize,
    pub method: String,
    pub backend: String,
    pub levels: Vec<LodsEntry>,
    pub seconds: LodsSeconds,
}

/// One level of a [`LodsManifest`].
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LodsEntry {
    /// 1 for the first ratio.
    pub level: usize,
    /// The level's mesh, as written (the output folder joined with its name).
    pub file: String,
    pub ratio: f64,
    pub target_faces: usize,
    pub faces: usize,
    pub vertices: usize,
    pub stop_reason: String,
    /// The largest collapse (or removal) error on the way to this level; `None` when not finite.
    pub max_collapse_error: Option<f64>,
    /// Against the original, as `meshslim compare` measures it; `None` with `--no-measure`.
    pub error: Option<LevelError>,
    /// Seconds from the start of the chain until this level was ready.
    pub ready_after_seconds: f64,
}

/// The two-sided distance of a level to the original, relative to the original's diagonal.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LevelError {
    pub mean_rel: f64,
    pub rms_rel: f64,
    pub hausdorff_rel: f64,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct LodsSeconds {
    pub load: f64,
    pub simplify: f64,
    pub measure: f64,
    pub save: f64,
}

/// `<name>.pareto.json`: one `meshslim pareto` run.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ParetoManifest {
    /// The input as given: a path (relative to where the command ran) or `builtin:NAME`.
    pub input: String,
    /// The input file's path from the manifest's folder, so that the manifest finds it from
    /// anywhere; `None` for a builtin.
    #[serde(default)]
    pub input_from_manifest: Option<String>,
    /// The input's vertices the search counts (those in faces).
    pub vertices: usize,
    pub removable: usize,
    pub options: ParetoManifestOptions,
    /// The hypervolumes' reference point, in the axes' units.
    pub reference_point: [f64; 2],
    pub objective_axes: Vec<String>,
    pub evaluations: usize,
    pub generations: Vec<GenerationEntry>,
    /// The final front's members, fewest vertices first.
    pub front: Vec<MemberEntry>,
    pub metro_hypervolume: MetroHypervolume,
    pub seconds: f64,
}

/// The search's settings, as `meshslim pareto` took them.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ParetoManifestOptions {
    pub population: usize,
    pub generations: usize,
    pub offspring: usize,
    pub mutation: f64,
    pub tournament: usize,
    pub seed: u64,
    pub error: String,
    pub init: String,
    pub crossover: String,
    pub mutation_at: String,
    pub anchor: bool,
    pub search_samples: Option<usize>,
}

/// One generation's front, points as (share of the vertices kept, error).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GenerationEntry {
    pub generation: usize,
    pub hypervolume: f64,
    pub front: Vec<[f64; 2]>,
}

/// A member of the final front.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MemberEntry {
    pub file: String,
    pub vertices: usize,
    pub faces: usize,
    /// The search's objective (vertex-plane or Metro error, relative to the diagonal).
    pub objective: f64,
    /// `meshslim compare`'s two-sided mean; `None` when not measured.
    pub metro_mean: Option<f64>,
    /// The greedy decimation chain at the same vertex count, when measured.
    pub greedy_at_same_vertices: Option<GreedyEntry>,
}

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct GreedyEntry {
    pub vertices: usize,
    pub faces: usize,
    pub objective: f64,
    pub metro_mean: Option<f64>,
}

/// The Metro hypervolumes of the front and of the greedy chain at its counts, when measured.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MetroHypervolume {
    pub front: Option<f64>,
    pub greedy_chain: Option<f64>,
}

/// Which of the two a JSON file is, by its name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ManifestKind {
    Lods,
    Pareto,
}

impl ManifestKind {
    /// `X.lods.json` or `X.pareto.json` (any case); `None` for anything else.
    pub fn of(path: &Path) -> Option<ManifestKind> {
        let name = path.file_name()?.to_string_lossy().to_lowercase();
        if name.ends_with(".lods.json") {
            Some(ManifestKind::Lods)
        } else if name.ends_with(".pareto.json") {
            Some(ManifestKind::Pareto)
        } else {
            None
        }
    }
}

/// Reads a manifest, with the file and the line in any error.
pub fn read<T: serde::de::DeserializeOwned>(path: &Path) -> Result<T> {
    let text = std::fs::read_to_string(path).map_err(|e| Error::io(path, e))?;
    serde_json::from_str(&text).map_err(|e| {
        Error::parse(
            path,
            Location::Line(e.line() as u64),
            format!("not a meshslim manifest: {e}"),
        )
    })
}

/// The input a manifest of either kind was made from, as written.
pub fn input_of(path: &Path) -> Result<String> {
    #[derive(Deserialize)]
    struct Input {
        input: String,
    }
    Ok(read::<Input>(path)?.input)
}

/// Writes a manifest as indented JSON (atomically: a reader never sees half of one).
pub fn write<T: Serialize>(path: &Path, manifest: &T) -> Result<()> {
    let text = serde_json::to_string_pretty(manifest)
        .map_err(|e| Error::Internal(format!("a manifest did not serialize: {e}")))?;
    crate::io::write_atomic(path, |w| {
        std::io::Write::write_all(w, text.as_bytes())?;
        std::io::Write::write_all(w, b"\n")
    })
}

/// `file`'s path from `folder` (where the manifest goes), `/`-separated; `None` when there is
/// no relative path (another drive).
pub fn path_from(folder: &Path, file: &Path) -> Option<String> {
    let abs = |p: &Path| {
        std::fs::canonicalize(p)
            .or_else(|_| std::path::absolute(p))
            .ok()
    };
    let rel = pathdiff::diff_paths(abs(file)?, abs(folder)?)?;
    rel.components()
        .all(|c| {
            matches!(
                c,
                std::path::Component::Normal(_) | std::path::Component::ParentDir
            )
        })
        .then(|| {
            rel.components()
                .map(|c| c.as_os_str().to_string_lossy())
                .collect::<Vec<_>>()
                .join("/")
        })
}

/// The input file of a manifest at `path`: by its path from the manifest when it has one and
/// it exists, else as [`resolve`] finds `input`.
pub fn resolve_input(path: &Path, input: &str, from_manifest: Option<&str>) -> Result<PathBuf> {
    let dir = path.parent().unwrap_or(Path::new("."));
    match from_manifest.map(|r| dir.join(r)) {
        Some(p) if p.is_file() => Ok(p),
        _ => resolve(path, input),
    }
}

/// The file a manifest names: as written when it exists from here (the command ran in this
/// folder, or the path is absolute), else beside the manifest (the folder was moved, or the
/// command ran elsewhere). When neither exists the error names both.
pub fn resolve(manifest: &Path, file: &str) -> Result<PathBuf> {
    let as_written = PathBuf::from(file);
    if as_written.exists() {
        return Ok(as_written);
    }
    let dir = manifest.parent().unwrap_or(Path::new("."));
    let candidates = [
        dir.join(&as_written),
        dir.join(as_written.file_name().unwrap_or_default()),
    ];
    candidates
        .iter()
        .find(|p| p.is_file())
        .cloned()
        .ok_or_else(|| {
            Error::InvalidOption(format!(
                "{}: names {file}, which is neither there nor beside the manifest ({})",
                manifest.display(),
                candidates[0].display()
            ))
        })
}
