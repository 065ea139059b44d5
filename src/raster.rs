//! SVG to pixels with resvg, text in the system's fonts: the benchmark's plot, and the labels a
//! screenshot of two panes carries.

use resvg::{tiny_skia, usvg};

/// Renders `svg` at its own size over `background` (transparent when `None`).
pub fn svg_pixmap(
    svg: &str,
    background: Option<tiny_skia::Color>,
) -> Result<tiny_skia::Pixmap, String> {
    let mut opt = usvg::Options::default();
    opt.fontdb_mut().load_system_fonts();
    let tree = usvg::Tree::from_str(svg, &opt).map_err(|e| e.to_string())?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("cannot allocate a {}x{} image", size.width(), size.height()))?;
    if let Some(c) = background {
        pixmap.fill(c);
    }
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    Ok(pixmap)
}
