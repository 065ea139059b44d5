//! `meshslim info`: a mesh's topology report, as text or JSON.

use std::io::{IsTerminal, Write};
use std::process::ExitCode;

use anyhow::Result;
use clap::Args;

use super::args::{Input, parse_input_arg};
use super::files::load;
use super::report::{Progress, write_json_with};
use crate::mesh;

pub(super) const INFO_AFTER_HELP: &str = "\
Examples:
  meshslim info scan.ply
  meshslim info simplified.obj --json
  meshslim info builtin:double-torus";

#[derive(Debug, Args)]
pub struct InfoArgs {
    /// Mesh to describe: a .obj, .ply, .stl, .gltf or .glb file, or builtin:NAME[:FACES]
    /// (names in 'meshslim simplify --help')
    #[arg(value_name = "IN", value_parser = parse_input_arg)]
    pub input: Input,

    /// Print the report as one JSON object on stdout
    #[arg(long)]
    pub json: bool,
}

pub(super) fn run_info(args: InfoArgs) -> Result<ExitCode> {
    let progress = Progress::new(!args.json && std::io::stderr().is_terminal());
    let mesh = load(&args.input, &progress)?;
    let (topo, quality) = progress.spinner("measuring".to_string(), || {
        (
            mesh::topology(&mesh),
            crate::metrics::triangle_quality(&mesh),
        )
    });
    let diagonal = mesh.bounds().map_or(0.0, |b| b.diagonal());
    let out = std::io::stdout();
    let mut out = out.lock();
    if args.json {
        let extra = serde_json::json!({
            "input": args.input.display(),
            "diagonal": diagonal,
            "manifold": topo.is_manifold(),
            "closed": topo.is_closed(),
            "consistently_oriented": topo.is_consistently_oriented(),
            "normals": mesh.normals.is_some(),
            "uvs": mesh.uvs.is_some(),
            "colors": mesh.colors.is_some(),
            "uv_origin": mesh.uvs.as_ref().map(|_| mesh.uv_origin.name()),
            "materials": mesh.materials.len(),
            "texture_images": mesh.textures.images.len(),
            "groups": mesh.groups.len(),
            "quality": quality,
        });
        write_json_with(&mut out, &topo, extra)?;
    } else {
        let t = &topo;
        let yes_no = |b: bool, yes: &'static str, no: &'static str| if b { yes } else { no };
        writeln!(out, "{}", args.input.display())?;
        writeln!(
            out,
            "  vertices           {} ({} welded by position)",
            t.vertices, t.welded_vertices
        )?;
        writeln!(out, "  faces              {}", t.faces)?;
        writeln!(out, "  edges              {}", t.edges)?;
        writeln!(
            out,
            "  boundary           {} edges in {} loops ({})",
            t.boundary_edges,
            t.boundary_loops,
            yes_no(t.is_closed(), "closed", "open")
        )?;
        writeln!(
            out,
            "  non-manifold       {} edges, {} vertices ({})",
            t.non_manifold_edges,
            t.non_manifold_vertices,
            yes_no(t.is_manifold(), "manifold", "not manifold")
        )?;
        writeln!(out, "  components         {}", t.connected_components)?;
        let genus = t
            .genus
            .map_or("undefined (not manifold)".to_string(), |g| g.to_string());
        writeln!(
            out,
            "  euler / genus      {} / {}",
            t.euler_characteristic, genus
        )?;
        if t.is_consistently_oriented() {
            writeln!(out, "  orientation        consistent")?;
        } else {
            writeln!(
                out,
                "  orientation        inconsistent: {} edges traversed the same way by both faces",
                t.inconsistently_oriented_edges
            )?;
        }
        writeln!(out, "  degenerate faces   {}", t.degenerate_faces)?;
        writeln!(out, "  duplicate faces    {}", t.duplicate_faces)?;
        super::report::write_quality(&mut out, &quality, "  ")?;
        writeln!(out, "  area               {:.6}", t.surface_area)?;
        writeln!(out, "  volume             {:.6} (signed)", t.signed_volume)?;
        writeln!(
            out,
            "  bounding box       {:?} .. {:?}, diagonal {:.6}",
            t.bounds_min, t.bounds_max, diagonal
        )?;
        let attrs: Vec<&str> = [
            (mesh.normals.is_some(), "normals"),
            (mesh.uvs.is_some(), "uvs"),
            (mesh.colors.is_some(), "colors"),
        ]
        .into_iter()
        .filter_map(|(has, name)| has.then_some(name))
        .collect();
        writeln!(
            out,
            "  attributes         {}",
            if attrs.is_empty() {
                "none".to_string()
            } else {
                attrs.join(", ")
            }
        )?;
        if mesh.uvs.is_some() {
            writeln!(
                out,
                "  uv origin          {} of the texture image",
                mesh.uv_origin.name()
            )?;
        }
        writeln!(out, "  materials          {}", mesh.materials.len())?;
        let images = &mesh.textures.images;
        if !images.is_empty() {
            let bytes: usize = images
                .iter()
                .filter_map(|i| i.data.as_ref())
                .map(|d| d.len())
                .sum();
            let unread = images.iter().filter(|i| i.data.is_none()).count();
            writeln!(
                out,
                "  texture images     {} ({:.1} MiB{})",
                images.len(),
                bytes as f64 / (1024.0 * 1024.0),
                if unread > 0 {
                    format!(", {unread} could not be read")
                } else {
                    String::new()
                }
            )?;
        }
        writeln!(out, "  groups             {}", mesh.groups.len())?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}
