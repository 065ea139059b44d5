//! The LOD scene's layout: a grid of instances of one mesh, the levels' face fractions, and
//! which level an instance draws for its size on screen.

/// The LOD scene: a grid of instances, as in the seed that measured 13.5 → 26.5 FPS.
pub const LOD_GRID: usize = 21;
/// Fractions of the faces kept by levels 1, 2, 3 (level 0 is the original).
pub const LOD_RATIOS: [f64; 3] = [0.25, 0.06, 0.015];

/// Instances this many diagonals apart.
pub(super) const LOD_SPACING: f32 = 1.25;

/// The level an instance `pixels` tall on screen draws: the original from
/// [`LOD_FULL_PIXELS`] up, each coarser level below half the size of the one before (the levels'
/// face counts fall about 4× apart, so the faces per pixel stay about even).
pub fn lod_level(pixels: f32, levels: usize) -> usize {
    let mut level = 0;
    let mut size = LOD_FULL_PIXELS;
    while pixels < size && level + 1 < levels {
        level += 1;
        size *= 0.5;
    }
    level
}

/// On-screen height from which the LOD scene draws the original.
pub const LOD_FULL_PIXELS: f32 = 240.0;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn larger_instances_draw_finer_levels() {
        let levels = 4;
        assert_eq!(lod_level(1e4, levels), 0, "large on screen: the original");
        let mut last = 0;
        for px in [500.0, 240.0, 200.0, 100.0, 50.0, 20.0, 1.0, 0.0] {
            let l = lod_level(px, levels);
            assert!(l >= last && l < levels, "{px} px: level {l}");
            last = l;
        }
        assert_eq!(last, levels - 1, "tiny is the coarsest");
        assert_eq!(lod_level(0.0, 1), 0, "one level only");
    }
}
