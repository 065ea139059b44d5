//! SVG to pixels with resvg, text in the system's fonts: the benchmark's plot, and the labels a
//! screenshot of two panes carries.

use resvg::usvg::fontdb::{Database, Family, Query};
use resvg::{tiny_skia, usvg};

/// The system's fonts, and where it has no sans-serif face the SVGs can name (a bare server:
/// the H200 machines here had none, and a side-by-side screenshot lost its labels without a
/// word), egui's own Ubuntu Light as sans-serif. Where DejaVu Sans is installed, as the SVGs ask
/// first, nothing changes.
fn fonts(db: &mut Database) {
    db.load_system_fonts();
    fall_back(db);
}

/// Ubuntu Light as sans-serif, unless `db` has a face for DejaVu Sans or sans-serif.
fn fall_back(db: &mut Database) {
    let sans = [Family::Name("DejaVu Sans"), Family::SansSerif];
    let query = Query {
        families: &sans,
        ..Default::default()
    };
    if db.query(&query).is_some() {
        return;
    }
    db.load_font_data(epaint_default_fonts::UBUNTU_LIGHT.to_vec());
    let family = db
        .faces()
        .last()
        .and_then(|f| f.families.first())
        .map(|f| f.0.clone());
    if let Some(family) = family {
        db.set_sans_serif_family(family);
    }
}

/// Renders `svg` at its own size over `background` (transparent when `None`).
pub fn svg_pixmap(
    svg: &str,
    background: Option<tiny_skia::Color>,
) -> Result<tiny_skia::Pixmap, String> {
    let mut opt = usvg::Options::default();
    fonts(opt.fontdb_mut());
    render(svg, &opt, background)
}

fn render(
    svg: &str,
    opt: &usvg::Options,
    background: Option<tiny_skia::Color>,
) -> Result<tiny_skia::Pixmap, String> {
    let tree = usvg::Tree::from_str(svg, opt).map_err(|e| e.to_string())?;
    let size = tree.size().to_int_size();
    let mut pixmap = tiny_skia::Pixmap::new(size.width(), size.height())
        .ok_or_else(|| format!("cannot allocate a {}x{} image", size.width(), size.height()))?;
    if let Some(c) = background {
        pixmap.fill(c);
    }
    resvg::render(&tree, tiny_skia::Transform::default(), &mut pixmap.as_mut());
    Ok(pixmap)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// With no font at all, a label is still drawn, in the fallback face.
    #[test]
    fn text_is_drawn_without_system_fonts() {
        let svg = concat!(
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="80" height="24">"#,
            r##"<text x="4" y="18" font-family="DejaVu Sans, sans-serif" font-size="13" "##,
            r##"fill="#ffffff">original</text></svg>"##
        );
        let mut opt = usvg::Options::default();
        let inked = |opt: &usvg::Options| {
            let p = render(svg, opt, None).unwrap();
            p.data().chunks_exact(4).filter(|px| px[3] > 128).count()
        };
        assert_eq!(inked(&opt), 0, "an empty font database draws no text");
        fall_back(opt.fontdb_mut());
        assert!(inked(&opt) > 20, "the fallback face drew the label");
    }
}
