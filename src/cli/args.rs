//! Argument types and value parsers shared by the commands: the input (a file or a generated
//! mesh), numbers, ratios, angles and image sizes.

use std::path::PathBuf;

use super::builtins::{BUILTIN_PREFIX, BuiltinMesh, parse_builtin};
use crate::options::AttributeWeights;

/// A mesh to read: a file, or a generated mesh `builtin:NAME[:FACES]`.
#[derive(Debug, Clone)]
pub enum Input {
    File(PathBuf),
    /// The spec as written (`builtin:torus:5000`) and what it names.
    Builtin {
        spec: String,
        kind: &'static BuiltinMesh,
        min_faces: Option<usize>,
    },
}

impl Input {
    /// How the user named it, for messages and the JSON report.
    pub fn display(&self) -> String {
        match self {
            Input::File(p) => p.display().to_string(),
            Input::Builtin { spec, .. } => spec.clone(),
        }
    }
}

impl std::str::FromStr for Input {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s.strip_prefix(BUILTIN_PREFIX) {
            Some(rest) => {
                let (kind, min_faces) = parse_builtin(rest)?;
                Ok(Input::Builtin {
                    spec: s.to_string(),
                    kind,
                    min_faces,
                })
            }
            None if s.is_empty() => Err("the input path is empty".into()),
            None => Ok(Input::File(PathBuf::from(s))),
        }
    }
}

pub(super) fn parse_input_arg(s: &str) -> std::result::Result<Input, String> {
    s.parse()
}

pub(super) fn parse_f64(s: &str) -> std::result::Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if v.is_finite() {
        Ok(v)
    } else {
        Err(format!("{s:?} is not a finite number"))
    }
}

pub(super) fn parse_face_count(s: &str) -> std::result::Result<usize, String> {
    s.trim()
        .parse::<usize>()
        .map_err(|_| format!("{s:?}: the face count is a whole number, 0 or more"))
}

pub(super) fn parse_ratio(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v <= 1.0 {
        Ok(v)
    } else {
        Err(format!(
            "the ratio must be in (0, 1], got {v} (use --faces N for a face count)"
        ))
    }
}

pub(super) fn parse_non_negative(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be >= 0, got {v}"))
    }
}

pub(super) fn parse_angle(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if v > 0.0 && v <= 180.0 {
        Ok(v)
    } else {
        Err(format!("the angle must be in (0, 180] degrees, got {v}"))
    }
}

pub(super) fn parse_unit(s: &str) -> std::result::Result<f64, String> {
    let v = parse_f64(s)?;
    if (0.0..=1.0).contains(&v) {
        Ok(v)
    } else {
        Err(format!("must be in [0, 1], got {v}"))
    }
}

pub(super) fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let bad = || format!("{s:?}: write the size as WIDTHxHEIGHT, e.g. 1024x768");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h) = (w.trim().parse::<u32>(), h.trim().parse::<u32>());
    match (w, h) {
        (Ok(w), Ok(h)) if (1..=16384).contains(&w) && (1..=16384).contains(&h) => Ok((w, h)),
        (Ok(w), Ok(h)) => Err(format!("{w}x{h}: each side must be 1 to 16384 pixels")),
        _ => Err(bad()),
    }
}

/// How much appearance counts in the collapse cost (`--method qem`, `--backend cpu`).
#[derive(Debug, Clone, Copy, clap::Args)]
pub struct AttributeArgs {
    /// Weight of vertex colours in the collapse cost: a colour difference of 1 (black to full
    /// red) costs like moving the surface by W bounding-box diagonals. Survivors take the best
    /// colour for their place instead of an endpoint's. 0 lets colours ride along
    #[arg(long, value_name = "W", default_value_t = AttributeWeights::default().color, value_parser = parse_non_negative, allow_negative_numbers = true, help_heading = "Appearance")]
    pub color_weight: f64,

    /// Weight of UVs in the collapse cost, as --color-weight (a UV difference of 1 spans the
    /// texture). A solved UV stays within the range its two endpoints had; seams keep a UV on
    /// each side. 0 lets UVs ride along
    #[arg(long, value_name = "W", default_value_t = AttributeWeights::default().uv, value_parser = parse_non_negative, allow_negative_numbers = true, help_heading = "Appearance")]
    pub uv_weight: f64,

    /// Weight of the input's vertex normals in the collapse cost; above 0 the output keeps the
    /// solved normals (unit length) instead of making new ones from its faces
    #[arg(long, value_name = "W", default_value_t = AttributeWeights::default().normal, value_parser = parse_non_negative, allow_negative_numbers = true, help_heading = "Appearance")]
    pub normal_weight: f64,
}

impl AttributeArgs {
    pub fn weights(&self) -> AttributeWeights {
        AttributeWeights {
            color: self.color_weight,
            uv: self.uv_weight,
            normal: self.normal_weight,
        }
    }
}

/// How `compare` and `bench` sample the distance and the appearance.
#[derive(Debug, Clone, clap::Args)]
pub struct SamplingArgs {
    /// Points sampled on the faces in each direction [default: at least one per face of the
    /// denser mesh and ten per face of the coarser one]
    #[arg(short = 'n', long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub samples: Option<u64>,

    /// Seed of the sample positions: the same seed gives the same figures
    #[arg(long, value_name = "S", default_value_t = 1)]
    pub seed: u64,

    /// A PNG or JPEG the meshes' UVs look up: adds the texture colour's deviation (RGB
    /// distance in 0..1 units at the interpolated UVs) to the appearance figures (for 'bench',
    /// a texture-error column)
    #[arg(long, value_name = "IMAGE")]
    pub texture: Option<PathBuf>,
}
